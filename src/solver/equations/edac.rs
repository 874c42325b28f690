//! EDAC pressure evolution (Ramachandran & Puri 2019) with the transport-velocity terms of
//! CTVF eqs. (23), (24) and (26).

use super::{Pair, Point};

/// `nu_edac = alpha h c_s / 8`, eq. (24); alpha = 0.5 is the paper's value.
pub fn nu_edac(alpha: f64, h: f64, cs: f64) -> f64 {
    alpha * h * cs / 8.0
}

/// `-rho c_s^2 div(u)`: the EDAC compressibility term, eq. (22), as `V_b rho_a c_s^2 u_ab .
/// grad W`. Eq. (26) prints `(p_a - rho_a c_s^2) u_ab`; from eq. (23), `(p - rho c_s^2)
/// div(u)` discretises to `(rho_a c_s^2 - p_a) V_b u_ab . grad W` (SEED-NOTES, eq. 26): the
/// printed sign makes compression lower the pressure. The `p_a` part is in
/// [`transport_correction`].
#[inline(always)]
pub fn compressibility<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>, cs2: f64) -> f64 {
    b.v() * a.rho * cs2 * (a.u - b.u).dot(&ab.dwij)
}

/// The transport-velocity correction terms of eq. (23): `p div(u) - p div(u~) +
/// div(p (u~ - u))`, discretised as `V_b (-p_a u_ab + p_a u~_ab - (p du)_ab) . grad W`.
/// With `u~_ab - u_ab = du_a - du_b` the sum is `V_b (p_b - p_a) du_b . grad W`, which is
/// what is evaluated (the continuous terms are `du . grad p`).
#[inline(always)]
pub fn transport_correction<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>) -> f64 {
    b.v() * (b.p - a.p) * b.du().dot(&ab.dwij)
}

/// `nu_edac lap(p)`: the pressure diffusion of eq. (26), in the Morris form
/// `V_b 2 nu (p_a - p_b) x_ab . grad W / (r^2 + 0.01 h^2)`.
///
/// Eq. (26) prints the factor `4 / (rho_a + rho_b)`, which is 2 at unit density (the
/// Taylor-Green vortex and the cavity) but gives the term units of pressure per density
/// otherwise; the continuous term `nu lap(p)` has the factor 2, which is what PySPH's
/// `EDACEquation` computes. We use 2. Where rho0 is not 1 (the dam break and the tank,
/// rho0 = 1000) this diffuses pressure rho0 = 1000 times more than the printed factor,
/// which the authors' code keeps.
#[inline(always)]
pub fn diffusion<const D: usize>(a: &Point<D>, b: &Point<D>, ab: &Pair<D>, nu: f64) -> f64 {
    b.v() * 2.0 * nu * (a.p - b.p) * ab.lap
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;

    #[test]
    fn compression_raises_pressure() {
        let (ab, ba) = pairs([0.0, 0.0], [0.1, 0.0], 0.1);
        let a = point([0.5, 0.0], [0.5, 0.0], 0.01, 1.0, 0.0);
        let b = point([-0.5, 0.0], [-0.5, 0.0], 0.01, 1.0, 0.0);
        assert!(compressibility(&a, &b, &ab, 100.0) > 0.0);
        assert!(compressibility(&b, &a, &ba, 100.0) > 0.0);
    }

    #[test]
    fn diffusion_smooths_and_conserves_for_equal_volumes() {
        let (ab, ba) = pairs([0.0, 0.0], [0.05, 0.04], 0.1);
        let a = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 2.0);
        let b = point([0.0, 0.0], [0.0, 0.0], 0.01, 1.0, 1.0);
        let da = diffusion(&a, &b, &ab, 0.1);
        let db = diffusion(&b, &a, &ba, 0.1);
        assert!(da < 0.0, "the higher pressure must fall");
        assert!((da + db).abs() < 1e-12 * da.abs());
    }

    /// The reduced form equals the terms as discretised, `V_b (-p_a u_ab + p_a u~_ab -
    /// (p du)_ab) . grad W`, to rounding.
    #[test]
    fn reduced_correction_equals_the_discretised_terms() {
        let (ab, _) = pairs([0.0, 0.0], [0.05, 0.04], 0.1);
        let a = point([0.3, 0.1], [0.35, 0.02], 0.01, 1.1, 2.0);
        let b = point([-0.2, 0.4], [-0.1, 0.47], 0.012, 0.9, -1.5);
        let (u_ab, uh_ab) = (a.u - b.u, a.u_hat() - b.u_hat());
        let pdu_ab = a.du() * a.p - b.du() * b.p;
        let full = b.v() * (u_ab * (-a.p) + uh_ab * a.p - pdu_ab).dot(&ab.dwij);
        let reduced = transport_correction(&a, &b, &ab);
        assert!(full.abs() > 1e-3, "{full}");
        assert!((reduced - full).abs() <= 1e-12 * full.abs(), "{reduced} vs {full}");
    }

    #[test]
    fn correction_vanishes_without_shifting() {
        let (ab, _) = pairs([0.0, 0.0], [0.05, 0.04], 0.1);
        let a = point([0.3, 0.1], [0.3, 0.1], 0.01, 1.0, 2.0);
        let b = point([-0.2, 0.4], [-0.2, 0.4], 0.01, 1.0, 1.0);
        assert!(transport_correction(&a, &b, &ab).abs() < 1e-14);
    }

    #[test]
    fn nu_edac_matches_eq_24() {
        assert_eq!(nu_edac(0.5, 0.02, 10.0), 0.5 * 0.02 * 10.0 / 8.0);
    }
}
