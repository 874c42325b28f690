//! Fluid-fluid: what a fluid particle gathers from a fluid neighbour, and the fluid's own
//! neighbour list. The terms a scheme declares are bits of a plan
//! ([`plan`](crate::solver::scheme::plan)), compiled into the loops of the named schemes, so
//! that the per-neighbour functions here check nothing at run time for them.
//!
//! Pass A gathers the density and pressure rates (eqs. 25-26), pass B the acceleration
//! (eq. 27 or its Adami form, viscosity, artificial viscosity, the transport-velocity
//! terms) and the homogenisation acceleration of a background pressure or of Sun et al.
//! (2019). A boundary neighbour adds the same terms seen through its extrapolated values,
//! without those that need a transport velocity ([`fluid_boundary`](super::fluid_boundary)).

use super::lists::{build_kernel_list, build_kernel_list_summing_density, KernelList};
use crate::solver::equations::{
    artificial_viscosity, continuity, edac, momentum, shifting, viscosity, Pair, Point,
};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::CellList;
use crate::solver::scheme::{plan, DensityModel, FluidScheme, PressureGradient, PressureModel, Shifting};
use crate::solver::systems::Fluid;

/// The fluid's neighbour list among its own particles and, with a summation density, its
/// own share of each particle's density, summed as the list is built.
#[derive(Debug, Default)]
pub struct FluidFluid<const D: usize> {
    /// The fluid's index among the bodies.
    pub body: usize,
    /// The list, with the kernel values of each pair.
    pub list: KernelList<D>,
    /// `sum_b m_b W_ab` over the fluid's own particles (with a summation density).
    pub density: Vec<f64>,
}

impl<const D: usize> FluidFluid<D> {
    /// The coupling of fluid `body` with itself, not listed yet.
    pub fn new(body: usize) -> Self {
        Self { body, ..Self::default() }
    }

    /// Lists the neighbours of `fluid` (binned by `cells` in its current order), summing
    /// the fluid's share of the summation density if its scheme declares one.
    pub fn relist(&mut self, cells: &CellList<D>, fluid: &Fluid<D>, kernel: &Kernel) {
        if fluid.physics.density == DensityModel::Summation {
            let own = (&fluid.x[..], &fluid.m[..], fluid.h);
            build_kernel_list_summing_density(&mut self.list, cells, own, kernel, &mut self.density);
        } else {
            build_kernel_list(&mut self.list, cells, &fluid.x, fluid.h, kernel);
        }
    }
}

/// The terms of pass A a scheme declares: its plan and the EDAC constants.
#[derive(Clone, Copy, Debug)]
pub struct RateTerms {
    /// The plan's bits of pass A.
    pub plan: u32,
    /// EDAC's `c_s^2` and `nu_edac`.
    pub cs2: f64,
    /// nu_edac of eq. (24).
    pub nu: f64,
}

impl RateTerms {
    /// The terms of `s`.
    pub fn new(s: &FluidScheme) -> Self {
        let corr = s.transport.map(|t| t.corrections);
        let continuity = s.density == DensityModel::Continuity;
        let (edac, cs2, nu) = match s.pressure {
            PressureModel::Edac { cs, nu } => (true, cs * cs, nu),
            PressureModel::StateEquation { .. } => (false, 0.0, 0.0),
        };
        let plan = plan::bit(edac, plan::EDAC)
            | plan::bit(edac && corr.is_some_and(|c| c.pressure), plan::PRESSURE_CORR)
            | plan::bit(continuity, plan::CONTINUITY)
            | plan::bit(continuity && corr.is_some_and(|c| c.continuity), plan::CONTINUITY_CORR);
        Self { plan, cs2, nu }
    }

    /// Adds fluid neighbour `b`'s share of `(dp/dt, drho/dt)` of particle `a` under plan `P`:
    /// eq. (26) and eq. (25), each with its correction if declared.
    #[inline(always)]
    pub fn fluid_neighbour<const P: u32, const D: usize>(
        &self,
        (dp, drho): &mut (f64, f64),
        a: &Point<D>,
        b: &Point<D>,
        ab: &Pair<D>,
    ) {
        let has = |t| plan::has::<P>(self.plan, t);
        if has(plan::EDAC) {
            *dp += edac::compressibility(a, b, ab, self.cs2) + edac::diffusion(a, b, ab, self.nu);
            if has(plan::PRESSURE_CORR) {
                *dp += edac::transport_correction(a, b, ab);
            }
        }
        if has(plan::CONTINUITY) {
            *drho += continuity::transport_divergence(a, b, ab);
            if has(plan::CONTINUITY_CORR) {
                *drho += continuity::correction(a, b, ab);
            }
        }
    }
}

/// The per-particle sums of pass B.
#[derive(Clone, Copy, Debug)]
pub struct AccelSums<const D: usize> {
    /// Acceleration.
    pub acc: Vector<D>,
    /// Homogenisation acceleration (before its prefactor).
    pub ac: Vector<D>,
    /// BQL: the weights of the reference pressure,
    pub c_ref: Vector<D>,
    /// and the neighbours' pressures,
    pub p_sum: f64,
    /// and their number, for its mean.
    pub n_nb: usize,
}

