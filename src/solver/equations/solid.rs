//! Elastic solids (CTVF sec. 2-3): the continuity equation with its transport-velocity
//! correction (eq. 25), the velocity gradient (eq. 31), the Jaumann stress rate with its
//! transport terms (eqs. 4, 21, 32) and the solid momentum equation (eq. 30), one function
//! per term.
//!
//! Conventions as in [`super`]: `a` the particle being updated, `b` a neighbour,
//! `x_ab = x_a - x_b`, `grad W = grad_a W_ab`, `V_b = m_b / rho_b`, `du = u~ - u`, and the
//! SPH divergence `(div f)_a = -sum_b V_b f_ab . grad W`. The deviatoric stress sigma' is a
//! symmetric D x D [`Matrix`]; in 2D the model is plane strain, as in the paper (its
//! deviator subtracts a third of the trace, eq. 4, and sigma'_zz is not tracked).

use super::Pair;
use crate::solver::math::{Matrix, Vector};

/// The values of one solid particle a term may read, gathered once per pass.
#[derive(Clone, Copy, Debug)]
pub struct SolidPoint<const D: usize> {
    /// Momentum velocity u.
    pub u: Vector<D>,
    /// The velocity the velocity gradient is taken of: u (CTVF, eq. 31) or u~ (GTVF).
    pub v_grad: Vector<D>,
    /// The shifting part of the transport velocity, `u~ - u` (zero without shifting).
    pub du: Vector<D>,
    /// Mass.
    pub m: f64,
    /// Density.
    pub rho: f64,
    /// Pressure.
    pub p: f64,
    /// Deviatoric stress sigma'.
    pub s: Matrix<D>,
    /// Volume m / rho.
    pub vol: f64,
    /// Monaghan's artificial stress R / rho^2 of the particle ([`artificial_stress`]);
    /// zero unless the scheme has it.
    pub r_art: Matrix<D>,
}

impl<const D: usize> SolidPoint<D> {
    /// The view of a particle of velocity `u`, gradient velocity `v_grad`, shifting part
    /// `du`, mass `m`, density `rho`, pressure `p` and deviatoric stress `s`.
    #[inline(always)]
    pub fn new(
        u: Vector<D>,
        v_grad: Vector<D>,
        du: Vector<D>,
        m: f64,
        rho: f64,
        p: f64,
        s: Matrix<D>,
    ) -> Self {
        Self { u, v_grad, du, m, rho, p, s, vol: m / rho, r_art: Matrix::zeros() }
    }

    /// The same particle with its artificial stress computed ([`artificial_stress`]).
    #[inline(always)]
    pub fn with_artificial_stress(self, eps: f64) -> Self {
        Self { r_art: artificial_stress(&self.s, self.p, self.rho, eps), ..self }
    }

    /// The transport velocity u~ = u + du.
    #[inline(always)]
    pub fn u_hat(&self) -> Vector<D> {
        self.u + self.du
    }
}

/// Eq. (25), first term: `rho_a V_b u~_ab . grad W`, which is `-rho div(u~)` of eq. (12).
#[inline(always)]
pub fn continuity<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> f64 {
    a.rho * b.vol * (a.u_hat() - b.u_hat()).dot(&ab.dwij)
}

/// Eq. (25), correction term: `-V_b (rho (u~ - u))_ab . grad W`, which is
/// `+div(rho (u~ - u))` of eq. (12). Eq. (25) prints a plus sign; the minus follows from
/// eq. (12) (`shared/SEED-NOTES.md`, "Eq. (25)").
#[inline(always)]
pub fn continuity_correction<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> f64 {
    -b.vol * (a.du * a.rho - b.du * b.rho).dot(&ab.dwij)
}

/// Eq. (31): one neighbour's share of the velocity gradient,
/// `-V_b (v_a - v_b) (x) grad W`, entry `(i, j)` approximating `d v_i / d x_j`, with `v`
/// the particle's [`v_grad`](SolidPoint::v_grad).
#[inline(always)]
pub fn velocity_gradient<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> Matrix<D> {
    (a.v_grad - b.v_grad) * ab.dwij.transpose() * -b.vol
}

