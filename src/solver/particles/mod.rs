//! Particle storage: one struct-of-arrays set per body, holding only the fields its
//! declared physics needs.

mod fluid;
mod wall;

pub use fluid::{Fluid, FluidInit, FluidRates};
pub use wall::{Wall, WallDensity, WallPressure};

/// Permutes `v` by `order` (`v_new[k] = v_old[order[k]]`) through a reusable scratch
/// buffer, so reordering allocates nothing once the buffers have grown.
pub(crate) fn permute<T: Copy>(v: &mut Vec<T>, order: &[u32], scratch: &mut Vec<T>) {
    scratch.clear();
    scratch.extend(order.iter().map(|&i| v[i as usize]));
    std::mem::swap(v, scratch);
}
