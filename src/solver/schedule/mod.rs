//! Scheduling for speed, apart from the physics: how the passes of a step are laid out on
//! the threads. None of it changes a result: every order of addition is fixed by the
//! passes themselves.
//!
//! - [`wavefront`]: a step's gather passes tile by tile (on the stage runner of
//!   [`stages`](crate::solver::stages)), the fast path of a scene of one
//!   fluid body;
//! - [`tuner`]: which of the sweeps and the wavefront a run keeps, timed on its first steps;
//! - [`warm`]: the pool's workers kept awake while a run steps.

pub mod tuner;
pub mod warm;
pub mod wavefront;

pub use tuner::{Schedule, Tuner, TUNING_STEPS};
pub use wavefront::{StageTimes, StepBodies, Wavefront};