/// Eq. (32), first correction: `-V_b (sigma' (x) (u~ - u))_ab . grad W`, entry `(i, j)`
/// the sum over `k` of `(sigma'_ij du_k)_ab dW/dx_k`; it is `+d/dx_k (sigma'_ij du_k)` of
/// eq. (21). Eq. (32) prints a plus sign, the slip of eq. (25)
/// (`shared/SEED-NOTES.md`, "Eq. (32)").
#[inline(always)]
pub fn stress_transport<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> Matrix<D> {
    (a.s * a.du.dot(&ab.dwij) - b.s * b.du.dot(&ab.dwij)) * -b.vol
}

/// Eq. (32), second correction, one neighbour's share of the scalar it multiplies
/// `sigma'_a` by: `V_b (u~ - u)_ab . grad W`, which is `-div(u~ - u)` (eq. 21's
/// `-sigma' d/dx_k (u~_k - u_k)`; printed correctly).
#[inline(always)]
pub fn transport_divergence<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> f64 {
    b.vol * (a.du - b.du).dot(&ab.dwij)
}

/// Eq. (4) (and the first terms of eqs. 21 and 32): the Jaumann rate of Hooke's deviatoric
/// stress, `2G (eps' - tr(eps')/3 I) + sigma' Omega^T + Omega sigma'`, from the velocity
/// gradient `grad_u` (entry `(i, j)` = `d u_i / d x_j`), with the strain rate
/// `eps' = (grad_u + grad_u^T)/2` (eq. 5) and the rotation rate
/// `Omega = (grad_u - grad_u^T)/2` (eq. 6). `sigma'_ik Omega_jk` of eq. (4) is
/// `(sigma' Omega^T)_ij`.
#[inline(always)]
pub fn jaumann_rate<const D: usize>(s: &Matrix<D>, grad_u: &Matrix<D>, shear_modulus: f64) -> Matrix<D> {
    let eps = (grad_u + grad_u.transpose()) * 0.5;
    let omega = (grad_u - grad_u.transpose()) * 0.5;
    let deviator = eps - Matrix::<D>::identity() * (eps.trace() / 3.0);
    deviator * (2.0 * shear_modulus) + s * omega.transpose() + omega * s
}

/// A factor on the pair term of eq. (30), [`momentum`]: 1, unless the environment variable
/// `SPHREPRO_PERTURB_SOLID_MOMENTUM` gives another (read once per process). It exists for the
/// test of the regression guard, `check --baseline`: a change to one term's arithmetic must
/// fail the baselines of the problems that use it and no others. (A factor of 1 changes no
/// bit.)
pub fn momentum_factor() -> f64 {
    static FACTOR: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *FACTOR.get_or_init(|| {
        std::env::var("SPHREPRO_PERTURB_SOLID_MOMENTUM").ok().and_then(|v| v.parse().ok()).unwrap_or(1.0)
    })
}

/// Eq. (30) without its artificial viscosity: `-m_b [(p_a/rho_a^2 + p_b/rho_b^2) I
/// - (sigma'_a/rho_a^2 + sigma'_b/rho_b^2)] grad W`. Monaghan's `Pi_ab` is grouped with
/// the pressure (`-m_b Pi_ab grad W`,
/// [`monaghan_values`](super::artificial_viscosity::monaghan_values)), not with the
/// deviatoric stress as printed (`shared/SEED-NOTES.md`, "Eq. (30)").
#[inline(always)]
pub fn momentum<const D: usize>(a: &SolidPoint<D>, b: &SolidPoint<D>, ab: &Pair<D>) -> Vector<D> {
    let (ia, ib) = (1.0 / (a.rho * a.rho), 1.0 / (b.rho * b.rho));
    let pressure = ab.dwij * (a.p * ia + b.p * ib);
    let deviatoric = (a.s * ia + b.s * ib) * ab.dwij;
    (pressure - deviatoric) * -b.m
}

