//! The SPH solver library. It knows nothing of problem files, caches, plots or the CLI.
//!
//! - [`kernel`]: smoothing kernels; [`nnps`]: neighbour search (SPH-free);
//! - [`systems`]: one module per body kind (a fluid, a wall and the boundary model it
//!   embeds, an elastic solid), each with its fields, constants, time-step limit, kicks and
//!   what it does at each stage of a step ([`systems::BodyStages`]);
//! - [`interactions`]: who acts on whom (one exhaustive match over ordered pairs of bodies)
//!   and one module per interaction, with its neighbour lists and what a particle gathers
//!   from a neighbour across it ([`interactions::Coupling`]);
//! - [`equations`]: one function per physics term, citing its equation;
//! - [`scheme`]: what a fluid scheme is (`edac`, `tvf`, `ctvf` and their switches), and a
//!   solid's (`ctvf`, `gtvf_pst`, `gtvf`, `gray`);
//! - [`passes`]: the parallel loops over a body's particles (density, rates,
//!   accelerations, free surface, IPST, a solid's rates and accelerations);
//! - [`schedule`] and [`stages`]: the wavefront, its tuner, the warm workers and the stage
//!   runner, for speed only;
//! - [`integrator`]: kick-drift-kick updates, the time-step limits and the time loop's
//!   settings; [`simulation`]: the bodies, the couplings and the step as ordered stages;
//! - [`fracture`]: the numerical-fracture detector of the solid scenes;
//! - [`output`]: ParaView snapshots, time series and the run summary.
//!
//! A new body kind is a module in [`systems`] (its fields and its [`systems::BodyStages`]),
//! an arm in [`systems::stages_of`] and its arms in [`interactions::interactions`]; a new
//! interaction is a module in [`interactions`], its variant of [`interactions::Coupling`]
//! with its hooks, and its arms in the match; a new physics term is a function in
//! [`equations`], called from the interaction that sums it.

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
pub mod stages;
pub mod systems;

/// Particles per rayon task in the loops that do a few flops per particle (kicks, drift,
/// wrapping, checks, explicit updates): tasks must be long for the scheduling not to
/// dominate at small sizes.
pub(crate) const LIGHT_LOOP_LEN: usize = 2048;
