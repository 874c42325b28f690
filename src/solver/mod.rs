//! The SPH solver library. It knows nothing of problem files, caches, plots or the CLI.
//!
//! - [`kernel`]: smoothing kernels; [`nnps`]: neighbour search;
//! - [`particles`]: per-body storage; [`equations`]: one function per physics term;
//! - [`scheme`]: named compositions of the terms and the passes that run them;
//! - [`integrator`]: kick-drift-kick and the time step; [`simulation`]: the run loop;
//!   [`warm`]: the pool's workers kept awake while a run steps;
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
pub mod integrator;
pub mod kernel;
pub mod math;
pub mod nnps;
pub mod output;
pub mod particles;
pub mod scheme;
pub mod simulation;
pub mod warm;

/// Particles per rayon task in the loops that do a few flops per particle (kicks, drift,
/// wrapping, checks, explicit updates): tasks must be long for the scheduling not to
/// dominate at small sizes.
pub(crate) const LIGHT_LOOP_LEN: usize = 2048;