/// The kernel-gradient correction (Bonet & Lok 1999, eq. 47; Randles & Libersky 1996), one
/// neighbour's share of the matrix it inverts: `V_b grad W (x) x_ba`, with
/// `x_ba = x_b - x_a = -x_ab`. Summed over a full support it is the identity (a lattice's
/// first moment); at a free surface, where half the support is empty, it is not, and the
/// SPH gradient of a linear field is off by it.
#[inline(always)]
pub fn correction_moment<const D: usize>(vol_b: f64, ab: &Pair<D>) -> Matrix<D> {
    ab.dwij * ab.xij.transpose() * -vol_b
}

/// The correction matrix `L_a = (sum_b V_b grad W (x) x_ba)^-1` from the summed
/// [`correction_moment`], so that the corrected gradient `L_a grad W_ab` makes the SPH
/// gradient of any linear field exact (`sum_b V_b (f_b - f_a) (x) L_a grad W = grad f`).
/// A particle whose neighbours do not span the space (a chain, a lone particle: the moment
/// singular, or so nearly that an entry of its inverse exceeds 1e3, where a full support
/// gives 1 and a corner's quarter support about 4) keeps the plain gradient (the identity).
#[inline(always)]
pub fn correction_matrix<const D: usize>(moment: &Matrix<D>) -> Matrix<D> {
    match moment.try_inverse() {
        Some(l) if l.iter().all(|v| v.abs() <= 1e3) => l,
        _ => Matrix::identity(),
    }
}

/// Eq. (30) with each particle's corrected kernel gradient: `-m_b [(p_a/rho_a^2 - sigma'_a
/// /rho_a^2) g_a + (p_b/rho_b^2 - sigma'_b/rho_b^2) g_b]` with `g_a = L_a grad W_ab`,
/// `g_b = L_b grad W_ab` ([`correction_matrix`]): the symmetric form of Bonet & Lok's
/// corrected SPH (their eq. 51) in which the pair's forces on a and b are equal and
/// opposite, so momentum is conserved; with `L = I` it is [`momentum`].
#[inline(always)]
pub fn momentum_corrected<const D: usize>(
    a: &SolidPoint<D>,
    b: &SolidPoint<D>,
    (g_a, g_b): (Vector<D>, Vector<D>),
) -> Vector<D> {
    let (ia, ib) = (1.0 / (a.rho * a.rho), 1.0 / (b.rho * b.rho));
    let pressure = g_a * (a.p * ia) + g_b * (b.p * ib);
    let deviatoric = a.s * g_a * ia + b.s * g_b * ib;
    (pressure - deviatoric) * -b.m
}

/// The second invariant of a deviatoric stress, `J2 = sigma':sigma' / 2`. In 2D plane
/// strain the deviator has an out-of-plane component too: the stress deviator's trace is
/// zero, so `sigma'_zz = -(sigma'_xx + sigma'_yy)`, which the in-plane components tracked
/// (eq. 4 subtracts a third of the trace) determine; it counts in J2, and so in the von
/// Mises stress and the yield test of sec. 4.7.
#[inline(always)]
pub fn j2<const D: usize>(s: &Matrix<D>) -> f64 {
    let out_of_plane = if D == 2 { s.trace().powi(2) } else { 0.0 };
    0.5 * (s.component_mul(s).sum() + out_of_plane)
}

