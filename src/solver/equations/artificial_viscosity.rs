//! Monaghan's artificial viscosity, CTVF eqs. (28)-(29).

use super::{Pair, Point};
use crate::solver::math::Vector;

/// `-m_b Pi_ab grad W` with `Pi_ab = -alpha h_ab c_ab phi_ab / rho_ab` for approaching
/// particles (`u_ab . x_ab < 0`) and 0 otherwise, `phi_ab = u_ab . x_ab / (r^2 + 0.01 h^2)`
/// (eq. 29); `c` is the (uniform) speed of sound.
#[inline(always)]
pub fn monaghan<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>, alpha: f64, c: f64) -> Vector<D> {
    monaghan_values(a.u - b.u, (a.rho, b.rho), b.m, ab, alpha, c)
}

/// [`monaghan`] from the values it reads: the velocity difference `u_ab`, the densities
/// `(rho_a, rho_b)` and the neighbour's mass `m_b` (for any body kind's particles).
#[inline(always)]
pub fn monaghan_values<const D: usize>(
    u_ab: Vector<D>,
    (rho_a, rho_b): (f64, f64),
    m_b: f64,
    ab: &Pair<D>,
    alpha: f64,
    c: f64,
) -> Vector<D> {
    let vr = u_ab.dot(&ab.xij);
    if vr >= 0.0 {
        return Vector::zeros();
    }
    let phi = vr * ab.inv_r2_eps;
    let pi_ab = -alpha * ab.h * c * phi / (0.5 * (rho_a + rho_b));
    ab.dwij * (-m_b * pi_ab)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn acts_only_on_approaching_pairs_and_repels() {
        let (ab, _) = pairs([0.0, 0.0], [0.07, 0.0], 0.1);
        let a = point([1.0, 0.0], [1.0, 0.0], 0.01, 1.0, 0.0);
        let b = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 0.0);
        // a moves towards b (x_ab points from b to a, u_ab . x_ab < 0).
        let f = monaghan(&a, &b, &ab, 0.1, 10.0);
        assert!(f[0] < 0.0, "approach is braked: {f:?}");
        let receding = point([-1.0, 0.0], [-1.0, 0.0], 0.01, 1.0, 0.0);
        assert_eq!(monaghan(&receding, &b, &ab, 0.1, 10.0).norm(), 0.0);
    }
}
