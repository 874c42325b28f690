//! An elastic solid's particles among themselves (CTVF eqs. 25, 30-32): the neighbour list
//! of the body with itself, and what a particle gathers from each neighbour for its
//! density and stress rates ([`RateTerms`]) and for its accelerations ([`AccelTerms`]).
//! The switches are read once per pass, outside the particle loop.

use crate::solver::equations::artificial_viscosity::monaghan_values;
use crate::solver::equations::shifting::{gtvf_pair, sun2019_volume};
use crate::solver::equations::solid::{self, SolidPoint};
use crate::solver::equations::Pair;
use crate::solver::interactions::lists::{build_kernel_list, KernelList};
use crate::solver::kernel::{Kernel, ScaledKernel};
use crate::solver::math::{Matrix, Vector};
use crate::solver::nnps::CellList;
use crate::solver::systems::ElasticSolid;

/// A solid body with itself: its index among the bodies and its neighbour list.
#[derive(Debug)]
pub struct SolidSolid<const D: usize> {
    /// The body's index.
    pub body: usize,
    /// Its particles' neighbours among themselves, with kernel values.
    pub list: KernelList<D>,
}

impl<const D: usize> SolidSolid<D> {
    /// The interaction of body `body` with itself (listed by [`relist`](Self::relist)).
    pub fn new(body: usize) -> Self {
        Self { body, list: KernelList::new() }
    }

    /// Lists the solid's neighbours from `cells`, which binned its current positions.
    pub fn relist(&mut self, cells: &CellList<D>, solid: &ElasticSolid<D>, kernel: &Kernel) {
        build_kernel_list(&mut self.list, cells, &solid.x, solid.h, kernel);
    }
}

/// One particle's sums for its density and stress rates.
#[derive(Clone, Copy, Debug)]
pub struct RateSums<const D: usize> {
    /// d rho/dt, eq. (25), both terms.
    pub drho: f64,
    /// The velocity gradient, eq. (31).
    pub grad_v: Matrix<D>,
    /// The first transport term of eq. (32).
    pub flux: Matrix<D>,
    /// The scalar of the second transport term of eq. (32).
    pub div_du: f64,
}

impl<const D: usize> RateSums<D> {
    /// Nothing summed yet.
    pub fn zero() -> Self {
        Self { drho: 0.0, grad_v: Matrix::zeros(), flux: Matrix::zeros(), div_du: 0.0 }
    }
}

/// The terms of the density and stress rates a scheme evaluates.
#[derive(Clone, Copy, Debug)]
pub struct RateTerms {
    /// The correction terms of eqs. (25) and (32).
    pub corrections: bool,
}

impl RateTerms {
    /// Neighbour `b`'s share of particle `a`'s rate sums.
    #[inline(always)]
    pub fn neighbour<const D: usize>(
        &self,
        s: &mut RateSums<D>,
        a: &SolidPoint<D>,
        b: &SolidPoint<D>,
        ab: &Pair<D>,
    ) {
        s.drho += solid::continuity(a, b, ab);
        s.grad_v += solid::velocity_gradient(a, b, ab);
        if self.corrections {
            s.drho += solid::continuity_correction(a, b, ab);
            s.flux += solid::stress_transport(a, b, ab);
            s.div_du += solid::transport_divergence(a, b, ab);
        }
    }

    /// Particle `a`'s stress rate from its sums, eq. (32): the Jaumann rate of eq. (4) plus,
    /// with the corrections, `flux + sigma'_a div_du`.
    #[inline(always)]
    pub fn stress_rate<const D: usize>(
        &self,
        a: &SolidPoint<D>,
        s: &RateSums<D>,
        shear_modulus: f64,
    ) -> Matrix<D> {
        let rate = solid::jaumann_rate(&a.s, &s.grad_v, shear_modulus);
        if self.corrections {
            rate + s.flux + a.s * s.div_du
        } else {
            rate
        }
    }
}

/// One particle's sums for its accelerations.
#[derive(Clone, Copy, Debug)]
pub struct AccelSums<const D: usize> {
    /// du/dt without the body force: eq. (30) with the artificial viscosity.
    pub acc: Vector<D>,
    /// The sum of the homogenisation before its prefactor: Sun's shifting, eq. (36), or
    /// GTVF's background pressure, eq. (20).
    pub ac: Vector<D>,
}

/// The terms of the accelerations a scheme evaluates.
#[derive(Clone, Copy, Debug)]
pub struct AccelTerms {
    /// The factor on the pair term of eq. (30): 1 ([`momentum_factor`](solid::momentum_factor)).
    pub momentum: f64,
    /// Artificial viscosity `(alpha, c0)`, eq. (28).
    pub viscosity: Option<(f64, f64)>,
    /// Sun's shifting `(W(dx), R, n)`, eq. (36).
    pub sun: Option<(f64, f64, i32)>,
    /// GTVF's homogenisation, eq. (20), with the kernel at h/2.
    pub gtvf: Option<ScaledKernel>,
    /// Monaghan's artificial stress `(W(dx), n)` (Gray et al. 2001, eq. 4.10).
    pub artificial_stress: Option<(f64, i32)>,
}

impl AccelTerms {
    /// Neighbour `b`'s share of particle `a`'s acceleration sums.
    #[inline(always)]
    pub fn neighbour<const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &SolidPoint<D>,
        b: &SolidPoint<D>,
        ab: &Pair<D>,
    ) {
        s.acc += solid::momentum(a, b, ab) * self.momentum;
        self.beside_momentum(s, a, b, ab);
    }

    /// [`neighbour`](Self::neighbour) with the kernel gradient corrected: eq. (30) with
    /// `a`'s correction `l_a` and `b`'s `l_b` ([`solid::momentum_corrected`]); the artificial
    /// viscosity and stress and the shifting as they are.
    #[inline(always)]
    pub fn neighbour_corrected<const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        (a, l_a): (&SolidPoint<D>, &Matrix<D>),
        (b, l_b): (&SolidPoint<D>, &Matrix<D>),
        ab: &Pair<D>,
    ) {
        s.acc += solid::momentum_corrected(a, b, (l_a * ab.dwij, l_b * ab.dwij)) * self.momentum;
        self.beside_momentum(s, a, b, ab);
    }

    /// The terms other than eq. (30)'s pair term.
    #[inline(always)]
    fn beside_momentum<const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &SolidPoint<D>,
        b: &SolidPoint<D>,
        ab: &Pair<D>,
    ) {
        if let Some((alpha, c)) = self.viscosity {
            s.acc += monaghan_values(a.u - b.u, (a.rho, b.rho), b.m, ab, alpha, c);
        }
        if let Some((w_dx, n)) = self.artificial_stress {
            s.acc += solid::artificial_stress_momentum(a, b, ab, w_dx, n);
        }
        if let Some((w_dx, r, n)) = self.sun {
            s.ac += sun2019_volume(b.vol, ab, w_dx, r, n);
        }
        if let Some(half) = &self.gtvf {
            s.ac += gtvf_pair(b.m, ab, half);
        }
    }
}
