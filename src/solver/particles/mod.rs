//! Particle storage: one struct-of-arrays set per body, holding only the fields its
//! declared physics needs.

mod fluid;
mod wall;

pub use fluid::{Fluid, FluidInit, FluidRates};
pub use wall::{Wall, WallDensity, WallPressure};

use rayon::prelude::*;

/// Permutes `v` by `order` (`v_new[k] = v_old[order[k]]`) through a reusable scratch
/// buffer, so reordering allocates nothing once the buffers have grown. A gather, split
/// across the threads: run serially, a step's reordering held the second core idle.
pub(crate) fn permute<T: Copy + Send + Sync>(v: &mut Vec<T>, order: &[u32], scratch: &mut Vec<T>) {
    let Some(&first) = v.first() else { return };
    scratch.resize(order.len(), first);
    let from = &v[..];
    scratch
        .par_iter_mut()
        .zip(order)
        .with_min_len(crate::solver::LIGHT_LOOP_LEN)
        .for_each(|(s, &i)| *s = from[i as usize]);
    std::mem::swap(v, scratch);
}
