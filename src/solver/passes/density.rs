//! The summation density, `rho_a = sum_b m_b W_ab` over a body and its boundaries.

use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// Sets `rho` of the particles at `x` to the summation density: their own body's share
/// `own` (summed as their list was built), then each boundary's, in order.
pub fn summation_density<const D: usize>(
    rho: &mut [f64],
    x: &[crate::solver::math::Vector<D>],
    own: &[f64],
    boundaries: Boundaries<'_, D>,
) {
    rho.par_iter_mut().zip(own).enumerate().with_min_len(LIGHT_LOOP_LEN).for_each(|(i, (rho, &s))| {
        *rho = s;
        for b in boundaries.iter() {
            let m = &b.model.m;
            b.list.for_each_from(i, x[i], b.x, |j, _, _, kw| *rho += m[j] * kw.w);
        }
    });
}
