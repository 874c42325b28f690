//! What the fluid-structure scenes share (thesis ch. 4): a water column in a tank of wall
//! particles (as [`tank`](super::tank) makes it, the fluid's scheme with the plain
//! parameter names) meeting an elastic structure (its scheme with the names of
//! [`STRUCTURE`]: `solid_scheme`, `solid_pst`, `solid_corrections`, `solid_alpha`,
//! `solid_density`, and `youngs_modulus`, `poisson_ratio`), the structure stepping
//! `solid_substeps` times per fluid step ([`Substeps`]); the structure presents itself to
//! the fluid with the walls' models (`wall_density`, `wall_pressure`, `wall_viscosity`);
//! and the checks that the fluid stays out of it.

use super::fluid_scheme::{time_settings, FluidConstants};
use super::measure::rms_deviation;
use super::params::{Params, Spec};
use super::snapshots::{snapshot_bodies, surface_fields};
use super::solid_common::{
    check_count, solid_params_as, solid_setup_as, Probe, SolidDefaults, SolidSetup, STRUCTURE,
};
use super::stepping::{forward_to_sim, plan, restore_sim};
use super::tank::LAYERS;
use super::tank::{Column, RHO0};
use super::walls::{wall_density, wall_pressure, wall_viscosity};
use super::SceneRun;
use crate::solver::fracture;
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::scheme::FluidScheme;
use crate::solver::simulation::{Simulation, Substeps, TimeSettings};
use crate::solver::systems::{Body, BoundaryMaterial, ElasticSolid, SolidInit};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The parameters of a structure in a fluid with defaults `d` (the fluid's and the common
/// ones come from the scene): its material and scheme, and its sub-steps.
pub fn structure_params(d: &SolidDefaults) -> Vec<Spec> {
    let mut v = solid_params_as(d, &STRUCTURE);
    v.push(Spec::auto_or_int(
        "solid_substeps",
        1,
        "steps of the structure per step of the fluid, the fluid's force held over them: auto (the ratio of the two time-step limits, eqs. 61-62, rounded up) or a number (1: no sub-steps, both at the smaller limit)",
    )
    // A bound on the work of one step: Ctrl-C is seen between steps.
    .at_most(MAX_SUBSTEPS as f64));
    v
}

/// The most sub-steps a structure may take per fluid step (given or `auto`): an aluminium
/// plate in water takes about eighty.
pub const MAX_SUBSTEPS: u32 = 10_000;

/// What a structure's lattice is made from, for its errors: `dx` and the two lengths it
/// spans, the parameters `keys`.
pub fn lattice_words(p: &Params, (a, b): (&str, &str)) -> String {
    format!("`dx` = {} (`{a}` = {}, `{b}` = {})", p.float("dx"), p.float(a), p.float(b))
}

/// The structure's particle count, `keys` (see [`lattice_words`]) over `dx` squared,
/// refused beyond what [`check_count`] allows.
pub fn check_lattice(scene: &str, p: &Params, keys: (&str, &str)) -> Result<(), String> {
    let dx = p.float("dx");
    check_count(scene, &lattice_words(p, keys), (p.float(keys.0) / dx) * (p.float(keys.1) / dx))
}

/// The sub-steps `p` asks for.
pub fn substeps(p: &Params) -> Substeps {
    match p.auto_or_int("solid_substeps") {
        None => Substeps::Auto,
        Some(n) => Substeps::Fixed(n as u32),
    }
}

/// What a fluid-structure scene's parameters make, once every check that needs no particle
/// has passed.
pub struct FsiSetup {
    /// The fluid's constants (c0 = 10 sqrt(2 g H) of the column).
    pub constants: FluidConstants,
    /// The kernel, shared by both bodies.
    pub kernel: Kernel,
    /// The fluid's smoothing length (the structure's too: one spacing, one `hdx`).
    pub h: f64,
    /// The fluid's scheme.
    pub fluid: FluidScheme,
    /// The structure's material and scheme.
    pub solid: SolidSetup,
    /// The structure's steps per fluid step.
    pub substeps: Substeps,
}

/// The setup of scene `scene`: the column's (`keys` as [`Column::setup`] takes them), and
/// the structure's (the largest speed it is expected to reach, `u_max`, and the keys that
/// set it; gravity `g` on it, m/s^2 downward). The kernel must be the solid's (the quintic
/// spline): one kernel serves both bodies.
pub fn fsi_setup(
    scene: &str,
    p: &Params,
    (column, keys): (&Column, [&str; 4]),
    u_max: (f64, &str),
    g: f64,
) -> Result<FsiSetup, String> {
    let (constants, kernel, h, fluid) = column.setup(scene, keys, p)?;
    let solid = solid_setup_as(scene, p, &STRUCTURE, u_max, (constants.u_ref, [0.0, -g, 0.0]))?;
    if kernel.kind() != solid.kernel.kind() {
        return Err(format!(
            "scene `{scene}`: `kernel` = {}: the structure's solid takes the quintic spline, and one kernel serves both bodies",
            p.str("kernel")
        ));
    }
    // The structure's steps per water step follow the ratio of the sound speeds (eqs.
    // 61-62 at rest): bounded, so that one step ends in reasonable time.
    let ratio = solid.material.c0() / constants.c0;
    if ratio > MAX_SUBSTEPS as f64 {
        return Err(format!(
            "scene `{scene}`: `youngs_modulus` = {:?}: the structure's sound speed {:.3e} m/s is {ratio:.3e} times the water's ({:.3e} m/s), more than {MAX_SUBSTEPS} structure steps per water step",
            p.float("youngs_modulus"),
            solid.material.c0(),
            constants.c0
        ));
    }
    Ok(FsiSetup { constants, kernel, h, fluid, solid, substeps: substeps(p) })
}

impl FsiSetup {
    /// The structure `name` of free particles `free` and fixed ones `fixed` (its clamps, at
    /// rest) at the setup's spacing, refused by its particle count first (`what` names the
    /// parameters it comes from); it presents itself to the fluid with the walls' models
    /// and the fluid's density and sound speed.
    pub fn structure(
        &self,
        (scene, what): (&str, &str),
        name: &str,
        free: Vec<Vector<2>>,
        fixed: Vec<Vector<2>>,
        p: &Params,
    ) -> Result<ElasticSolid<2>, String> {
        check_count(scene, what, (free.len() + fixed.len()) as f64)?;
        let s = &self.solid;
        let n = free.len() + fixed.len();
        let mut flags = vec![false; free.len()];
        flags.resize(n, true);
        let mut x = free;
        x.extend(fixed);
        let rho0 = s.material.rho0;
        let init = SolidInit {
            x,
            u: vec![Vector::zeros(); n],
            m: vec![rho0 * s.dx * s.dx; n],
            rho: vec![rho0; n],
            fixed: flags,
        };
        let boundary = BoundaryMaterial {
            rho0: RHO0,
            c0: self.constants.c0,
            density: wall_density(p),
            pressure: wall_pressure(p),
            viscosity: wall_viscosity(p),
        };
        ElasticSolid::new(name, s.h, init, s.material, s.scheme)
            .and_then(|solid| solid.facing_fluid(boundary))
            .map_err(|e| format!("scene `{scene}`: {e}"))
    }

    /// The simulation of `bodies` in `domain`, its time loop as the common parameters set it
    /// with the structure's sub-steps.
    pub fn simulation(
        &self,
        scene: &str,
        p: &Params,
        domain: Domain<2>,
        bodies: impl IntoIterator<Item = Body<2>>,
    ) -> Result<Simulation<2>, String> {
        let time = TimeSettings { solid_substeps: self.substeps, ..time_settings(p) };
        let builder = Simulation::builder(domain, self.kernel).time(time);
        bodies
            .into_iter()
            .fold(builder, |b, body| b.body(body))
            .build()
            .map_err(|e| format!("scene `{scene}`: {e}"))
    }
}

/// Fluid particles of `sim` inside the structure `name` (particle spacing `dx`): those with
/// at least four of its particles within 1.55 dx, around them on every side (the mean of
/// the unit vectors towards them shorter than one half). A fluid particle against the
/// structure's surface has at most three there, all on one side; one in a corner between
/// the structure and its clamp has them within a quarter of the circle (a mean of 0.6 or
/// more); one inside has the lattice around it.
pub fn fluid_inside(sim: &Simulation<2>, name: &str, dx: f64) -> usize {
    let Some((s, _)) = sim.solid(name) else { return 0 };
    let r2 = (1.55 * dx) * (1.55 * dx);
    let (lo, hi) =
        s.x.iter().fold(
            (Vector::<2>::repeat(f64::INFINITY), Vector::<2>::repeat(f64::NEG_INFINITY)),
            |(lo, hi), x| (lo.inf(x), hi.sup(x)),
        );
    let near_box = |x: &Vector<2>| (0..2).all(|k| x[k] > lo[k] - 2.0 * dx && x[k] < hi[k] + 2.0 * dx);
    let surrounded = |x: &Vector<2>| {
        let (n, sum) =
            s.x.iter()
                .map(|y| y - x)
                .filter(|d| d.norm_squared() < r2)
                .fold((0usize, Vector::<2>::zeros()), |(n, sum), d| (n + 1, sum + d / d.norm().max(1e-300)));
        n >= 4 && sum.norm() < 0.5 * n as f64
    };
    sim.fluid().x.iter().filter(|x| near_box(x) && surrounded(x)).count()
}

/// Fluid particles of `sim` that left a tank `tank_width` wide with its floor at y = 0
/// (spacing `dx`): beyond the outer layer of its side walls or its floor. A particle within
/// the layers has penetrated a wall, not left.
pub fn fluid_outside(sim: &Simulation<2>, tank_width: f64, dx: f64) -> usize {
    let depth = super::tank::LAYERS as f64 * dx;
    sim.fluid().x.iter().filter(|x| x[0] < -depth || x[0] > tank_width + depth || x[1] < -depth).count()
}

/// The points `(t, value)` of the CSV `text` (a header row, then rows) whose column
/// `source` equals `which`, with `t` and the value in the columns `t` and `value`, in time
/// order.
pub fn reference_curve(
    text: &str,
    (key, which): (usize, &str),
    (t, value): (usize, usize),
) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let c: Vec<&str> = l.split(',').map(str::trim).collect();
            (c.get(key)? == &which).then_some(())?;
            Some((c.get(t)?.parse().ok()?, c.get(value)?.parse().ok()?))
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// What a fluid-structure scene follows over a run: a point of the structure (its
/// displacement sampled as `tip_x`, `tip_y`), the water found outside the tank or inside the
/// structure, and the structure's numerical fracture ([`fracture::Worst`], particles linked
/// within 1.5 dx). Its metrics: `tip_x_max`, `tip_y_max` (the largest displacement over the
/// run), `particles_lost` (the most water particles found lost at a sample or at the end),
/// `clusters_max`, `max_gap`, and the RMS deviation from published curves.
#[derive(Clone, Debug)]
pub struct Watch {
    /// The structure's body name.
    pub body: &'static str,
    /// Its followed point.
    pub tip: Probe,
    /// What it has seen, the part of a checkpoint it keeps.
    pub seen: Seen,
    /// The tank's width and the particle spacing.
    tank: (f64, f64),
}

/// What a [`Watch`] has seen over a run.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Seen {
    /// (t, tip_x, tip_y) samples.
    pub samples: Vec<(f64, f64, f64)>,
    /// The most water particles found lost at a sample.
    pub lost_max: usize,
    /// The fracture detector's worst.
    pub fracture: fracture::Worst,
}

