//! 2D dam break (CTVF paper, sec. 4.3, figs. 3-4, 16, 17): a water column L = 1 m wide and
//! 2 m high released at the left of a 4 m tank, g = 9.81 m/s^2, rho0 = 1000 kg/m^3,
//! c0 = 10 sqrt(2 g H), continuity density (eq. 25), EDAC pressure (eq. 26), artificial
//! viscosity alpha = 0.05 (eq. 28), free-slip walls for the divergence and no-slip for the
//! viscous terms (sec. 3.6), free surface detected every step (sec. 3.4) with the shifting
//! kept tangential near it (sec. 3.5); its pressure evolves by eq. (26) unless
//! `surface_pressure` says otherwise (see
//! [`SurfacePressure`](crate::solver::scheme::SurfacePressure)).
//! The tank is 4 m high (the paper gives no height) and open above.
//!
//! Metrics: `toe_rms`, the RMS deviation of Z/L from Koshizuka & Oka (1996) over their
//! time range (our toe interpolated at their times); `particles_lost`, fluid particles
//! outside the tank at the end (through a wall beyond its outer layer, or thrown over it);
//! `max_penetration`, the deepest fluid particle beyond a wall surface but within its
//! layers, in dx. `timeseries.csv`: `t, toe, t_star, toe_star, max_speed, ipst_iterations,
//! shift_max` (the shifting columns of every scene), with the toe Z
//! the largest x of the fluid inside the tank, t* = t sqrt(2 g / L) and Z/L.

use super::fluid_scheme::{free_surface_params, scheme_params, FluidConstants};
use super::measure::rms_deviation;
use super::params::{Bound, Params, Spec};
use super::snapshots::{shifting_columns, snapshot_bodies, surface_fields};
use super::stepping::{checkpoint, forward_to_sim, plan, simulation};
use super::tank::{Column, G, LAYERS};
use super::walls::wall_params;
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::scheme::FluidScheme;
use crate::solver::simulation::Simulation;
use std::collections::BTreeMap;
use std::path::Path;

const KOSHIZUKA: &str = include_str!("../../reference_data/koshizuka1996_dambreak_toe.csv");

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "dam_break",
    dim: 2,
    about: "Dam break in a 4 m tank against Koshizuka & Oka 1996 (CTVF sec. 4.3)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &["toe_rms", "particles_lost", "max_penetration"],
    columns: &["t", "toe", "t_star", "toe_star", "max_speed", "ipst_iterations", "shift_max"],
    outputs: 0,
};

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("dx", 0.02, Bound::Positive, "particle spacing (m)"),
        Spec::float("column_width", 1.0, Bound::Positive, "water column width L (m)"),
        Spec::float("column_height", 2.0, Bound::Positive, "water column height H (m)"),
        Spec::float("tank_width", 4.0, Bound::Positive, "tank width (m)"),
        Spec::float("tank_height", 4.0, Bound::Positive, "tank wall height (m)"),
        Spec::float("alpha", 0.05, Bound::NonNegative, "artificial viscosity alpha, eq. (28)"),
    ];
    v.extend(scheme_params("sun"));
    v.extend(free_surface_params());
    v.extend(wall_params());
    let mut common = common_params(2.5);
    for s in common.iter_mut() {
        if s.name == "output_dt" {
            *s = Spec::float(
                "output_dt",
                0.1,
                Bound::NonNegative,
                "interval between ParaView snapshots (s); 0: tf/10",
            );
        }
    }
    v.extend(common);
    v
}

/// Koshizuka & Oka's (t*, Z/L) points.
fn koshizuka() -> Vec<(f64, f64)> {
    KOSHIZUKA
        .lines()
        .skip(1)
        .filter_map(|l| {
            let (a, b) = l.split_once(',')?;
            Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
        })
        .collect()
}

struct DamBreak {
    sim: Simulation<2>,
    dx: f64,
    column_width: f64,
    tank_width: f64,
    /// (t*, Z/L) samples.
    toe: Vec<(f64, f64)>,
}

/// The constants, kernel, smoothing length and scheme, once every parameter check that
/// needs no particle has passed.
fn setup(p: &Params) -> Result<(FluidConstants, Kernel, f64, FluidScheme), String> {
    let (l, hc) = (p.float("column_width"), p.float("column_height"));
    let (tw, th) = (p.float("tank_width"), p.float("tank_height"));
    let bad = |key: &str, why: String| Err(format!("scene `dam_break`: `{key}` = {}: {why}", p.float(key)));
    if tw < l {
        return bad("tank_width", format!("the tank is narrower than the column (column_width = {l})"));
    }
    if th < hc {
        return bad("tank_height", format!("the tank is lower than the column (column_height = {hc})"));
    }
    column(p).setup("dam_break", ["column_width", "column_height", "tank_width", "tank_height"], p)
}

/// The water column in its tank.
fn column(p: &Params) -> Column {
    let tank = (p.float("tank_width"), p.float("tank_height"));
    Column { width: p.float("column_width"), height: p.float("column_height"), tank, dx: p.float("dx") }
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(dam_break(p)?))
}

