//! Physical viscosity.

use super::{Pair, Point};
use crate::solver::math::Vector;

/// Morris et al. (1997) laminar viscosity, the third term of CTVF eq. (27):
/// `m_b 4 nu (x_ab . grad W) / ((rho_a + rho_b)(r^2 + 0.01 h^2)) u_ab`, with `nu` the
/// kinematic viscosity.
#[inline(always)]
pub fn morris<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>, nu: f64) -> Vector<D> {
    let f = b.m * 4.0 * nu * ab.lap / (a.rho + b.rho);
    (a.u - b.u) * f
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn viscosity_slows_relative_motion_and_conserves_momentum() {
        let (ab, ba) = pairs([0.0, 0.0], [0.0, 0.07], 0.1);
        let a = point([1.0, 0.0], [1.0, 0.0], 0.01, 1.0, 0.0);
        let b = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 0.0);
        let fa = morris(&a, &b, &ab, 0.01);
        let fb = morris(&b, &a, &ba, 0.01);
        assert!(fa[0] < 0.0, "the faster particle is slowed");
        assert!((fa * a.m + fb * b.m).norm() < 1e-15);
        let same = point([1.0, 0.0], [1.0, 0.0], 0.01, 1.0, 0.0);
        assert_eq!(morris(&a, &same, &ab, 0.01).norm(), 0.0);
    }
}