/// A published curve a metric measures the run against: the metric's name, the component
/// of the displacement (0: x, 1: y), and the curve's (t, value) points.
pub type Published<'a> = (&'a str, usize, Vec<(f64, f64)>);

/// Particles closer than this many spacings are linked by the fracture detector (as the
/// solid scenes link them).
pub const LINK: f64 = 1.5;

impl Watch {
    /// Follows `tip` of structure `body` in a tank `tank_width` wide (spacing `dx`).
    pub fn new(body: &'static str, tip: Probe, (tank_width, dx): (f64, f64)) -> Self {
        Self { body, tip, seen: Seen::default(), tank: (tank_width, dx) }
    }

    fn solid<'a>(&self, sim: &'a Simulation<2>) -> &'a ElasticSolid<2> {
        sim.solid(self.body).expect("the watched structure").0
    }

    fn lost(&self, sim: &Simulation<2>) -> usize {
        let (tw, dx) = self.tank;
        fluid_outside(sim, tw, dx) + fluid_inside(sim, self.body, dx)
    }

    /// One time-series row, `t, tip_x, tip_y, max_speed`, recorded.
    pub fn sample(&mut self, sim: &Simulation<2>) -> Vec<(&'static str, f64)> {
        let (t, d) = (sim.time(), self.tip.displacement(self.solid(sim)));
        self.seen.samples.push((t, d[0], d[1]));
        self.seen.lost_max = self.seen.lost_max.max(self.lost(sim));
        self.seen.fracture.observe(&self.solid(sim).x, self.tank.1, LINK);
        vec![("t", t), ("tip_x", d[0]), ("tip_y", d[1]), ("max_speed", sim.max_speed())]
    }

    /// The metrics at the end of a run, with `(metric, component, curve)`: the RMS
    /// deviation of `tip_x` (component 0) or `tip_y` (1) from each published curve.
    pub fn metrics(&self, sim: &Simulation<2>, published: &[Published]) -> BTreeMap<String, f64> {
        let mut m =
            BTreeMap::from([("particles_lost".to_string(), self.seen.lost_max.max(self.lost(sim)) as f64)]);
        m.extend(self.seen.fracture.with(&self.solid(sim).x, self.tank.1, LINK).metrics());
        let series = |k: usize| -> Vec<(f64, f64)> {
            self.seen.samples.iter().map(|s| (s.0, if k == 0 { s.1 } else { s.2 })).collect()
        };
        for (k, name) in [(0, "tip_x_max"), (1, "tip_y_max")] {
            if let Some(max) = series(k).iter().map(|s| s.1).reduce(f64::max) {
                m.insert(name.into(), max);
            }
        }
        for (name, k, curve) in published {
            if let Some(r) = rms_deviation(&series(*k), curve) {
                m.insert(name.to_string(), r);
            }
        }
        m
    }
}

