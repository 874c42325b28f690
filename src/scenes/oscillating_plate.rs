//! 2D oscillating plate (CTVF paper, sec. 4.4, eq. 67, figs. 17-21, Table 1): an elastic
//! plate of length L = 0.2 m and height H = 0.02 m, clamped at x = 0, released with the
//! velocity of its first bending mode, `v_y(x) = V_f c0 F(x) / F(L)` with F of eq. (67) and
//! kL = 1.875; E = 2.0e6 Pa, nu = 0.3975, rho0 = 1000 kg/m^3, so that
//! c0 = sqrt(E / (3 (1 - 2 nu) rho0)) = 57.0 m/s; Monaghan's artificial viscosity with
//! alpha = 1. Quintic spline, h = `hdx` dx. No gravity.
//!
//! The plate is a lattice of `round(L/dx)` x `round(H/dx)` particles at cell centres, its
//! mid-plane at y = 0. The clamp (fig. 17's set-up, after Gray et al. 2001) is made of
//! fixed particles of the same body continuing the lattice beyond x = 0 for as many layers
//! as the kernel's support reaches (3 for the quintic spline at h = dx); see
//! [`ElasticSolid`] for how fixed particles are treated.
//!
//! Metrics:
//! - `period` (s): from the zero crossings of `tip_y`, the mean y of the particles of the
//!   plate's last column (the free end's mid-line), followed at every step and crossings
//!   interpolated linearly between steps. With crossings `t_1 < ... < t_k` after release,
//!   `T = 2 (t_k - t_1) / (k - 1)` for `k >= 2` (successive crossings are half a period
//!   apart), `T = 2 t_1` for `k = 1` (the tip starts at y = 0, so the first crossing comes
//!   after half a period); absent with none (a run shorter than half a period).
//! - `period_rel_error_paper`: `|T - T_paper| / T_paper` against Table 1 for the same V_f:
//!   its GTVF row for `scheme = gtvf` (0.284, 0.283, 0.284, 0.285 s for V_f = 0.001, 0.01,
//!   0.03, 0.05), its CTVF row for every other scheme (0.284, 0.283, 0.283, 0.284 s); only
//!   for those V_f with the paper's plate and material.
//! - `period_theory` (s) and `period_rel_error_theory`: the thin-plate (Euler-Bernoulli,
//!   plane strain) period `2 pi / omega`, `omega^2 = E H^2 k^4 / (12 rho0 (1 - nu^2))`,
//!   k = 1.875 / L: 0.254 s for the paper's plate (Table 1's analytical row). The paper's
//!   periods exceed it by design (finite thickness, `shared/SEED-NOTES.md`).
//! - `clusters_max` and `max_gap`: the numerical-fracture detector ([`fracture`]) over the
//!   plate's and clamp's particles at every time-series row and at the end: the largest
//!   number of clusters (particles closer than 1.5 dx connected; 1 = intact) and the largest
//!   nearest-neighbour distance, in dx; in a run that blows up, over what it ran.
//! - `fracture_time` (s): the first time-series row at which the plate is in more than one
//!   cluster (absent if it never is); kept by a run that blows up after it.
//!
//! `timeseries.csv`: `t, tip_y, clusters, max_gap`.

use super::params::{Bound, Params, Spec};
use super::snapshots::snapshot_bodies;
use super::solid_common::{solid_params, solid_setup, BlockSetup, SolidDefaults, SolidSetup};
use super::stepping::{checkpoint, forward_stepwise, plan, simulation};
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::fracture;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::scheme::SolidSchemeName;
use crate::solver::simulation::Simulation;
use crate::solver::systems::{ElasticSolid, SolidInit, SolidMaterial};
use std::collections::BTreeMap;
use std::path::Path;

/// kL of the first bending mode of a clamped-free plate (eq. 67's text).
pub const KL: f64 = 1.875;

/// Particles closer than this many initial spacings are connected in the fracture detector.
pub const LINK: f64 = 1.5;

/// Table 1's CTVF row: (V_f, period in s).
pub const TABLE1_CTVF: [(f64, f64); 4] = [(0.001, 0.284), (0.01, 0.283), (0.03, 0.283), (0.05, 0.284)];

/// Table 1's GTVF row: (V_f, period in s).
pub const TABLE1_GTVF: [(f64, f64); 4] = [(0.001, 0.284), (0.01, 0.283), (0.03, 0.284), (0.05, 0.285)];

/// The paper's plate and material, for which Table 1 holds: (L, H, E, nu, rho0).
const PAPER_PLATE: (f64, f64, f64, f64, f64) = (0.2, 0.02, 2.0e6, 0.3975, 1000.0);

