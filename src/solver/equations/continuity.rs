//! Density evolution with a transport velocity: CTVF eq. (25), from eq. (12).

use super::{Pair, Point};

/// `-rho_a div(u~)`: the first term of eq. (25), `V_b rho_a u~_ab . grad W`. Without
/// shifting (u~ = u) this is the standard continuity equation.
#[inline(always)]
pub fn transport_divergence<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> f64 {
    b.v() * a.rho * (a.u_hat() - b.u_hat()).dot(&ab.dwij)
}

/// `+div(rho (u~ - u))`: the correction term of eq. (25). Printed with a `+` sign; the
/// divergence of eq. (12) discretises to `-V_b (rho du)_ab . grad W` (SEED-NOTES, eq. 25),
/// which is what the authors' code does.
#[inline(always)]
pub fn correction<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> f64 {
    -b.v() * (a.du() * a.rho - b.du() * b.rho).dot(&ab.dwij)
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn compression_raises_density() {
        // b moves towards a: u_ab . x_ab < 0, so the density of a must grow.
        let (ab, _) = pairs([0.0, 0.0], [0.1, 0.0], 0.1);
        let a = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 0.0);
        let b = point([-1.0, 0.0], [-1.0, 0.0], 0.01, 1.0, 0.0);
        assert!(transport_divergence(&a, &b, &ab) > 0.0);
    }

    #[test]
    fn correction_vanishes_without_shifting_and_for_uniform_shift() {
        let (ab, _) = pairs([0.0, 0.0], [0.07, 0.03], 0.1);
        let a = point([0.3, 0.1], [0.3, 0.1], 0.01, 1.0, 0.0);
        let b = point([-0.2, 0.4], [-0.2, 0.4], 0.01, 1.0, 0.0);
        assert_eq!(correction(&a, &b, &ab), 0.0);
        let a = point([0.3, 0.1], [0.35, 0.1], 0.01, 1.0, 0.0);
        let b = point([-0.2, 0.4], [-0.15, 0.4], 0.01, 1.0, 0.0);
        assert!(correction(&a, &b, &ab).abs() < 1e-12);
    }

    #[test]
    fn correction_is_minus_the_divergence_of_rho_du() {
        // A shift field diverging from a (du_b points away from a) has div(rho du) > 0,
        // so the correction of eq. (12) must be positive.
        let (ab, _) = pairs([0.0, 0.0], [0.1, 0.0], 0.1);
        let a = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 0.0);
        let b = point([0.0, 0.0], [0.1, 0.0], 0.01, 1.0, 0.0);
        assert!(correction(&a, &b, &ab) > 0.0);
    }
}