/// A run of a water column and a structure in a tank followed by a [`Watch`]: the scene of
/// the dam break onto a plate and of the elastic gate, which differ only in how they are
/// built. Its time series is the watch's, its metrics the watch's against `published`.
pub struct StructureRun {
    /// The simulation.
    pub sim: Simulation<2>,
    /// What is followed.
    pub watch: Watch,
    /// The published curves the metrics measure the run against.
    pub published: Vec<Published<'static>>,
    /// How the structure is held, for the run's plan (`the plate clamped through the floor`).
    pub held: &'static str,
}

impl SceneRun for StructureRun {
    forward_to_sim!();
    fn plan(&self) -> String {
        let (_, n) = self.sim.step_sizes();
        let body = self.watch.body;
        plan(
            &self.sim,
            &format!("{LAYERS} wall layers, open top; {}; {n} {body} steps per fluid step", self.held),
        )
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        self.watch.sample(&self.sim)
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, surface_fields(&self.sim))
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        self.watch.metrics(&self.sim, &self.published)
    }
    fn save_state(&self) -> serde_json::Value {
        serde_json::json!({ "sim": &self.sim.state, "watch": &self.watch.seen })
    }
    fn load_state(&mut self, state: serde_json::Value) -> Result<(), String> {
        self.watch.seen = serde_json::from_value(state["watch"].clone())
            .map_err(|e| format!("checkpoint: `watch`: {e}"))?;
        restore_sim(&mut self.sim, &state)
    }
}
