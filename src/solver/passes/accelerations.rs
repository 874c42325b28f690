//! Pass B: a fluid's accelerations (eq. 27 or its Adami form, with viscosity, artificial
//! viscosity and the transport-velocity terms) and, for the shifting techniques that are
//! sums over neighbours, its homogenisation acceleration (a background pressure, or Sun et
//! al. 2019, eq. 36), kept tangential near a free surface (eq. 44).

use super::free_surface::SurfaceFields;
use super::{FluidPasses, Gatherer, Sources, MIN_LEN};
use crate::solver::equations::{Pair, Point};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::fluid_fluid::{AccelSums, AccelTerms};
use crate::solver::interactions::lists::KernelList;
use crate::solver::math::Vector;
use crate::solver::scheme::plan::with_accelerations_plan;
use crate::solver::scheme::{FluidScheme, PressureReference, Shifting};
use crate::solver::systems::{Fluid, FluidRates};
use rayon::prelude::*;

/// Particle `a`'s sums of pass B as it gathers them under plan `P`.
struct AccelGather<'t, const P: u32, const D: usize> {
    terms: &'t AccelTerms,
    a: &'t Point<D>,
    sums: AccelSums<D>,
}

impl<const P: u32, const D: usize> Gatherer<D> for AccelGather<'_, P, D> {
    #[inline(always)]
    fn fluid(&mut self, ab: &Pair<D>, b: &Point<D>) {
        self.terms.fluid_neighbour::<P, D>(&mut self.sums, self.a, ab, b);
    }

    #[inline(always)]
    fn boundary(&mut self, ab: &Pair<D>, views: [&Point<D>; 3]) {
        self.terms.boundary_neighbour::<P, D>(&mut self.sums, self.a, ab, views);
    }
}

/// Particle `i`'s sums over its sources under plan `P`.
#[inline(always)]
pub(crate) fn accel_sums<const P: u32, const D: usize>(
    terms: &AccelTerms,
    src: &Sources<'_, D>,
    i: usize,
) -> AccelSums<D> {
    let mut g = AccelGather::<P, D> { terms, a: src.pts.get(i), sums: AccelSums::zero() };
    src.gather(i, &mut g);
    g.sums
}

/// Pass B of `fluid` over its list `nl` and its `boundaries`, its free surface `surface`
/// if detected: the accelerations into `rates.du`, and the homogenisation acceleration into
/// `rates.a_c` where a sum over neighbours gives it. `dt` is the step the homogenisation
/// will be applied over (eq. 36 divides by it).
pub fn accelerations<const D: usize>(
    passes: &mut FluidPasses<D>,
    fluid: &Fluid<D>,
    nl: &KernelList<D>,
    boundaries: Boundaries<'_, D>,
    surface: Option<&SurfaceFields<D>>,
    rates: &mut FluidRates<D>,
    dt: f64,
) {
    let s = &fluid.physics;
    let src = passes.gather(fluid, nl, boundaries);
    rates.a_c_dt = shifting_dt(s, dt);
    let a_c = if writes_homogenisation(s) { &mut rates.a_c[..] } else { &mut [] };
    write_accelerations(&src, fluid, surface, dt, 0, &mut rates.du, a_c, MIN_LEN);
}

/// Pass B over the gathered points, for the particles from `first` on: one per element
/// of `du`, with their homogenisation accelerations in `a_c` unless it is empty, in
/// rayon tasks of at least `task_len` particles.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_accelerations<const D: usize>(
    src: &Sources<'_, D>,
    fluid: &Fluid<D>,
    surface: Option<&SurfaceFields<D>>,
    dt: f64,
    first: usize,
    du: &mut [Vector<D>],
    a_c: &mut [Vector<D>],
    task_len: usize,
) {
    let s = &fluid.physics;
    let g = s.gravity_vector::<D>();
    let shifting = s.transport.map(|t| t.shifting);
    let sun_prefactor = match shifting {
        // -(Ma c0) 2h / dt, eq. (36)
        Some(Shifting::Sun2019 { ma_c0, .. }) => -ma_c0 * 2.0 * fluid.h / dt,
        _ => 0.0,
    };
    let terms = AccelTerms::new(s);
    // The fluid's mean pressure, if it is the reference: summed in particle order, so
    // that it does not depend on the thread count.
    let global_mean = (s.pressure_reference == PressureReference::GlobalMean)
        .then(|| fluid.p.iter().sum::<f64>() / fluid.len() as f64);
    let rate = |i: usize| -> (Vector<D>, Vector<D>) {
        let sums = with_accelerations_plan!(terms.plan, P => accel_sums::<P, D>(&terms, src, i));
        let AccelSums { mut acc, mut ac, c_ref, p_sum, n_nb } = sums;
        // A reference pressure (the neighbours' mean for BQL) is constant over the
        // sum, so it is applied once here (c_ref is zero without one).
        acc += c_ref * global_mean.unwrap_or(p_sum / n_nb.max(1) as f64);
        if matches!(shifting, Some(Shifting::Sun2019 { .. })) {
            ac *= sun_prefactor;
        }
        if let Some(fs) = surface {
            // eq. (44)
            ac = fs.adjust(i, ac);
        }
        (acc + g, ac)
    };
    if a_c.is_empty() {
        du.par_iter_mut().enumerate().with_min_len(task_len).for_each(|(k, du)| *du = rate(first + k).0);
    } else {
        du.par_iter_mut()
            .zip(a_c.par_iter_mut())
            .enumerate()
            .with_min_len(task_len)
            .for_each(|(k, (du, ac))| (*du, *ac) = rate(first + k));
    }
}

/// The step a scheme's shifting divides `(du/dt)_c` by, when pass B is evaluated for step
/// `dt`: both shifting techniques do (eqs. 36, 41; IPST's pass after pass B is evaluated
/// with the same one), a background pressure does not.
pub(crate) fn shifting_dt(s: &FluidScheme, dt: f64) -> Option<f64> {
    matches!(s.transport.map(|t| t.shifting), Some(Shifting::Sun2019 { .. } | Shifting::Ipst { .. }))
        .then_some(dt)
}

/// Whether pass B writes the homogenisation acceleration: with a transport velocity whose
/// shifting is not IPST's (without transport there is none; IPST fills it in its own pass).
pub(crate) fn writes_homogenisation(s: &FluidScheme) -> bool {
    s.transport.is_some_and(|t| !matches!(t.shifting, Shifting::Ipst { .. }))
}
