//! The SPH solver library. It knows nothing of problem files, caches, plots or the CLI.
//!
//! - [`kernel`]: smoothing kernels; [`nnps`]: neighbour search (SPH-free);
//! - [`systems`]: one module per body kind (fluid, wall, and the boundary model a wall
//!   embeds), each with its fields, constants, time-step limit and kicks;
//! - [`equations`]: one function per physics term, citing its equation;
//! - [`scheme`]: what a fluid scheme is (`edac`, `tvf`, `ctvf` and their switches);
//! - [`interactions`]: who acts on whom (one exhaustive match over body kinds) and what a
//!   particle gathers from each neighbour across each pair of bodies;
//! - [`passes`]: the parallel loops over a body's particles (density, rates,
//!   accelerations, free surface, IPST);
//! - [`schedule`]: the wavefront, its tuner and the thread stages, for speed only;
//! - [`integrator`]: kick-drift-kick updates and the time-step limits;
//!   [`simulation`]: the bodies and the step as ordered stages;
//! - [`output`]: ParaView snapshots, time series and the run summary.

/// `NAMES` (the accepted names, in order) and `from_name` for an enum of choices, each
/// variant's name written once so the two cannot disagree.
macro_rules! named_choices {
    ($ty:ident { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Accepted names.
            pub const NAMES: &'static [&'static str] = &[$($name),+];

            /// Parses a name from `NAMES`.
            pub fn from_name(s: &str) -> Option<Self> {
                match s {
                    $($name => Some(Self::$variant),)+
                    _ => None,
                }
            }
        }
    };
}

pub mod equations;
pub mod fracture;
pub mod integrator;
pub mod interactions;
pub mod kernel;
pub mod math;
pub mod nnps;
pub mod output;
pub mod passes;
pub mod schedule;
pub mod scheme;
pub mod simulation;
pub mod systems;

/// Particles per rayon task in the loops that do a few flops per particle (kicks, drift,
/// wrapping, checks, explicit updates): tasks must be long for the scheduling not to
/// dominate at small sizes.
pub(crate) const LIGHT_LOOP_LEN: usize = 2048;