/// The body's name.
const PLATE: &str = "plate";

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "oscillating_plate",
    dim: 2,
    about: "Elastic plate clamped at one end, released in its first bending mode (CTVF sec. 4.4)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &[
        "period",
        "period_rel_error_paper",
        "period_theory",
        "period_rel_error_theory",
        "clusters_max",
        "max_gap",
        "fracture_time",
    ],
    columns: &["t", "tip_y", "clusters", "max_gap"],
    outputs: 1,
};

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("vf", 0.05, Bound::Positive, "initial tip speed over c0, V_f of sec. 4.4"),
        Spec::float("length", 0.2, Bound::Positive, "plate length L (m)"),
        Spec::float("height", 0.02, Bound::Positive, "plate height H (m)"),
    ];
    v.extend(solid_params(&SolidDefaults {
        dx: 0.002,
        youngs_modulus: 2.0e6,
        poisson_ratio: 0.3975,
        density: 1000.0,
        yield_stress: None,
        alpha: 1.0,
        pst: "sun",
    }));
    v.extend(common_params(0.3));
    v
}

/// What the parameters make, once every check that needs no particle has passed.
fn setup(p: &Params) -> Result<BlockSetup, String> {
    let scene = "oscillating_plate";
    if p.float("vf") >= 1.0 {
        return Err(format!(
            "scene `{scene}`: parameter `vf` = {:?}: must be below 1: the tip would start at the speed of sound",
            p.float("vf")
        ));
    }
    let c0 = SolidMaterial::new(p.float("youngs_modulus"), p.float("poisson_ratio"), p.float("density"))
        .map(|m| m.c0())
        .unwrap_or(0.0);
    let u = p.float("vf") * c0;
    let solid = solid_setup(scene, p, (u, "`vf`"), u, [0.0; 3])?;
    let (l, hp) = (p.float("length"), p.float("height"));
    let plate = format!("the plate (`length` = {l:?}, `height` = {hp:?}) at `dx` = {:?}", solid.dx);
    solid.block(scene, &plate, (l, hp), (4.0, 2.0))
}

/// Eq. (67): the shape of the first bending mode of a clamped-free plate, `k = kL / L`.
pub fn mode_shape(x: f64, k: f64, l: f64) -> f64 {
    let kl = k * l;
    (kl.cos() + kl.cosh()) * ((k * x).cosh() - (k * x).cos())
        + (kl.sin() - kl.sinh()) * ((k * x).sinh() - (k * x).sin())
}

/// The thin-plate period of the first mode (plane strain): `2 pi / omega` with
/// `omega^2 = E H^2 k^4 / (12 rho0 (1 - nu^2))`, `k = kL / L`.
pub fn thin_plate_period(m: &SolidMaterial, l: f64, hp: f64) -> f64 {
    let k = KL / l;
    let omega2 = m.youngs_modulus * hp * hp * k.powi(4) / (12.0 * m.rho0 * (1.0 - m.poisson_ratio.powi(2)));
    2.0 * std::f64::consts::PI / omega2.sqrt()
}

/// The period from zero crossings `t_1 < ... < t_k` (the rule of the module's docs).
pub fn period_from_crossings(t: &[f64]) -> Option<f64> {
    match t {
        [] => None,
        [t1] => Some(2.0 * t1),
        [first, .., last] => Some(2.0 * (last - first) / (t.len() - 1) as f64),
    }
}

struct Plate {
    sim: Simulation<2>,
    dx: f64,
    length: f64,
    height: f64,
    vf: f64,
    /// The particles of the plate's last column.
    tip: Vec<usize>,
    /// (t, tip_y) at the last step, and the zero crossings of tip_y so far.
    last: (f64, f64),
    crossings: Vec<f64>,
    /// The fracture detector's worst over the run.
    fracture: fracture::Worst,
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(plate(p)?))
}