/// The radial return of an elastic-perfectly-plastic material onto the von Mises yield
/// surface (CTVF sec. 4.7): `sigma' <- sqrt(beta) sigma'` with
/// `beta = min(Y0^2 / (3 J2), 1)`, J2 with the out-of-plane component in 2D ([`j2`]),
/// which scales with the in-plane ones. The paper prints the factor as beta; scaling sigma' by f
/// scales J2 by f^2, so the return onto `sqrt(3 J2) = Y0` takes sqrt(beta)
/// (`shared/SEED-NOTES.md`, "Section 4.7").
#[inline(always)]
pub fn radial_return<const D: usize>(s: &Matrix<D>, y0: f64) -> Matrix<D> {
    let j2 = j2(s);
    if 3.0 * j2 > y0 * y0 {
        s * (y0 * y0 / (3.0 * j2)).sqrt()
    } else {
        *s
    }
}

/// The von Mises stress `sqrt(3 J2)` of a deviatoric stress.
#[inline(always)]
pub fn von_mises<const D: usize>(s: &Matrix<D>) -> f64 {
    (3.0 * j2(s)).sqrt()
}

/// The von Mises stress of a 2D total stress `sigma` from its principal stresses
/// (eqs. 68-70): `sqrt(s1^2 + s2^2 - s1 s2)` with
/// `s1,2 = (sxx + syy)/2 +- sqrt(((sxx - syy)/2)^2 + sxy^2)`. Eqs. (69)-(70) print `((sxx + syy)/2)^2` under the root, which is not the
/// principal stresses' formula (Mohr's circle has radius `(sxx - syy)/2`); the two agree
/// when one of sxx, syy is zero and sxy is, as at the centre of a uniaxial specimen.
pub fn von_mises_principal(sigma: &Matrix<2>) -> f64 {
    let mean = 0.5 * (sigma[(0, 0)] + sigma[(1, 1)]);
    let radius = (0.25 * (sigma[(0, 0)] - sigma[(1, 1)]).powi(2) + sigma[(0, 1)].powi(2)).sqrt();
    let (s1, s2) = (mean + radius, mean - radius);
    (s1 * s1 + s2 * s2 - s1 * s2).max(0.0).sqrt()
}

/// Monaghan's artificial stress (Monaghan 2000; Gray, Monaghan & Swift 2001, eqs. 4.7-4.9)
/// divided by rho^2: in the principal frame of the total stress `sigma = -p I + sigma'`,
/// `R_ii = -eps sigma_ii / rho^2` where `sigma_ii > 0` (tension) and 0 where not, rotated
/// back. It repels particles that tension would pull into clumps (the tensile instability).
pub fn artificial_stress<const D: usize>(s: &Matrix<D>, p: f64, rho: f64, eps: f64) -> Matrix<D> {
    let sigma = s - Matrix::<D>::identity() * p;
    // nalgebra's eigen-decomposition of a const-generic D x D matrix needs bounds a
    // const D does not meet: decompose a dynamic copy (gray is a comparison scheme).
    let eig = nalgebra::DMatrix::from_column_slice(D, D, sigma.as_slice()).symmetric_eigen();
    let r = eig.eigenvalues.map(|l| if l > 0.0 { -eps * l / (rho * rho) } else { 0.0 });
    let q = Matrix::<D>::from_column_slice(eig.eigenvectors.as_slice());
    q * Matrix::<D>::from_diagonal(&Vector::<D>::from_column_slice(r.as_slice())) * q.transpose()
}

