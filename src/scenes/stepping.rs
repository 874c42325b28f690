//! A scene's simulation: built from its bodies and parameters, the [`SceneRun`](super::SceneRun)
//! methods every scene forwards to it (its counts, its stepping loop, its checkpoint), and the
//! plan written at the top of a run log.

use super::fluid_scheme::time_settings;
use super::params::Params;
use crate::solver::kernel::Kernel;
use crate::solver::simulation::{Builder, Simulation};
use crate::solver::systems::Body;

/// The simulation of scene `scene`: `bodies` in `domain` with `kernel`, its time loop as
/// the common parameters `p` set it ([`time_settings`]); an error names the scene.
pub fn simulation<const D: usize>(
    scene: &str,
    p: &Params,
    domain: crate::solver::nnps::Domain<D>,
    kernel: Kernel,
    bodies: impl IntoIterator<Item = Body<D>>,
) -> Result<Simulation<D>, String> {
    simulation_with(scene, p, domain, kernel, bodies, |b| b)
}

/// As [`simulation`], with what `pairs` sets for pairs of bodies on the builder (a pair kept
/// apart, two solids summing across, a load on a body).
pub fn simulation_with<const D: usize>(
    scene: &str,
    p: &Params,
    domain: crate::solver::nnps::Domain<D>,
    kernel: Kernel,
    bodies: impl IntoIterator<Item = Body<D>>,
    pairs: impl FnOnce(Builder<D>) -> Builder<D>,
) -> Result<Simulation<D>, String> {
    let builder = Simulation::builder(domain, kernel).time(time_settings(p));
    pairs(bodies.into_iter().fold(builder, |b, body| b.body(body)))
        .build()
        .map_err(|e| format!("scene `{scene}`: {e}"))
}

/// The [`SceneRun`](super::SceneRun) counts every scene forwards to its `sim` field
/// (a `Simulation<D>`): particles, time, steps.
macro_rules! forward_counts {
    () => {
        fn particles(&self) -> usize {
            $crate::scenes::stepping::particle_count(&self.sim)
        }
        fn body_particles(&self) -> Vec<(String, usize)> {
            $crate::scenes::stepping::body_particles(&self.sim)
        }
        fn time(&self) -> f64 {
            self.sim.time()
        }
        fn steps(&self) -> u64 {
            self.sim.steps()
        }
        fn wavefront_steps(&self) -> u64 {
            self.sim.wavefront_steps()
        }
    };
}

pub(crate) use forward_counts;

/// The counts of [`forward_counts`] and an advance that steps one step at a time in the
/// stepping loop of every run ([`step_until`](crate::solver::simulation::step_until)), and calls
/// `self.after_step()` after each (to follow probes, crossings or extrema at every step), or
/// the closure given, of the scene (`|_| {}`: nothing).
macro_rules! forward_stepwise {
    () => {
        $crate::scenes::stepping::forward_stepwise!(|s: &mut Self| s.after_step());
    };
    ($after_step:expr) => {
        $crate::scenes::stepping::forward_counts!();
        fn advance(
            &mut self,
            t_stop: f64,
            t_end: f64,
            on_step: &mut dyn FnMut(f64, u64) -> bool,
        ) -> Result<bool, $crate::solver::simulation::Divergence> {
            $crate::solver::simulation::step_until(
                self,
                |s| &mut s.sim,
                (t_stop, t_end),
                |s| {
                    ($after_step)(s);
                    on_step(s.sim.time(), s.sim.steps())
                },
            )
        }
    };
}
pub(crate) use forward_stepwise;

/// [`forward_stepwise`] with nothing after a step: the scene's `advance` is its simulation's.
macro_rules! forward_to_sim {
    () => {
        $crate::scenes::stepping::forward_stepwise!(|_: &mut Self| {});
    };
}
pub(crate) use forward_to_sim;

/// The [`SceneRun`](super::SceneRun) checkpoint of a scene whose evolving state is its `sim`
/// and the fields named (each `Serialize` and `Deserialize`): `save_state` writes the
/// simulation's state under `sim` and each field under its name, `load_state` reads them
/// back (an error names the field) and restores the simulation.
macro_rules! checkpoint {
    ($($field:ident),* $(,)?) => {
        fn save_state(&self) -> serde_json::Value {
            let mut state = serde_json::Map::new();
            state.insert("sim".into(), serde_json::to_value(&self.sim.state).expect("a state serialises"));
            $(state.insert(stringify!($field).into(), serde_json::to_value(&self.$field).expect("a state serialises"));)*
            serde_json::Value::Object(state)
        }
        fn load_state(&mut self, state: serde_json::Value) -> Result<(), String> {
            $(self.$field = serde_json::from_value(state[stringify!($field)].clone())
                .map_err(|e| format!("checkpoint: `{}`: {e}", stringify!($field)))?;)*
            $crate::scenes::stepping::restore_sim(&mut self.sim, &state)
        }
    };
}
pub(crate) use checkpoint;

/// The plan written at the top of a run log: the bodies (with `setting`, e.g. the walls'
/// layout), the kernel and the fluid's scheme with every term it evaluates.
pub fn plan<const D: usize>(sim: &Simulation<D>, setting: &str) -> String {
    let mut bodies = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => {
                for part in &f.parts {
                    bodies.push(format!(
                        "body `{}`: {} particles, h = {:.4e}",
                        part.name,
                        part.ids.len(),
                        f.h
                    ));
                }
            }
            Body::Wall(w) => bodies.push(format!("body `{}`: {} particles", w.name, w.len())),
            Body::ElasticSolid(s) => bodies.push(format!(
                "body `{}`: {} particles ({} fixed), h = {:.4e}, E = {:.4e} Pa, nu = {}, rho0 = {}, c0 = {:.4e} m/s",
                s.name,
                s.len(),
                s.fixed.iter().filter(|&&f| f).count(),
                s.h,
                s.material.youngs_modulus,
                s.material.poisson_ratio,
                s.material.rho0,
                s.material.c0()
            )),
        }
    }
    let mut schemes: Vec<String> = sim.solids().map(|s| format!("{}", s.physics)).collect();
    if sim.has_fluid() {
        schemes.insert(0, format!("{}", sim.fluid().physics));
    }
    format!("{}, kernel {:?} ({setting})\n{}", bodies.join("; "), sim.kernel.kind(), schemes.join("\n"))
}

/// The particles of each body of `sim` (each part of the fluid apart), by name.
pub fn body_particles<const D: usize>(sim: &Simulation<D>) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => out.extend(f.parts.iter().map(|p| (p.name.clone(), p.ids.len()))),
            Body::Wall(w) => out.push((w.name.clone(), w.len())),
            Body::ElasticSolid(s) => out.push((s.name.clone(), s.len())),
        }
    }
    out
}

/// Particles in every body of `sim`.
pub fn particle_count<const D: usize>(sim: &Simulation<D>) -> usize {
    sim.bodies().iter().map(Body::len).sum()
}

/// Restores `sim` from the `sim` entry of a scene's checkpoint.
pub fn restore_sim<const D: usize>(sim: &mut Simulation<D>, state: &serde_json::Value) -> Result<(), String> {
    sim.restore(serde_json::from_value(state["sim"].clone()).map_err(|e| format!("checkpoint: {e}"))?);
    Ok(())
}