fn plate(p: &Params) -> Result<Plate, String> {
    let BlockSetup { solid: SolidSetup { material, scheme, kernel, dx, h }, nx, ny, layers } = setup(p)?;
    let (l, hp) = (nx as f64 * dx, ny as f64 * dx);
    let (k, c0, vf) = (KL / l, material.c0(), p.float("vf"));
    let f_l = mode_shape(l, k, l);
    let mut init = SolidInit::<2>::default();
    let mut tip = Vec::new();
    for j in 0..ny {
        let y = (j as f64 + 0.5) * dx - 0.5 * hp;
        for i in 0..nx + layers {
            // Columns 0..layers are the clamp, beyond x = 0; the plate starts at x = dx/2.
            let x = (i as f64 - layers as f64 + 0.5) * dx;
            let fixed = i < layers;
            if i == nx + layers - 1 {
                tip.push(init.x.len());
            }
            init.x.push(Vector::<2>::new(x, y));
            let vy = if fixed { 0.0 } else { vf * c0 * mode_shape(x, k, l) / f_l };
            init.u.push(Vector::<2>::new(0.0, vy));
            init.m.push(material.rho0 * dx * dx);
            init.rho.push(material.rho0);
            init.fixed.push(fixed);
        }
    }
    let solid = ElasticSolid::new(PLATE, h, init, material, scheme)?;
    // Room for the plate to swing: its tip moves about V_f c0 / omega (0.13 m at V_f = 0.05).
    let reach = (l + vf * c0 * thin_plate_period(&material, l, hp)).max(l);
    let domain = Domain::bounded([-(layers as f64 + 4.0) * dx - l, -reach - l], [l + reach, reach + l]);
    let sim = simulation("oscillating_plate", p, domain, kernel, [solid.into()])?;
    let mut run = Plate {
        sim,
        dx,
        length: l,
        height: hp,
        vf,
        tip,
        last: (0.0, 0.0),
        crossings: Vec::new(),
        fracture: fracture::Worst::default(),
    };
    run.last = (0.0, run.tip_y());
    Ok(run)
}

impl Plate {
    fn solid(&self) -> &ElasticSolid<2> {
        self.sim.solid(PLATE).expect("the plate").0
    }

    /// The mean y of the last column: the free end's mid-line.
    fn tip_y(&self) -> f64 {
        let s = self.solid();
        self.tip.iter().map(|&i| s.x[i][1]).sum::<f64>() / self.tip.len() as f64
    }

    /// Records a zero crossing of the tip between the last step and this one.
    fn after_step(&mut self) {
        let (t1, y1) = (self.sim.time(), self.tip_y());
        let (t0, y0) = self.last;
        if t1 > 0.0 && ((y0 > 0.0 && y1 <= 0.0) || (y0 < 0.0 && y1 >= 0.0)) {
            self.crossings.push(t0 + (t1 - t0) * y0 / (y0 - y1));
        }
        self.last = (t1, y1);
    }

    fn fracture(&mut self) -> fracture::Fracture {
        let (t, x) = (self.sim.time(), &self.sim.solid(PLATE).expect("the body").0.x);
        self.fracture.observe_at(t, x, (self.dx, LINK), 1)
    }

    fn paper_plate(&self) -> bool {
        let m = self.solid().material;
        let (l, hp, e, nu, rho) = PAPER_PLATE;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        close(self.length, l)
            && close(self.height, hp)
            && close(m.youngs_modulus, e)
            && close(m.poisson_ratio, nu)
            && close(m.rho0, rho)
    }
}

