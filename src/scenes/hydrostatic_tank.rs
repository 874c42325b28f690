//! Fluid at rest in a tank under gravity (a check of the wall boundary condition, CTVF
//! sec. 3.6): a column of `width` x `height` in three layers of wall particles, open at the
//! top, started from the hydrostatic pressure. rho0 = 1000 kg/m^3, g = 9.81 m/s^2,
//! c0 = 10 sqrt(2 g H), continuity density, EDAC pressure, artificial viscosity `alpha`.
//! With `tank_acceleration` = a, the tank is accelerated upward from rest, carrying the
//! fluid: at rest in the tank's frame, the fluid holds the hydrostatic pressure of g + a,
//! which the walls give it through the acceleration term of eq. (52).
//!
//! Metrics: `pressure_rel_error`, the RMS over the fluid of (p - rho0 (g + a) (H - y)) /
//! (rho0 (g + a) H) at the end, y the height above the tank's bottom; `max_speed`, the
//! largest |u - u_tank| over sqrt(g H) at the end (spurious currents); `particles_outside`,
//! the fluid particles found beyond the wall surfaces (none may be). The free surface is detected every step (CTVF sec. 3.4) and any shifting
//! kept tangential near it (sec. 3.5); the default runs without shifting (`pst = none`).

use super::fluid_scheme::{free_surface_params, scheme_params, FluidConstants};
use super::params::{Bound, Params, Spec};
use super::snapshots::{shifting_columns, snapshot_bodies};
use super::stepping::{checkpoint, forward_to_sim, plan, simulation};
use super::tank::{Column, G, LAYERS, RHO0};
use super::walls::wall_params;
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::scheme::FluidScheme;
use crate::solver::simulation::{Simulation, BLOWUP_MACH};
use std::collections::BTreeMap;
use std::path::Path;

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "hydrostatic_tank",
    dim: 2,
    about: "Fluid at rest in a tank under gravity: wall pressure and spurious currents",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &["pressure_rel_error", "max_speed", "particles_outside"],
    columns: &["t", "max_speed", "pressure_rel_error", "ipst_iterations", "shift_max"],
    outputs: 0,
};

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("dx", 0.02, Bound::Positive, "particle spacing (m)"),
        Spec::float("height", 1.0, Bound::Positive, "fluid column height H (m)"),
        Spec::float("width", 1.0, Bound::Positive, "tank width (m)"),
        Spec::float("alpha", 0.05, Bound::NonNegative, "artificial viscosity alpha, eq. (28)"),
        Spec::float(
            "tank_acceleration",
            0.0,
            Bound::None,
            "upward acceleration a of the tank from rest (m/s^2): the fluid holds the pressure of g + a",
        )
        .added_later(),
    ];
    v.extend(scheme_params("none"));
    v.extend(free_surface_params());
    v.extend(wall_params());
    v.extend(common_params(2.0));
    v
}

struct Tank {
    sim: Simulation<2>,
    height: f64,
    width: f64,
    /// The tank's upward acceleration.
    a: f64,
}

/// The constants, kernel, smoothing length and scheme, once every parameter check that
/// needs no particle has passed.
fn setup(p: &Params) -> Result<(FluidConstants, Kernel, f64, FluidScheme), String> {
    let a = p.float("tank_acceleration");
    if a <= -G {
        return Err(format!(
            "scene `hydrostatic_tank`: `tank_acceleration` = {a}: a tank falling at g = {G} m/s^2 or faster cannot hold its water"
        ));
    }
    let setup = column(p).setup("hydrostatic_tank", ["width", "height", "width", "height"], p)?;
    // The run checks the fluid's speed against its speed of sound (the Mach limit of a
    // blow-up), and the fluid moves with the tank: a tank that would outrun it by the end
    // is refused here, not reported as a blow-up later.
    let (c0, tf) = (setup.0.c0, p.float("tf"));
    if a.abs() * tf >= BLOWUP_MACH * c0 {
        return Err(format!(
            "scene `hydrostatic_tank`: `tank_acceleration` = {a}: the tank would move at {:.3e} m/s by tf = {tf} s, at or above the speed of sound c0 = {c0:.3} m/s, where a run stops as a blow-up",
            a.abs() * tf
        ));
    }
    Ok(setup)
}

/// The fluid column in a tank as wide and half as high again.
fn column(p: &Params) -> Column {
    let (height, width) = (p.float("height"), p.float("width"));
    Column { width, height, tank: (width, 1.5 * height), dx: p.float("dx") }
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(tank(p)?))
}