fn dam_break(p: &Params) -> Result<DamBreak, String> {
    let (constants, kernel, h, scheme) = setup(p)?;
    let c0 = constants.c0;
    let column = column(p);
    let (fluid, wall) = column.bodies(p, h, c0, scheme, G)?;
    let Column { width: l, height: hc, tank: (tw, th), dx } = column;
    // Open above and around the tank: the run-up jets are fast (11-19 m/s measured at the
    // impact on the far wall, where the front of Ritter's solution runs at 2 sqrt(g H) =
    // 8.9 m/s), and a drop thrown out of the tank is splash, counted by `particles_lost`,
    // not a blow-up. The domain reaches 8 H above the walls, the height a drop launched at
    // 4 sqrt(g H) climbs to, and as far below, and a tank width on either side.
    let reach = th + 8.0 * hc;
    let domain = Domain::bounded([-tw, -reach], [2.0 * tw, reach]);
    let sim = simulation("dam_break", p, domain, kernel, [fluid.into(), wall.into()])?;
    Ok(DamBreak { sim, dx, column_width: l, tank_width: tw, toe: Vec::new() })
}

impl DamBreak {
    fn toe(&self) -> f64 {
        // Inside the tank: a drop thrown over the far wall is not the surge front.
        let tw = self.tank_width;
        self.sim.fluid().x.iter().map(|x| x[0]).filter(|&x| x <= tw).fold(f64::MIN, f64::max)
    }

    fn t_star(&self, t: f64) -> f64 {
        t * (2.0 * G / self.column_width).sqrt()
    }

    /// RMS of our Z/L minus Koshizuka's at their times within our sampled range (all of
    /// theirs unless the run ends before t* = 3.1).
    fn toe_rms(&self) -> Option<f64> {
        rms_deviation(&self.toe, &koshizuka())
    }
}

impl SceneRun for DamBreak {
    forward_to_sim!();
    fn plan(&self) -> String {
        plan(&self.sim, &format!("{LAYERS} wall layers, open top"))
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let (t, toe) = (self.sim.time(), self.toe());
        let (ts, zs) = (self.t_star(t), toe / self.column_width);
        self.toe.push((ts, zs));
        let mut row = vec![
            ("t", t),
            ("toe", toe),
            ("t_star", ts),
            ("toe_star", zs),
            ("max_speed", self.sim.max_speed()),
        ];
        row.extend(shifting_columns(&self.sim));
        row
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, surface_fields(&self.sim))
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        let f = self.sim.fluid();
        let tw = self.tank_width;
        let depth = |x: &Vector<2>| (-x[0]).max(x[0] - tw).max(-x[1]).max(0.0);
        let deepest_each: Vec<f64> = f.x.iter().map(|x| depth(x) / self.dx).collect();
        let outside = |d: f64| d > LAYERS as f64;
        let lost = deepest_each.iter().filter(|&&d| outside(d)).count();
        // Inside a wall; a particle beyond its outer layer is lost, not penetrating.
        let deepest = deepest_each.iter().copied().filter(|&d| !outside(d)).fold(0.0, f64::max);
        let mut m = BTreeMap::from([
            ("particles_lost".to_string(), lost as f64),
            ("max_penetration".to_string(), deepest),
        ]);
        if let Some(r) = self.toe_rms() {
            m.insert("toe_rms".into(), r);
        }
        m
    }
    checkpoint!(toe);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::equations::wall::{ghost, WallSums};

    /// The walls' pressure (eqs. 46-52) is summed from the fluid pressure that the
    /// accelerations use: after the surface particles are set to p = 0, not before.
    #[test]
    fn the_walls_see_the_surface_pressure_the_accelerations_use() {
        let specs = params();
        let mut p = Params::defaults(&specs);
        for (key, value) in [("dx", "0.1"), ("surface_pressure", "zero"), ("wall_pressure", "extrapolated")] {
            p.set_str("dam_break", &specs, key, value).unwrap();
        }
        let mut run = dam_break(&p).unwrap();
        for _ in 0..50 {
            run.sim.step(f64::INFINITY).unwrap();
        }
        let sim = &run.sim;
        let fluid = sim.fluid();
        let wall = sim.walls().next().expect("the tank");
        let surface = &sim.surface().expect("a free surface").surface;
        assert!(fluid.p.iter().zip(surface).all(|(&p, &s)| !s || p == 0.0), "surface particles at p = 0");
        // The test needs surface particles within a wall particle's support.
        let reach = sim.kernel.support() * fluid.h;
        let touching = (0..fluid.len())
            .filter(|&i| surface[i] && wall.x.iter().any(|w| (w - fluid.x[i]).norm() < reach))
            .count();
        assert!(touching > 0, "no surface particle near a wall");
        // Eq. (52) summed afresh over every fluid particle in reach, from the pressures now.
        let (k, g) = (sim.kernel.scaled(fluid.h), fluid.physics.gravity_vector::<2>());
        for (i, xw) in wall.x.iter().enumerate() {
            let mut s = WallSums::default();
            for j in 0..fluid.len() {
                let x_wf = xw - fluid.x[j];
                if x_wf.norm() < reach {
                    s.add(k.w(x_wf.norm()), x_wf, fluid.p[j], fluid.rho[j], fluid.u[j], fluid.u[j]);
                }
            }
            let p = ghost(&s, Vector::zeros(), true, Vector::zeros(), wall.normal[i], g).p;
            let got = wall.boundary.ghost[i].p;
            assert!((got - p).abs() <= 1e-9 * p.abs().max(1.0), "wall particle {i}: {got} against {p}");
        }
    }

    #[test]
    fn koshizuka_points_parse() {
        let k = koshizuka();
        assert_eq!(k.len(), 9);
        assert_eq!(k[0], (0.0, 1.0));
        assert_eq!(k[8], (3.096, 3.624));
    }
}