impl SceneRun for Plate {
    forward_stepwise!();
    fn plan(&self) -> String {
        plan(
            &self.sim,
            &format!(
                "clamp of {} fixed layers",
                self.solid().fixed.iter().filter(|&&f| f).count() / self.tip.len()
            ),
        )
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let f = self.fracture();
        vec![
            ("t", self.sim.time()),
            ("tip_y", self.tip_y()),
            ("clusters", f.clusters as f64),
            ("max_gap", f.max_gap),
        ]
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, Vec::new())
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        // The detector at the end too, whatever the sampling.
        let worst = self.fracture.with(&self.solid().x, self.dx, LINK);
        let material = self.solid().material;
        let theory = thin_plate_period(&material, self.length, self.height);
        let mut m: BTreeMap<String, f64> = worst.metrics().into_iter().collect();
        m.insert("period_theory".into(), theory);
        if let Some(t) = period_from_crossings(&self.crossings) {
            m.insert("period".into(), t);
            m.insert("period_rel_error_theory".into(), (t - theory).abs() / theory);
            let row = match self.solid().physics.name {
                SolidSchemeName::Gtvf => &TABLE1_GTVF,
                _ => &TABLE1_CTVF,
            };
            let paper = row.iter().find(|(vf, _)| (vf - self.vf).abs() <= 1e-9 * vf);
            if let (Some(&(_, t_paper)), true) = (paper, self.paper_plate()) {
                m.insert("period_rel_error_paper".into(), (t - t_paper).abs() / t_paper);
            }
        }
        m
    }
    fn running_metrics(&self) -> BTreeMap<String, f64> {
        self.fracture.metrics().into_iter().collect()
    }
    checkpoint!(last, crossings, fracture);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. (67) vanishes with its slope at the clamp; the thin-plate period of the paper's
    /// plate is Table 1's analytical 0.254 s; the period rule of the module's docs.
    #[test]
    fn mode_shape_theory_and_period_rule() {
        let (l, k) = (0.2, KL / 0.2);
        assert_eq!(mode_shape(0.0, k, l), 0.0);
        assert!(mode_shape(1e-4, k, l).abs() < 1e-6 * mode_shape(l, k, l).abs(), "zero slope at x = 0");
        let m = SolidMaterial::new(2.0e6, 0.3975, 1000.0).unwrap();
        assert!((thin_plate_period(&m, 0.2, 0.02) - 0.254).abs() < 0.0005);
        assert_eq!(period_from_crossings(&[]), None);
        assert_eq!(period_from_crossings(&[0.1]), Some(0.2));
        assert!((period_from_crossings(&[0.1, 0.2, 0.3]).unwrap() - 0.2).abs() < 1e-15);
    }

    /// The quick case (dx = 0.004, five particles across) through one period: no numerical
    /// fracture (one cluster, no particle farther than 1.5 dx from its nearest neighbour),
    /// and a period (two crossings) within 15 % of the thin-plate period (the coarse plate
    /// is stiffer; the paper's periods are 12 % above it).
    #[test]
    fn the_quick_plate_oscillates_without_fracture() {
        let specs = params();
        let mut p = Params::defaults(&specs);
        for (key, value) in [("dx", "0.004"), ("tf", "0.3")] {
            p.set_str("oscillating_plate", &specs, key, value).unwrap();
        }
        let mut run = plate(&p).unwrap();
        while run.sim.time() < 0.3 {
            let before = run.sim.time();
            run.advance(before + 0.01, 0.3, &mut |_, _| true).unwrap();
            run.sample();
        }
        let m = run.metrics();
        assert_eq!(m["clusters_max"], 1.0);
        assert!(m["max_gap"] < LINK, "{m:?}");
        assert_eq!(run.crossings.len(), 2, "{:?}", run.crossings);
        assert!(m["period_rel_error_theory"] < 0.15, "{m:?}");
        assert!(m.contains_key("period_rel_error_paper"));
    }

    /// Bad material input is refused with the key and value named.
    #[test]
    fn bad_material_is_refused_by_key() {
        let specs = params();
        for (key, value) in [("poisson_ratio", "0.5"), ("poisson_ratio", "-1"), ("poisson_ratio", "0.7")] {
            let mut p = Params::defaults(&specs);
            p.set_str("oscillating_plate", &specs, key, value).unwrap();
            let e = setup(&p).err().unwrap();
            assert!(
                e.contains(&format!("`{key}` = {value}")) || e.contains(&format!("`{key}` = {value}.0")),
                "{e}"
            );
        }
        for (key, value) in [("youngs_modulus", "0"), ("density", "-1"), ("dx", "0"), ("gtvf_p_ref", "-1")] {
            let mut p = Params::defaults(&specs);
            let e = p.set_str("oscillating_plate", &specs, key, value).unwrap_err();
            assert!(e.contains(&format!("`{key}`")) && e.contains(value), "{e}");
        }
    }

    /// GTVF's parameter is refused by key when the scheme does not read it, GTVF refuses a
    /// shifting technique of its own (it homogenises with its background pressure), and the
    /// surface's shift rule is refused without a shifting technique.
    #[test]
    fn gtvfs_parameters_are_refused_where_unread() {
        let specs = params();
        let with = |pairs: &[(&str, &str)]| {
            let mut p = Params::defaults(&specs);
            for (k, v) in pairs {
                p.set_str("oscillating_plate", &specs, k, v).unwrap();
            }
            setup(&p).err()
        };
        let e = with(&[("scheme", "ctvf"), ("gtvf_p_ref", "1e6")]).unwrap();
        assert!(e.contains("`gtvf_p_ref` = 1000000.0") && e.contains("ctvf"), "{e}");
        let e = with(&[("scheme", "gtvf"), ("pst", "sun")]).unwrap();
        assert!(e.contains("`scheme` = gtvf") && e.contains("`pst` = sun"), "{e}");
        assert!(with(&[("scheme", "gtvf"), ("pst", "none"), ("gtvf_p_ref", "1e6")]).is_none());
        let e = with(&[("pst", "none"), ("surface_shift", "outward")]).unwrap();
        assert!(e.contains("`surface_shift` = outward") && e.contains("`pst` = none"), "{e}");
        assert!(with(&[("pst", "sun"), ("surface_shift", "outward")]).is_none());
    }
}
