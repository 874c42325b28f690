//! Physics terms, one function per term, each citing the equation it discretises.
//!
//! Conventions (those of the CTVF paper and `shared/SEED-NOTES.md`): `a` is the particle
//! being updated, `b` a neighbour, `x_ab = x_a - x_b`, `grad W = grad_a W_ab`,
//! `V_b = m_b / rho_b`, `du = u~ - u` (the shifting part of the transport velocity), and the
//! SPH divergence `(div f)_a = -sum_b V_b f_ab . grad W`. Functions here hold no loops, no
//! allocation and no parallelism: the passes in `scheme` do that.

pub mod artificial_viscosity;
pub mod continuity;
pub mod edac;
pub mod free_surface;
pub mod momentum;
pub mod shifting;
pub mod solid;
pub mod viscosity;
pub mod wall;

use crate::solver::math::Vector;

/// One neighbour pair, computed once per pass and shared by every term.
#[derive(Clone, Copy, Debug)]
pub struct Pair<const D: usize> {
    /// x_a - x_b (minimum image when periodic).
    pub xij: Vector<D>,
    /// |x_ab|^2.
    pub r2: f64,
    /// Smoothing length h_ab.
    pub h: f64,
    /// W_ab.
    pub wij: f64,
    /// grad_a W_ab.
    pub dwij: Vector<D>,
    /// 1 / (r^2 + 0.01 h^2), the regularised inverse distance of eqs. (26), (27), (29).
    pub inv_r2_eps: f64,
    /// `x_ab . grad W / (r^2 + 0.01 h^2)`, the factor of the Morris-form Laplacians
    /// (eqs. 26 and 27), from the kernel's gradient factor as [`regularised_laplacian`].
    pub lap: f64,
}

/// `x_ab . grad W / (r^2 + 0.01 h^2) = f r^2 / (r^2 + 0.01 h^2)` with `f = (1/r) dW/dr`:
/// computed with the kernel values of the list, where it vectorises.
#[inline(always)]
pub fn regularised_laplacian(grad_factor: f64, r2: f64, h: f64) -> f64 {
    grad_factor * r2 / (r2 + eps2(h))
}

impl<const D: usize> Pair<D> {
    /// The pair at difference `xij` (with `r2 = |xij|^2`), kernel value `wij` and gradient
    /// factor `(1/r) dW/dr`.
    #[inline(always)]
    pub fn new(xij: Vector<D>, r2: f64, h: f64, wij: f64, grad_factor: f64) -> Self {
        Self::with_laplacian(xij, r2, h, wij, grad_factor, regularised_laplacian(grad_factor, r2, h))
    }

    /// As [`new`](Self::new), with the Laplacian factor `lap` already computed.
    #[inline(always)]
    pub fn with_laplacian(xij: Vector<D>, r2: f64, h: f64, wij: f64, grad_factor: f64, lap: f64) -> Self {
        Self { xij, r2, h, wij, dwij: xij * grad_factor, inv_r2_eps: 1.0 / (r2 + eps2(h)), lap }
    }

    /// The pair seen by a particle whose kernel gradient is corrected by `l` (Bonet & Lok:
    /// `grad W` becomes `l grad W`, [`solid::correction_matrix`]); nothing else changes.
    #[inline(always)]
    pub fn corrected(&self, l: &crate::solver::math::Matrix<D>) -> Self {
        Self { dwij: l * self.dwij, ..*self }
    }
}

/// The values of one particle a term may read, gathered once per particle and pass, with
/// the quotients every pair would otherwise recompute.
#[derive(Clone, Copy, Debug)]
pub struct Point<const D: usize> {
    /// Momentum velocity u.
    pub u: Vector<D>,
    /// The shifting part of the transport velocity, `u~ - u` (zero without shifting).
    pub du: Vector<D>,
    /// Mass.
    pub m: f64,
    /// Density.
    pub rho: f64,
    /// Pressure.
    pub p: f64,
    /// Volume m / rho.
    pub vol: f64,
    /// 1 / rho,
    pub inv_rho: f64,
    /// 1 / rho^2.
    pub inv_rho2: f64,
    /// 1 / m.
    pub inv_m: f64,
}

impl<const D: usize> Point<D> {
    /// A particle's view from its fields.
    #[inline(always)]
    pub fn new(u: Vector<D>, u_hat: Vector<D>, m: f64, rho: f64, p: f64) -> Self {
        let inv_rho = 1.0 / rho;
        Self {
            u,
            du: u_hat - u,
            m,
            rho,
            p,
            vol: m / rho,
            inv_rho,
            inv_rho2: inv_rho * inv_rho,
            inv_m: 1.0 / m,
        }
    }

    /// Volume m / rho.
    #[inline(always)]
    pub fn v(&self) -> f64 {
        self.vol
    }

    /// u~ - u.
    #[inline(always)]
    pub fn du(&self) -> Vector<D> {
        self.du
    }

    /// The transport velocity u~.
    #[inline(always)]
    pub fn u_hat(&self) -> Vector<D> {
        self.u + self.du
    }
}

/// The regularisation 0.01 h^2 in the denominators of eqs. (26), (27) and (29).
#[inline(always)]
pub(crate) fn eps2(h: f64) -> f64 {
    0.01 * h * h
}

#[cfg(test)]
pub(crate) mod test_support {
    //! Two-particle fixtures shared by the term tests.
    use super::*;
    use crate::solver::kernel::{Kernel, KernelKind};

    pub fn point(u: [f64; 2], u_hat: [f64; 2], m: f64, rho: f64, p: f64) -> Point<2> {
        Point::new(Vector::<2>::from(u), Vector::<2>::from(u_hat), m, rho, p)
    }

    /// The pair (a, b) and the reversed pair (b, a) for positions xa, xb.
    pub fn pairs(xa: [f64; 2], xb: [f64; 2], h: f64) -> (Pair<2>, Pair<2>) {
        let k = Kernel::new(KernelKind::QuinticSpline, 2);
        let make = |xij: Vector<2>| {
            let r2 = xij.norm_squared();
            let (w, f) = k.w_and_grad_factor(r2.sqrt(), h);
            Pair::new(xij, r2, h, w, f)
        };
        let xab = Vector::<2>::from(xa) - Vector::<2>::from(xb);
        (make(xab), make(-xab))
    }
}
