//! Pass A: the density and pressure rates of a fluid (eqs. 25 and 26) over its own
//! particles and its boundaries, and their explicit update (eqs. 56-57); or the pressure
//! from the state equation (8).

use super::{apply, FluidPasses, Gatherer, Sources, MIN_LEN};
use crate::solver::equations::{Pair, Point};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::fluid_fluid::RateTerms;
use crate::solver::interactions::lists::KernelList;
use crate::solver::scheme::plan::{self, with_rates_plan};
use crate::solver::scheme::{DensityModel, PressureModel};
use crate::solver::systems::{Fluid, FluidRates};
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// Particle `a`'s `(dp/dt, drho/dt)` as it gathers them under plan `P`: the sums stay in
/// registers across the loops over the fluid and the boundaries.
struct RateSums<'t, const P: u32, const D: usize> {
    terms: &'t RateTerms,
    a: &'t Point<D>,
    sums: (f64, f64),
}

impl<const P: u32, const D: usize> Gatherer<D> for RateSums<'_, P, D> {
    #[inline(always)]
    fn fluid(&mut self, ab: &Pair<D>, b: &Point<D>) {
        self.terms.fluid_neighbour::<P, D>(&mut self.sums, self.a, b, ab);
    }

    #[inline(always)]
    fn boundary(&mut self, ab: &Pair<D>, [b, _, _]: [&Point<D>; 3]) {
        self.terms.boundary_neighbour::<P, D>(&mut self.sums, self.a, b, ab);
    }
}

/// Particle `i`'s `(dp/dt, drho/dt)` under plan `P`.
#[inline(always)]
pub(crate) fn rate_sums<const P: u32, const D: usize>(
    terms: &RateTerms,
    src: &Sources<'_, D>,
    i: usize,
) -> (f64, f64) {
    let mut g = RateSums::<P, D> { terms, a: src.pts.get(i), sums: (0.0, 0.0) };
    src.gather(i, &mut g);
    g.sums
}

/// Whether pass A sums anything for `fluid`: the EDAC pressure rate or the continuity
/// equation (not the state equation of `tvf`).
pub fn sums_rates<const D: usize>(fluid: &Fluid<D>) -> bool {
    let s = &fluid.physics;
    s.density == DensityModel::Continuity || matches!(s.pressure, PressureModel::Edac { .. })
}

/// Pass A's rates of `fluid` (eqs. 25 and 26) over its list `nl` and its `boundaries`,
/// into `rates` (nothing for a scheme without them, [`sums_rates`]).
pub fn density_and_pressure_rates<const D: usize>(
    passes: &mut FluidPasses<D>,
    fluid: &Fluid<D>,
    nl: &KernelList<D>,
    boundaries: Boundaries<'_, D>,
    rates: &mut FluidRates<D>,
) {
    if !sums_rates(fluid) {
        return;
    }
    let continuity_on = fluid.physics.density == DensityModel::Continuity;
    let terms = RateTerms::new(&fluid.physics);
    let src = passes.gather(fluid, nl, boundaries);
    let rate = |i: usize| with_rates_plan!(terms.plan, P => rate_sums::<P, D>(&terms, &src, i));
    match (terms.plan & plan::EDAC != 0, continuity_on) {
        (true, true) => rates
            .dp
            .par_iter_mut()
            .zip(rates.drho.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_LEN)
            .for_each(|(i, (dp, drho))| (*dp, *drho) = rate(i)),
        (true, false) => pressure_rates(&terms, &src, 0, &mut rates.dp, MIN_LEN),
        (false, _) => {
            rates.drho.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, d)| *d = rate(i).1)
        }
    }
}

/// The explicit update over `dt` of the density and pressure of `fluid` by their rates
/// (eqs. 56-57), or its pressure from the state equation (8).
pub fn update_density_and_pressure<const D: usize>(fluid: &mut Fluid<D>, rates: &FluidRates<D>, dt: f64) {
    if fluid.physics.density == DensityModel::Continuity {
        apply(&mut fluid.rho, &rates.drho, dt);
    }
    match fluid.physics.pressure {
        PressureModel::Edac { .. } => apply(&mut fluid.p, &rates.dp, dt),
        PressureModel::StateEquation { c0, rho0 } => {
            let c2 = c0 * c0;
            fluid
                .p
                .par_iter_mut()
                .zip(&fluid.rho)
                .with_min_len(LIGHT_LOOP_LEN)
                .for_each(|(p, &rho)| *p = c2 * (rho - rho0));
        }
    }
}

/// Pass A's EDAC pressure rates (eq. 26) of the particles from `first` on, one per element
/// of `dp`, without the continuity equation, in rayon tasks of at least `task_len`.
pub(crate) fn pressure_rates<const D: usize>(
    terms: &RateTerms,
    src: &Sources<'_, D>,
    first: usize,
    dp: &mut [f64],
    task_len: usize,
) {
    let rate = |i: usize| with_rates_plan!(terms.plan, P => rate_sums::<P, D>(terms, src, i)).0;
    dp.par_iter_mut().enumerate().with_min_len(task_len).for_each(|(k, dp)| *dp = rate(first + k));
}