/// The artificial-stress term of Gray et al. (2001) eq. (4.10) in the momentum equation:
/// `m_b (R_a/rho_a^2 + R_b/rho_b^2) f_ab^n grad W`, `f_ab = W_ab / W(dx)`.
#[inline(always)]
pub fn artificial_stress_momentum<const D: usize>(
    a: &SolidPoint<D>,
    b: &SolidPoint<D>,
    ab: &Pair<D>,
    w_dx: f64,
    n: i32,
) -> Vector<D> {
    let f = (ab.wij / w_dx).powi(n);
    (a.r_art + b.r_art) * ab.dwij * (b.m * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(xa: [f64; 2], xb: [f64; 2], h: f64) -> Pair<2> {
        // A made-up kernel: W = 1, (1/r) dW/dr = -2, so grad W = -2 x_ab.
        let xij = Vector::<2>::from(xa) - Vector::<2>::from(xb);
        Pair::new(xij, xij.norm_squared(), h, 1.0, -2.0)
    }

    fn pt(u: [f64; 2], du: [f64; 2], m: f64, rho: f64, p: f64, s: [[f64; 2]; 2]) -> SolidPoint<2> {
        let s = Matrix::<2>::new(s[0][0], s[0][1], s[1][0], s[1][1]);
        SolidPoint::new(u.into(), u.into(), du.into(), m, rho, p, s)
    }

    /// The radial return (sec. 4.7) puts any stress beyond the yield surface on it, keeps
    /// its direction, and leaves a stress inside untouched.
    #[test]
    fn radial_return_caps_the_von_mises_stress_at_y0() {
        let y0 = 3.0e8;
        let inside = Matrix::<2>::new(1.0e8, 2.0e7, 2.0e7, -5.0e7);
        assert_eq!(radial_return(&inside, y0), inside);
        let beyond = inside * 10.0;
        let r = radial_return(&beyond, y0);
        assert!((von_mises(&r) - y0).abs() < 1e-9 * y0, "{}", von_mises(&r));
        let ratio = r.component_div(&beyond);
        assert!(ratio.iter().all(|&f| (f - ratio[0]).abs() < 1e-12), "direction kept");
    }

    /// Plane strain by hand: the in-plane deviator diag(2, 1) (sigma'_zz = -3) has
    /// J2 = (4 + 1 + 9) / 2 = 7, so sqrt(3 J2) = sqrt(21); returned onto Y0 = 3 it becomes
    /// diag(2, 1) 3 / sqrt(21), whose von Mises stress (out-of-plane part included) is 3.
    #[test]
    fn plane_strain_j2_counts_the_out_of_plane_deviator() {
        let s = Matrix::<2>::new(2.0, 0.0, 0.0, 1.0);
        assert!((j2(&s) - 7.0).abs() < 1e-15);
        assert!((von_mises(&s) - 21f64.sqrt()).abs() < 1e-14);
        let r = radial_return(&s, 3.0);
        assert!((r - s * (3.0 / 21f64.sqrt())).norm() < 1e-15, "{r}");
        assert!((von_mises(&r) - 3.0).abs() < 1e-14);
        // A pure shear has no out-of-plane part: J2 = tau^2.
        assert!((j2(&Matrix::<2>::new(0.0, 2.0, 2.0, 0.0)) - 4.0).abs() < 1e-15);
    }

    /// Eqs. (68)-(70) by hand: a uniaxial stress of -3 has von Mises stress 3; a pure shear
    /// of 2 has principal stresses +-2, so sqrt(4 + 4 + 4) = 2 sqrt(3); an equal biaxial
    /// stress of 5 has sqrt(25 + 25 - 25) = 5 (eq. 68 is the plane-stress form).
    #[test]
    fn von_mises_from_principal_stresses() {
        assert!((von_mises_principal(&Matrix::<2>::new(0.0, 0.0, 0.0, -3.0)) - 3.0).abs() < 1e-15);
        let shear = Matrix::<2>::new(0.0, 2.0, 2.0, 0.0);
        assert!((von_mises_principal(&shear) - 2.0 * 3f64.sqrt()).abs() < 1e-14);
        assert!((von_mises_principal(&(Matrix::<2>::identity() * 5.0)) - 5.0).abs() < 1e-12);
    }

    /// Artificial stress by hand: a uniaxial tension sigma_xx = 4 (p = 0, rho = 2) gives
    /// R_xx = -eps 4 / 4 = -eps and nothing else; a compression gives none; rotated by 45
    /// degrees, R rotates with it.
    #[test]
    fn artificial_stress_acts_on_tension_only() {
        let eps = 0.3;
        let tension = Matrix::<2>::new(4.0, 0.0, 0.0, 0.0);
        let r = artificial_stress(&tension, 0.0, 2.0, eps);
        assert!((r - Matrix::<2>::new(-eps, 0.0, 0.0, 0.0)).norm() < 1e-14, "{r}");
        assert_eq!(artificial_stress(&(-tension), 0.0, 2.0, eps), Matrix::<2>::zeros());
        // p = -4 is a tension of 4 in both directions.
        let r = artificial_stress(&Matrix::<2>::zeros(), -4.0, 2.0, eps);
        assert!((r - Matrix::<2>::identity() * -eps).norm() < 1e-14, "{r}");
        let q = nalgebra::Rotation2::new(std::f64::consts::FRAC_PI_4).into_inner();
        let r = artificial_stress(&(q * tension * q.transpose()), 0.0, 2.0, eps);
        let want = q * Matrix::<2>::new(-eps, 0.0, 0.0, 0.0) * q.transpose();
        assert!((r - want).norm() < 1e-14, "{r} against {want}");
    }

    /// Two particles by hand: x_ab = (0.1, 0), so grad W = (-0.2, 0); b of volume 0.5.
    /// Every value below is worked out on paper from the formulas of the doc comments.
    #[test]
    fn two_particle_hand_values() {
        let ab = pair([0.1, 0.0], [0.0, 0.0], 0.1);
        let s_a = [[1.0, 2.0], [2.0, -1.0]];
        let s_b = [[3.0, 0.0], [0.0, 5.0]];
        let a = pt([1.0, 2.0], [0.5, 0.0], 1.0, 2.0, 4.0, s_a);
        let b = pt([0.0, 1.0], [0.0, 0.5], 1.0, 2.0, 8.0, s_b);
        // u~_a = (1.5, 2), u~_b = (0, 1.5): u~_ab = (1.5, 0.5); . grad W = -0.3;
        // rho_a V_b = 2 * 0.5 = 1.
        assert!((continuity(&a, &b, &ab) - -0.3).abs() < 1e-15);
        // (rho du)_ab = (1, 0) - (0, 1) = (1, -1); . grad W = -0.2; times -V_b = 0.1.
        assert!((continuity_correction(&a, &b, &ab) - 0.1).abs() < 1e-15);
        // -V_b u_ab (x) grad W = -0.5 (1, 1)^T (-0.2, 0) = [[0.1, 0], [0.1, 0]].
        let g = velocity_gradient(&a, &b, &ab);
        assert!((g - Matrix::<2>::new(0.1, 0.0, 0.1, 0.0)).norm() < 1e-15, "{g}");
        // du_a . grad W = -0.1, du_b . grad W = 0: -0.5 (sigma_a (-0.1)) = 0.05 sigma_a.
        let t = stress_transport(&a, &b, &ab);
        assert!((t - Matrix::<2>::new(0.05, 0.1, 0.1, -0.05)).norm() < 1e-15, "{t}");
        // V_b (du_a - du_b) . grad W = 0.5 (0.5, -0.5) . (-0.2, 0) = -0.05.
        assert!((transport_divergence(&a, &b, &ab) - -0.05).abs() < 1e-15);
        // 1/rho^2 = 1/4: pressure (4 + 8)/4 = 3, deviatoric (s_a + s_b)/4 = [[1, .5], [.5, 1]];
        // [3 I - that] grad W = [[2, -.5], [-.5, 2]] (-0.2, 0) = (-0.4, 0.1); times -m_b.
        let f = momentum(&a, &b, &ab);
        assert!((f - Vector::<2>::new(0.4, -0.1)).norm() < 1e-15, "{f}");
    }

    /// Eq. (4) by hand: a simple shear `d u_x / d y = 1` of an unstressed particle gives
    /// `sigma'_xy` rate `G`; a uniform compression gives no deviatoric rate in the
    /// deviator's trace; the stress rate of a stressed particle under the same shear adds
    /// the rotation terms.
    #[test]
    fn jaumann_rate_by_hand() {
        let g = 3.0;
        let shear = Matrix::<2>::new(0.0, 1.0, 0.0, 0.0);
        let r = jaumann_rate(&Matrix::zeros(), &shear, g);
        assert!((r - Matrix::<2>::new(0.0, g, g, 0.0)).norm() < 1e-15, "{r}");
        // Plane strain: tr(eps) = 2 for grad u = I, eps' = I - 2/3 I = I/3, rate 2G/3 I.
        let r = jaumann_rate(&Matrix::zeros(), &Matrix::<2>::identity(), g);
        assert!((r - Matrix::<2>::identity() * (2.0 * g / 3.0)).norm() < 1e-15, "{r}");
        // Omega = [[0, 1/2], [-1/2, 0]]; sigma' = diag(1, -1): sigma' Omega^T + Omega sigma'
        // = [[0, -1/2], [-1/2, 0]] + [[0, -1/2], [-1/2, 0]] = [[0, -1], [-1, 0]].
        let s = Matrix::<2>::new(1.0, 0.0, 0.0, -1.0);
        let r = jaumann_rate(&s, &shear, g);
        assert!((r - Matrix::<2>::new(0.0, g - 1.0, g - 1.0, 0.0)).norm() < 1e-15, "{r}");
    }

    /// Objectivity: under a rigid rotation (an antisymmetric velocity gradient) the
    /// Jaumann rate only rotates the stress, so its invariants do not change. The rate of
    /// J2 is `sigma' : rate`, which is zero to rounding; integrated over a quarter turn
    /// (RK4, 400 steps), the trace and J2 keep their values to 1e-10 and the stress turns
    /// with the body.
    #[test]
    fn a_rigid_rotation_leaves_the_stress_invariants_unchanged() {
        let w = 2.0; // angular velocity: grad u = [[0, -w], [w, 0]]
        let spin = Matrix::<2>::new(0.0, -w, w, 0.0);
        let s0 = Matrix::<2>::new(1.5, 0.7, 0.7, -0.4);
        let rate = |s: &Matrix<2>| jaumann_rate(s, &spin, 10.0);
        assert!(s0.component_mul(&rate(&s0)).sum().abs() < 1e-14, "d J2/dt = 0");
        let (t_end, n) = (std::f64::consts::FRAC_PI_2 / w, 400);
        let dt = t_end / n as f64;
        let mut s = s0;
        for _ in 0..n {
            let k1 = rate(&s);
            let k2 = rate(&(s + k1 * (0.5 * dt)));
            let k3 = rate(&(s + k2 * (0.5 * dt)));
            let k4 = rate(&(s + k3 * dt));
            s += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        }
        assert!((s.trace() - s0.trace()).abs() < 1e-10);
        assert!((j2(&s) - j2(&s0)).abs() < 1e-10 * j2(&s0));
        // A quarter turn: R s0 R^T with R the rotation by pi/2.
        let rot = Matrix::<2>::new(0.0, -1.0, 1.0, 0.0);
        let expected = rot * s0 * rot.transpose();
        assert!((s - expected).norm() < 1e-9, "{s} against {expected}");
    }

    /// A uniform field gives no rates: the terms are differences over the pair.
    #[test]
    fn uniform_fields_give_no_rates() {
        let ab = pair([0.1, 0.05], [0.0, 0.0], 0.1);
        let s = [[1.0, 0.3], [0.3, -2.0]];
        let a = pt([1.0, 2.0], [0.5, 0.1], 1.0, 2.0, 4.0, s);
        let b = a;
        assert_eq!(continuity(&a, &b, &ab), 0.0);
        assert_eq!(continuity_correction(&a, &b, &ab), 0.0);
        assert_eq!(velocity_gradient(&a, &b, &ab), Matrix::<2>::zeros());
        assert_eq!(stress_transport(&a, &b, &ab), Matrix::<2>::zeros());
        assert_eq!(transport_divergence(&a, &b, &ab), 0.0);
    }
}