fn tank(p: &Params) -> Result<Tank, String> {
    let (constants, kernel, h, scheme) = setup(p)?;
    let c0 = constants.c0;
    let column = column(p);
    let a = p.float("tank_acceleration");
    let (fluid, mut wall) = column.bodies(p, h, c0, scheme, G + a)?;
    if a != 0.0 {
        wall = wall.translating(Vector::zeros(), Vector::<2>::new(0.0, a));
    }
    let Column { width, height, tank: (_, tank_height), dx } = column;
    let edge = (LAYERS as f64 + 0.5) * dx;
    // The box holds the tank wherever it moves to by the end.
    let rise = 0.5 * a * p.float("tf").powi(2);
    let domain =
        Domain::bounded([-edge, -edge + rise.min(0.0)], [width + edge, tank_height + edge + rise.max(0.0)]);
    let sim = simulation("hydrostatic_tank", p, domain, kernel, [fluid.into(), wall.into()])?;
    Ok(Tank { sim, height, width, a })
}

impl Tank {
    /// The tank's height above its start and its velocity now (it starts at rest).
    fn tank_motion(&self) -> (f64, Vector<2>) {
        let t = self.sim.time();
        (0.5 * self.a * t * t, Vector::<2>::new(0.0, self.a * t))
    }

    /// (pressure error, largest speed in the tank's frame), normalised.
    fn errors(&self) -> (f64, f64) {
        let f = self.sim.fluid();
        let g = G + self.a;
        let (rise, u_tank) = self.tank_motion();
        let scale = RHO0 * g * self.height;
        let order = f.by_id(&(0..f.len() as u32).collect::<Vec<_>>());
        let (mut e2, mut umax) = (0.0, 0.0f64);
        for &k in &order {
            let k = k as usize;
            let d = (f.p[k] - RHO0 * g * (self.height - (f.x[k][1] - rise))) / scale;
            e2 += d * d;
            umax = umax.max((f.u[k] - u_tank).norm());
        }
        ((e2 / f.len() as f64).sqrt(), umax / (G * self.height).sqrt())
    }
}

impl SceneRun for Tank {
    forward_to_sim!();
    fn plan(&self) -> String {
        plan(&self.sim, &format!("{LAYERS} wall layers, open top"))
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let (p_err, umax) = self.errors();
        let mut row = vec![("t", self.sim.time()), ("max_speed", umax), ("pressure_rel_error", p_err)];
        row.extend(shifting_columns(&self.sim));
        row
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, Vec::new())
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        let (p_err, umax) = self.errors();
        let w = self.width;
        let rise = self.tank_motion().0;
        let outside =
            self.sim.fluid().x.iter().filter(|x| x[0] < 0.0 || x[0] > w || x[1] - rise < 0.0).count();
        BTreeMap::from([
            ("pressure_rel_error".to_string(), p_err),
            ("max_speed".to_string(), umax),
            ("particles_outside".to_string(), outside as f64),
        ])
    }
    checkpoint!();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. (52) with the wall's acceleration: from the initial field of a fluid at rest in a
    /// tank accelerated at a, p = rho0 (g + a) (H - y) (uniform density), the extrapolation
    /// gives every wall particle in reach of the fluid the same linear field,
    /// rho0 (g + a) (H - y_w), to rounding (the field is linear, so eq. 52 is exact for it).
    /// Without the acceleration term it would be off by rho0 a (y_f - y_w) on average.
    #[test]
    fn an_accelerated_tank_extrapolates_the_pressure_of_g_plus_a() {
        for a in [0.0, 9.81, -4.9] {
            let specs = params();
            let mut p = Params::defaults(&specs);
            for (key, value) in [("dx", "0.1".to_string()), ("tank_acceleration", a.to_string())] {
                p.set_str("hydrostatic_tank", &specs, key, &value).unwrap();
            }
            let tank = tank(&p).unwrap();
            let (wall, fluid) = (tank.sim.walls().next().unwrap(), tank.sim.fluid());
            let reach = tank.sim.kernel.support() * fluid.h;
            let scale = RHO0 * (G + a) * tank.height;
            let mut seen = 0;
            for (x, ghost) in wall.x.iter().zip(&wall.boundary.ghost) {
                if fluid.x.iter().all(|f| (f - x).norm() >= reach * (1.0 - 1e-6)) {
                    continue; // no fluid in reach (W = 0 at the support's edge): nothing to extrapolate from
                }
                let expected = RHO0 * (G + a) * (tank.height - x[1]);
                assert!(
                    (ghost.p - expected).abs() <= 1e-9 * scale,
                    "a = {a}, wall at {x:?}: {} against {expected}",
                    ghost.p
                );
                seen += 1;
            }
            // At least the three layers under the ten particles of the column's width.
            assert!(seen >= 30, "a = {a}: {seen} wall particles in reach of the fluid");
        }
    }
}