impl<const D: usize> AccelSums<D> {
    /// Nothing summed yet.
    #[inline(always)]
    pub fn zero() -> Self {
        Self { acc: Vector::zeros(), ac: Vector::zeros(), c_ref: Vector::zeros(), p_sum: 0.0, n_nb: 0 }
    }
}

/// The terms of pass B a scheme declares: the plan and the terms' constants.
#[derive(Clone, Copy, Debug)]
pub struct AccelTerms {
    /// The plan's bits of pass B.
    pub plan: u32,
    /// Kinematic viscosity.
    pub nu: f64,
    /// Artificial viscosity `(alpha, c)`.
    pub av: (f64, f64),
    /// Background pressure.
    pub pb: f64,
    /// Sun 2019: `(W(dx), R, n)`.
    pub sun: (f64, f64, i32),
}

impl AccelTerms {
    /// The terms of `s`.
    pub fn new(s: &FluidScheme) -> Self {
        let shifting = s.transport.map(|t| t.shifting);
        let (adami, bql) = match s.pressure_gradient {
            PressureGradient::Symmetric { bql } => (false, bql),
            PressureGradient::Adami { bql } => (true, bql),
        };
        let plan = plan::bit(adami, plan::ADAMI)
            | plan::bit(bql, plan::BQL)
            | plan::bit(s.viscosity.is_some(), plan::VISCOSITY)
            | plan::bit(s.artificial_viscosity.is_some(), plan::ARTIFICIAL_VISCOSITY)
            | plan::bit(s.transport.is_some(), plan::TRANSPORT)
            | plan::bit(s.transport.is_some_and(|t| t.corrections.momentum), plan::MOMENTUM_CORR)
            | plan::bit(
                matches!(shifting, Some(Shifting::BackgroundPressure { .. })),
                plan::BACKGROUND_PRESSURE,
            )
            | plan::bit(matches!(shifting, Some(Shifting::Sun2019 { .. })), plan::SUN2019);
        let (mut pb, mut sun) = (0.0, (0.0, 0.0, 0));
        match shifting {
            Some(Shifting::BackgroundPressure { pb: p }) => pb = p,
            Some(Shifting::Sun2019 { w_dx, r, n, .. }) => sun = (w_dx, r, n),
            _ => {}
        }
        Self {
            plan,
            nu: s.viscosity.unwrap_or(0.0),
            av: s.artificial_viscosity.unwrap_or((0.0, 0.0)),
            pb,
            sun,
        }
    }

    /// Whether term `t` is on under plan `P`.
    #[inline(always)]
    pub fn has<const P: u32>(&self, t: u32) -> bool {
        plan::has::<P>(self.plan, t)
    }

    /// Adds fluid neighbour `b`'s share of particle `a`'s sums under plan `P`.
    #[inline(always)]
    pub fn fluid_neighbour<const P: u32, const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        b: &Point<D>,
    ) {
        self.pressure_and_viscous::<P, D>(s, a, ab, [b, b, b]);
        if self.has::<P>(plan::TRANSPORT) {
            s.acc += momentum::artificial_stress(a, b, ab);
            if self.has::<P>(plan::MOMENTUM_CORR) {
                s.acc += momentum::transport_divergence_correction(a, b, ab);
            }
            self.homogenisation::<P, D>(s, a, ab, b);
        }
    }

    /// The pressure gradient (eq. 27 or Adami's, with the BQL reference's weights and the
    /// neighbours' pressures if declared) with neighbour `b` as the divergence terms see
    /// it, the viscosity with `b_visc` and the artificial viscosity with `b_av` as they see it
    /// (the three differ for a boundary).
    #[inline(always)]
    pub fn pressure_and_viscous<const P: u32, const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        [b, b_visc, b_av]: [&Point<D>; 3],
    ) {
        if self.has::<P>(plan::ADAMI) {
            s.acc += momentum::pressure_gradient_adami(a, b, ab);
            if self.has::<P>(plan::BQL) {
                s.c_ref += momentum::adami_weight(a, b, ab);
            }
        } else {
            s.acc += momentum::pressure_gradient(a, b, ab);
            if self.has::<P>(plan::BQL) {
                s.c_ref += momentum::pressure_reference_weight(a, b, ab);
            }
        }
        if self.has::<P>(plan::BQL) {
            // The neighbours' mean pressure, the reference of BQL (unused without one).
            s.p_sum += b.p;
            s.n_nb += 1;
        }
        if self.has::<P>(plan::VISCOSITY) {
            s.acc += viscosity::morris(a, b_visc, ab, self.nu);
        }
        if self.has::<P>(plan::ARTIFICIAL_VISCOSITY) {
            s.acc += artificial_viscosity::monaghan(a, b_av, ab, self.av.0, self.av.1);
        }
    }

    /// The homogenisation acceleration's share of neighbour `b` (before its prefactor): a
    /// background pressure's or Sun et al.'s (eq. 36), whichever is declared.
    #[inline(always)]
    pub fn homogenisation<const P: u32, const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        b: &Point<D>,
    ) {
        if self.has::<P>(plan::BACKGROUND_PRESSURE) {
            s.ac += shifting::background_pressure(a, b, ab, self.pb);
        } else if self.has::<P>(plan::SUN2019) {
            let (w_dx, r, n) = self.sun;
            s.ac += shifting::sun2019(b, ab, w_dx, r, n);
        }
    }
}
