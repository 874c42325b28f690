//! Fluid at rest in a tank under gravity (a check of the wall boundary condition, CTVF
//! sec. 3.6): a column of `width` x `height` in three layers of wall particles, open at the
//! top, started from the hydrostatic pressure. rho0 = 1000 kg/m^3, g = 9.81 m/s^2,
//! c0 = 10 sqrt(2 g H), continuity density, EDAC pressure, artificial viscosity `alpha`.
//!
//! Metrics: `pressure_rel_error`, the RMS over the fluid of (p - rho0 g (H - y)) /
//! (rho0 g H) at the end; `max_speed`, the largest |u| over sqrt(g H) at the end (spurious
//! currents); `particles_outside`, the fluid particles found beyond the wall surfaces
//! (none may be). The free surface is detected every step (CTVF sec. 3.4) and any shifting
//! kept tangential near it (sec. 3.5); the default runs without shifting (`pst = none`).

use super::common::{
    forward_to_sim, free_surface_params, plan, restore_sim, scheme_params, shifting_columns, snapshot_bodies,
    time_settings, wall_params, FluidConstants,
};
use super::params::{Bound, Params, Spec};
use super::tank::{Column, G, LAYERS, RHO0};
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::kernel::Kernel;
use crate::solver::nnps::Domain;
use crate::solver::scheme::FluidScheme;
use crate::solver::simulation::Simulation;
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
}

/// The constants, kernel, smoothing length and scheme, once every parameter check that
/// needs no particle has passed.
fn setup(p: &Params) -> Result<(FluidConstants, Kernel, f64, FluidScheme), String> {
    column(p).setup("hydrostatic_tank", ["width", "height", "width", "height"], p)
}

/// The fluid column in a tank as wide and half as high again.
fn column(p: &Params) -> Column {
    let (height, width) = (p.float("height"), p.float("width"));
    Column { width, height, tank: (width, 1.5 * height), dx: p.float("dx") }
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    let (constants, kernel, h, scheme) = setup(p)?;
    let c0 = constants.c0;
    let column = column(p);
    let (fluid, wall) = column.bodies(p, h, c0, scheme.transport.is_some())?;
    let Column { width, height, tank: (_, tank_height), dx } = column;
    let edge = (LAYERS as f64 + 0.5) * dx;
    let domain = Domain::bounded([-edge, -edge], [width + edge, tank_height + edge]);
    let time = time_settings(p, c0, constants.u_ref);
    let sim = Simulation::new(domain, kernel, fluid, Some(wall), scheme, time)
        .map_err(|e| format!("scene `hydrostatic_tank`: {e}"))?;
    Ok(Box::new(Tank { sim, height, width }))
}

impl Tank {
    /// (pressure error, largest speed), normalised.
    fn errors(&self) -> (f64, f64) {
        let f = self.sim.fluid();
        let scale = RHO0 * G * self.height;
        let order = f.by_id(&(0..f.len() as u32).collect::<Vec<_>>());
        let (mut e2, mut umax) = (0.0, 0.0f64);
        for &k in &order {
            let k = k as usize;
            let d = (f.p[k] - RHO0 * G * (self.height - f.x[k][1])) / scale;
            e2 += d * d;
            umax = umax.max(f.u[k].norm());
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
        let outside = self.sim.fluid().x.iter().filter(|x| x[0] < 0.0 || x[0] > w || x[1] < 0.0).count();
        BTreeMap::from([
            ("pressure_rel_error".to_string(), p_err),
            ("max_speed".to_string(), umax),
            ("particles_outside".to_string(), outside as f64),
        ])
    }
    fn save_state(&self) -> serde_json::Value {
        serde_json::json!({ "sim": &self.sim.state })
    }
    fn load_state(&mut self, state: serde_json::Value) -> Result<(), String> {
        restore_sim(&mut self.sim, &state)
    }
}
