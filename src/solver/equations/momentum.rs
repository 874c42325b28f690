//! Momentum equation terms: pressure gradient, TVF artificial stress and the CTVF
//! transport-velocity divergence correction (CTVF eqs. 19 and 27).

use super::{Pair, Point};
use crate::solver::math::Vector;

/// `-grad(p)/rho` in the symmetric form of eq. (27): `-m_b (p_a/rho_a^2 + p_b/rho_b^2) grad W`.
#[inline(always)]
pub fn pressure_gradient<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    ab.dwij * (-b.m * (a.p * a.inv_rho2 + b.p * b.inv_rho2))
}

/// What [`pressure_gradient`] gains per unit of a reference pressure subtracted from both
/// `p_a` and `p_b`: `m_b (1/rho_a^2 + 1/rho_b^2) grad W`.
#[inline(always)]
pub fn pressure_reference_weight<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    ab.dwij * (b.m * (a.inv_rho2 + b.inv_rho2))
}

/// The Adami et al. (2013) inter-particle pressure `p~_ab = (rho_b p_a + rho_a p_b) /
/// (rho_a + rho_b)`.
#[inline(always)]
pub fn inter_particle_pressure<const D: usize>(a: &Point<D>, b: &Point<D>) -> f64 {
    (b.rho * a.p + a.rho * b.p) / (a.rho + b.rho)
}

/// The volume weight of the Adami et al. (2013) forms, `(V_a^2 + V_b^2)/m_a grad W`.
#[inline(always)]
pub fn adami_weight<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    let (va, vb) = (a.v(), b.v());
    ab.dwij * ((va * va + vb * vb) * a.inv_m)
}

/// The Adami et al. (2013) pressure gradient `-(V_a^2 + V_b^2)/m_a p~_ab grad W`. A reference
/// pressure subtracted from `p~_ab` adds [`adami_weight`] per unit.
#[inline(always)]
pub fn pressure_gradient_adami<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    adami_weight(a, b, ab) * -inter_particle_pressure(a, b)
}

/// The artificial stress of the TVF (first term of eq. 19, the `A` terms of eq. 27):
/// `div(u (u~ - u))` as `m_b (A_a/rho_a^2 + A_b/rho_b^2) . grad W` with
/// `A = rho u (x) (u~ - u)`, so that `A . grad W = rho u ((u~ - u) . grad W)`.
#[inline(always)]
pub fn artificial_stress<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    let aa = a.u * (a.du().dot(&ab.dwij) * a.inv_rho);
    let bb = b.u * (b.du().dot(&ab.dwij) * b.inv_rho);
    (aa + bb) * b.m
}

/// The CTVF momentum correction `-u_a div(u~ - u)` (second term of eq. 19), as
/// `u_a V_b (du_a - du_b) . grad W`. Eq. (27) prints `u~_ab` where eq. (19) has
/// `(u~ - u)_ab`; we follow the derivation (eq. 19), as the authors' code does.
#[inline(always)]
pub fn transport_divergence_correction<const D: usize>(
    a: &Point<D>,
    b: &Point<D>,
    ab: &Pair<D>,
) -> Vector<D> {
    a.u * (b.v() * (a.du() - b.du()).dot(&ab.dwij))
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn pressure_pushes_apart_and_is_antisymmetric_in_force() {
        let (ab, ba) = pairs([0.0, 0.0], [0.06, 0.02], 0.1);
        let a = point([0.0; 2], [0.0; 2], 0.01, 1.0, 5.0);
        let b = point([0.0; 2], [0.0; 2], 0.01, 1.0, 5.0);
        let fa = pressure_gradient(&a, &b, &ab) * a.m;
        let fb = pressure_gradient(&b, &a, &ba) * b.m;
        assert!(fa.dot(&ab.xij) > 0.0, "positive pressure repels");
        assert!((fa + fb).norm() < 1e-12 * fa.norm());
        let ga = pressure_gradient_adami(&a, &b, &ab) * a.m;
        let gb = pressure_gradient_adami(&b, &a, &ba) * b.m;
        assert!(ga.dot(&ab.xij) > 0.0);
        assert!((ga + gb).norm() < 1e-12 * ga.norm());
        // Hand value: equal particles, so (V_a^2 + V_b^2)/m_a p = 2 m p / rho^2.
        assert!((ga - fa).norm() < 1e-12 * fa.norm());
        // Subtracting the common pressure as a reference leaves no force.
        let shifted = pressure_gradient_adami(&a, &b, &ab) + adami_weight(&a, &b, &ab) * 5.0;
        assert!(shifted.norm() < 1e-12 * ga.norm());
        let shifted = pressure_gradient(&a, &b, &ab) + pressure_reference_weight(&a, &b, &ab) * 5.0;
        assert!(shifted.norm() < 1e-12 * fa.norm());
    }

    #[test]
    fn shifting_terms_vanish_without_shifting() {
        let (ab, _) = pairs([0.0, 0.0], [0.06, 0.02], 0.1);
        let a = point([0.3, 0.1], [0.3, 0.1], 0.01, 1.0, 1.0);
        let b = point([-0.2, 0.4], [-0.2, 0.4], 0.01, 1.0, 2.0);
        assert_eq!(artificial_stress(&a, &b, &ab).norm(), 0.0);
        assert_eq!(transport_divergence_correction(&a, &b, &ab).norm(), 0.0);
    }
}
