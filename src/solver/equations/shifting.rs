//! Particle homogenisation: the background-pressure transport velocity of Adami et al.
//! (2013), Sun et al. (2019) shifting (SPST) and the iterative shifting (IPST) of Huang et
//! al. (2019), all expressed as a homogenisation acceleration (du/dt)_c (CTVF sec. 3.3).

use super::{Pair, Point};
use crate::solver::kernel::ScaledKernel;
use crate::solver::math::Vector;

/// Adami et al. (2013) background-pressure acceleration (CTVF eq. 20) in the volume form
/// `-p_b (V_a^2 + V_b^2)/m_a grad W` that PySPH's TVF and EDAC schemes use.
#[inline(always)]
pub fn background_pressure<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>, pb: f64) -> Vector<D> {
    super::momentum::adami_weight(a, b, ab) * -pb
}

/// The sum of Sun et al. (2019), eq. (36) without its prefactor:
/// `V_b [1 + R (W_ab / W(dx))^n] grad W`. The acceleration is
/// `-(Ma 2h c_0 / dt)` times the sum over neighbours.
#[inline(always)]
pub fn sun2019<const D: usize>(b: &Point<D>, ab: &Pair<D>, w_dx: f64, r: f64, n: i32) -> Vector<D> {
    sun2019_volume(b.v(), ab, w_dx, r, n)
}

/// [`sun2019`] from the neighbour's volume `v_b` (for any body kind's particles).
#[inline(always)]
pub fn sun2019_volume<const D: usize>(v_b: f64, ab: &Pair<D>, w_dx: f64, r: f64, n: i32) -> Vector<D> {
    ab.dwij * (v_b * (1.0 + r * powi_small(ab.wij / w_dx, n)))
}

/// GTVF's background pressure of a solid particle at pressure `p` (Zhang, Hu & Adams
/// 2017): `p0_a = min(10 |p_a|, p_ref)`, as the authors' `GTVFSetP0` sets it with `p_ref`
/// the bulk modulus. It vanishes with the pressure at a free surface, where GTVF has no
/// other surface treatment (CTVF sec. 3.4).
#[inline(always)]
pub fn gtvf_background_pressure(p: f64, p_ref: f64) -> f64 {
    (10.0 * p.abs()).min(p_ref)
}

/// Neighbour `b`'s share of GTVF's homogenisation sum, CTVF eq. (20) as the authors'
/// `ComputeAuHatGTVF` evaluates it: `m_b grad W(x_ab, h/2)`, the kernel gradient taken at
/// half the smoothing length (`half`). The acceleration is `-p0_a / rho_a^2` times the sum
/// ([`gtvf_background_pressure`]).
#[inline(always)]
pub fn gtvf_pair<const D: usize>(m_b: f64, ab: &Pair<D>, half: &ScaledKernel) -> Vector<D> {
    let (_, grad_factor) = half.w_and_grad_factor(ab.r2.sqrt());
    ab.xij * (m_b * grad_factor)
}

/// `x^n` for a small non-negative `n` by repeated multiplication (`powi` with a
/// run-time exponent is a library call in the pair loop).
#[inline(always)]
fn powi_small(x: f64, n: i32) -> f64 {
    let mut p = 1.0;
    for _ in 0..n {
        p *= x;
    }
    p
}

/// One IPST displacement contribution, eq. (37) without `U_max dt`: `V_b n_ab W_ab` with
/// `n_ab = x_ab / r_ab` (zero for the particle itself), i.e. `x_ab` times `V_b` times
/// [`ipst_factor`].
#[inline(always)]
pub fn ipst_displacement<const D: usize>(v_b: f64, ab: &Pair<D>) -> Vector<D> {
    ab.xij * (v_b * ipst_factor(ab.wij, ab.r2.sqrt()))
}

/// `W_ab / r_ab` (0 at r = 0): the factor of `V_b x_ab` in eq. (37), the same for both
/// particles of a pair (`x_ba = -x_ab`), so a sweep evaluates it once per pair. On scalars
/// alone, so that a block of pairs evaluates it in one vectorised loop.
#[inline(always)]
pub fn ipst_factor(w: f64, r: f64) -> f64 {
    let f = w / r;
    if r > 0.0 {
        f
    } else {
        0.0
    }
}

/// The IPST uniformity measure of eq. (40), one neighbour's share: `h^2 W_ab` (on
/// scalars, as [`ipst_factor`]).
#[inline(always)]
pub fn ipst_chi(h: f64, w: f64) -> f64 {
    h * h * w
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn shifting_pushes_a_particle_away_from_a_close_neighbour() {
        let (ab, _) = pairs([0.0, 0.0], [0.03, 0.0], 0.1);
        let a = point([0.0; 2], [0.0; 2], 0.01, 1.0, 0.0);
        let b = point([0.0; 2], [0.0; 2], 0.01, 1.0, 0.0);
        // Sun: the acceleration is minus the sum, so the sum points towards b.
        assert!(sun2019(&b, &ab, 1.0, 0.2, 4)[0] > 0.0);
        assert!(background_pressure(&a, &b, &ab, 1.0)[0] < 0.0);
        assert!(ipst_displacement(b.v(), &ab)[0] < 0.0);
    }
}
