//! The parallel loops. Each pass is a gather over the neighbours of every particle of one
//! body, writing only that particle's own row: a plain rayon loop with no locks or atomics,
//! and a neighbour order fixed by the neighbour list, so results are bit-for-bit identical
//! for any number of threads. IPST's sweeps, which run up to ten times a step over the same
//! pairs, evaluate each fluid pair once instead ([`ipst`](super::ipst)).

use super::ipst::IpstWork;
use super::plan::{self, with_accelerations_plan, with_rates_plan};
use super::{
    DensityModel, FluidScheme, PressureGradient, PressureModel, PressureReference, Shifting, SurfaceFields,
    WallSet,
};
use crate::solver::equations::{
    artificial_viscosity, continuity, edac, free_surface, momentum, regularised_laplacian, shifting,
    viscosity, Pair, Point,
};
use crate::solver::kernel::{Kernel, ScaledKernel};
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Gather, Listed, NeighbourList};
use crate::solver::particles::{Fluid, FluidRates};
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// Particles per rayon task: large enough that scheduling is noise.
pub(super) const MIN_LEN: usize = 128;

/// The neighbour list of a fluid body: each pair carries its `PairKernel`, evaluated once
/// per step when the list is built.
pub type KernelList<const D: usize> = NeighbourList<D, PairKernel>;

/// The kernel values of a listed pair, evaluated for all the pairs of a point in one
/// vectorised loop (the passes then divide nothing for them).
#[derive(Clone, Copy, Debug, Default)]
pub struct PairKernel {
    /// W_ab.
    pub w: f64,
    /// `(1/r) dW/dr`, which turns `x_ab` into `grad_a W_ab`.
    pub grad_factor: f64,
    /// `x_ab . grad W / (r^2 + 0.01 h^2)` ([`regularised_laplacian`]).
    pub lap: f64,
}

impl PairKernel {
    /// The pair at difference `xij` (`r2 = |xij|^2`) for smoothing length `h`.
    #[inline(always)]
    pub fn pair<const D: usize>(&self, xij: Vector<D>, r2: f64, h: f64) -> Pair<D> {
        Pair::with_laplacian(xij, r2, h, self.w, self.grad_factor, self.lap)
    }
}

/// Builds the neighbour list of `fluid` with the kernel values of each pair.
pub fn build_kernel_list<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    fluid: &Fluid<D>,
    k: &Kernel,
) {
    let k = k.scaled(fluid.h);
    nl.build(cells, &fluid.x, |r2, out| kernel_payload(&k, r2, out));
}

/// As [`build_kernel_list`], also summing each particle's density over the fluid,
/// `sum_b m_b W_ab`, into `rho` while its pairs are in cache (the walls' share is added by
/// [`FluidPasses::summation_density`]).
pub fn build_kernel_list_summing_density<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    fluid: &Fluid<D>,
    k: &Kernel,
    rho: &mut Vec<f64>,
) {
    rho.resize(fluid.len(), 0.0);
    let list = KernelAndDensity::new(fluid, k);
    nl.build_reducing(cells, &fluid.x, |r2, out| list.payload(r2, out), rho, |p| list.density(p));
}

/// What a fluid's list build computes for each pair, its [`PairKernel`] from the pair's
/// squared distance, and for each particle as its pairs are listed, the fluid's share of
/// its summation density.
pub(super) struct KernelAndDensity<'a> {
    k: ScaledKernel,
    m: &'a [f64],
}

impl<'a> KernelAndDensity<'a> {
    pub(super) fn new<const D: usize>(fluid: &'a Fluid<D>, k: &Kernel) -> Self {
        Self { k: k.scaled(fluid.h), m: &fluid.m }
    }

    /// The payloads of the pairs at squared distances `r2`.
    pub(super) fn payload(&self, r2: &[f64], out: &mut [PairKernel]) {
        kernel_payload(&self.k, r2, out);
    }

    /// `sum_b m_b W_ab` over a particle's pairs.
    pub(super) fn density(&self, pairs: Listed<'_, PairKernel>) -> f64 {
        pairs.iter().fold(0.0, |s, (j, kw)| s + self.m[j] * kw.w)
    }
}

/// Builds the list of the neighbours of `queries` (a body of smoothing length `h`) among
/// `sources` (binned by `cells`), with the kernel values of each pair.
pub fn build_kernel_list_cross<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    sources: &[Vector<D>],
    queries: &[Vector<D>],
    h: f64,
    k: &Kernel,
) {
    let k = k.scaled(h);
    nl.build_cross(cells, sources, queries, |r2, out| kernel_payload(&k, r2, out));
}

/// The [`PairKernel`]s of the pairs at squared distances `r2`.
fn kernel_payload(k: &ScaledKernel, r2: &[f64], out: &mut [PairKernel]) {
    let h = k.h;
    k.w_and_grad_factor_map(r2, out, |r2, w, grad_factor| PairKernel {
        w,
        grad_factor,
        lap: regularised_laplacian(grad_factor, r2, h),
    });
}

#[inline(always)]
fn point<const D: usize>(f: &Fluid<D>, u_hat: &[Vector<D>], i: usize) -> Point<D> {
    Point::new(f.u[i], u_hat[i], f.m[i], f.rho[i], f.p[i])
}

/// Every particle's [`Point`], gathered once per pass so that each neighbour visit reads
/// one record and divides nothing.
fn gather_points<const D: usize>(f: &Fluid<D>, out: &mut Vec<Point<D>>) {
    let u_hat = f.u_hat();
    out.resize(f.len(), point(f, u_hat, 0));
    out.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, p)| *p = point(f, u_hat, i));
}

/// Sets the density and pressure of the particles from `first` on (one per element of
/// `points`, `rho` and `p`) with `set(i, rho_i, p_i)` and gathers their views anew from
/// `fluid`'s other fields, in rayon tasks of at least `task_len` particles.
pub(super) fn set_and_regather<const D: usize>(
    fluid: FluidViews<'_, D>,
    first: usize,
    (points, rho, p): (&mut [Point<D>], &mut [f64], &mut [f64]),
    set: impl Fn(usize, &mut f64, &mut f64) + Sync,
    task_len: usize,
) {
    let FluidViews { u, u_hat, m } = fluid;
    points
        .par_iter_mut()
        .zip(rho.par_iter_mut().zip(p.par_iter_mut()))
        .enumerate()
        .with_min_len(task_len)
        .for_each(|(k, (pt, (rho, p)))| {
            let i = first + k;
            set(i, rho, p);
            *pt = Point::new(u[i], u_hat[i], m[i], *rho, *p);
        });
}

/// The fields of a fluid its particles' views are gathered from besides the density and
/// the pressure.
#[derive(Clone, Copy)]
pub(super) struct FluidViews<'a, const D: usize> {
    u: &'a [Vector<D>],
    u_hat: &'a [Vector<D>],
    m: &'a [f64],
}

impl<'a, const D: usize> FluidViews<'a, D> {
    pub(super) fn of(f: &'a Fluid<D>) -> Self {
        Self { u: &f.u, u_hat: f.u_hat(), m: &f.m }
    }
}

/// The wall particles as the fluid sees them: with the slip ghost velocities of eqs.
/// (48)-(49) for the divergence terms, and with the no-slip one of eq. (50) for the viscous
/// terms.
fn gather_wall_points<const D: usize>(ws: &WallSet<D>, div: &mut Vec<Point<D>>, visc: &mut Vec<Point<D>>) {
    let w = &ws.wall;
    div.clear();
    visc.clear();
    for i in 0..w.len() {
        let (g, m, rho) = (&w.ghost[i], w.m[i], w.rho(i));
        div.push(Point::new(g.u_slip, g.u_hat_slip, m, rho, g.p));
        visc.push(Point::new(g.u_noslip, g.u_noslip, m, rho, g.p));
    }
}

/// The sources a fluid particle sums over: its own body, then the walls (if any) with
/// their two views. `f(pair, b, b_viscous, b_is_fluid)`.
pub(super) struct Sources<'a, const D: usize> {
    h: f64,
    x: &'a [Vector<D>],
    nl: &'a KernelList<D>,
    /// Read one at a time: the wavefront step writes other tiles' meanwhile.
    pts: Gather<'a, Point<D>>,
    walls: Option<(&'a WallSet<D>, &'a [Point<D>], &'a [Point<D>])>,
}

impl<'a, const D: usize> Sources<'a, D> {
    /// The fluid's own particles, without walls, their views read from `pts`.
    pub(super) fn fluid_only(fluid: &'a Fluid<D>, nl: &'a KernelList<D>, pts: Gather<'a, Point<D>>) -> Self {
        Self { h: fluid.h, x: &fluid.x, nl, pts, walls: None }
    }

    #[inline(always)]
    fn for_each(&self, i: usize, mut f: impl FnMut(&Pair<D>, &Point<D>, &Point<D>, bool)) {
        let h = self.h;
        self.nl.for_each_with(
            i,
            self.x[i],
            self.x,
            self.pts,
            #[inline(always)]
            |_, xij, r2, kw, b| f(&kw.pair(xij, r2, h), b, b, true),
        );
        if let Some((ws, div, visc)) = self.walls {
            ws.fluid_to_wall.for_each_from(
                i,
                self.x[i],
                &ws.wall.x,
                #[inline(always)]
                |j, xij, r2, kw| f(&kw.pair(xij, r2, h), &div[j], &visc[j], false),
            );
        }
    }
}

/// Scratch state of the fluid passes that must survive between steps without allocating:
/// the gathered particle views and IPST's work space.
#[derive(Debug, Default)]
pub struct FluidPasses<const D: usize> {
    pub(super) ipst: IpstWork<D>,
    /// The fluid's particles as the passes read them (IPST takes its volumes from them),
    pub(super) points: Vec<Point<D>>,
    /// and the walls', as the divergence terms and as the viscous ones see them.
    pub(super) wall_div: Vec<Point<D>>,
    wall_visc: Vec<Point<D>>,
}

impl<const D: usize> FluidPasses<D> {
    /// Empty work space; the arrays grow on first use (IPST's only when it is declared).
    pub fn new() -> Self {
        Self::default()
    }

    /// Gathers the views of the fluid (and walls) for a pass.
    fn gather<'a>(
        &'a mut self,
        fluid: &'a Fluid<D>,
        nl: &'a KernelList<D>,
        walls: Option<&'a WallSet<D>>,
    ) -> Sources<'a, D> {
        gather_points(fluid, &mut self.points);
        if let Some(ws) = walls {
            gather_wall_points(ws, &mut self.wall_div, &mut self.wall_visc);
        }
        self.sources(fluid, nl, walls)
    }

    /// The sources of a pass as last gathered.
    pub(super) fn sources<'a>(
        &'a self,
        fluid: &'a Fluid<D>,
        nl: &'a KernelList<D>,
        walls: Option<&'a WallSet<D>>,
    ) -> Sources<'a, D> {
        Sources {
            walls: walls.map(|ws| (ws, &self.wall_div[..], &self.wall_visc[..])),
            ..Sources::fluid_only(fluid, nl, self.points[..].into())
        }
    }

    /// Summation density, `rho_a = sum_b m_b W_ab` over the fluid and the walls: the
    /// fluid's share `fluid_sums` (summed as the list was built), then the walls'.
    pub fn summation_density(fluid: &mut Fluid<D>, fluid_sums: &[f64], walls: Option<&WallSet<D>>) {
        let x = &fluid.x;
        fluid.rho.par_iter_mut().zip(fluid_sums).enumerate().with_min_len(LIGHT_LOOP_LEN).for_each(
            |(i, (rho, &s))| {
                *rho = s;
                if let Some(ws) = walls {
                    ws.fluid_to_wall
                        .for_each_from(i, x[i], &ws.wall.x, |j, _, _, kw| *rho += ws.wall.m[j] * kw.w);
                }
            },
        );
    }

    /// Pass A: the density and pressure rates (eqs. 25 and 26), then their explicit
    /// update over `dt` (eqs. 56-57); or the state equation (8). Walls enter through their
    /// extrapolated pressure and slip velocities.
    pub fn update_density_and_pressure(
        &mut self,
        fluid: &mut Fluid<D>,
        nl: &KernelList<D>,
        walls: Option<&WallSet<D>>,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) {
        let continuity_on = s.density == DensityModel::Continuity;
        let terms = RateTerms::new(s);
        if continuity_on || terms.plan & plan::EDAC != 0 {
            let src = self.gather(fluid, nl, walls);
            let rate = |i: usize| with_rates_plan!(terms.plan, P => terms.sums::<P, D>(&src, i));
            match (terms.plan & plan::EDAC != 0, continuity_on) {
                (true, true) => rates
                    .dp
                    .par_iter_mut()
                    .zip(rates.drho.par_iter_mut())
                    .enumerate()
                    .with_min_len(MIN_LEN)
                    .for_each(|(i, (dp, drho))| (*dp, *drho) = rate(i)),
                (true, false) => pressure_rates(&terms, &src, 0, &mut rates.dp, MIN_LEN),
                (false, _) => rates
                    .drho
                    .par_iter_mut()
                    .enumerate()
                    .with_min_len(MIN_LEN)
                    .for_each(|(i, d)| *d = rate(i).1),
            }
        }
        if continuity_on {
            apply(&mut fluid.rho, &rates.drho, dt);
        }
        match s.pressure {
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

    /// Pass B: the acceleration (eq. 27 or its Adami form) and, for the shifting
    /// techniques that are sums over neighbours, the homogenisation acceleration.
    /// `dt` is the step the homogenisation will be applied over (eq. 36 divides by it).
    /// Walls act through their pressure (pressure gradient), their no-slip ghost velocity
    /// (viscosity) and as neighbours in the shifting; the transport-velocity terms
    /// (artificial stress, momentum correction) sum over the fluid only.
    #[allow(clippy::too_many_arguments)]
    pub fn accelerations(
        &mut self,
        fluid: &Fluid<D>,
        nl: &KernelList<D>,
        walls: Option<&WallSet<D>>,
        surface: Option<&SurfaceFields<D>>,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) {
        let src = self.gather(fluid, nl, walls);
        rates.a_c_dt = shifting_dt(s, dt);
        let a_c = if writes_homogenisation(s) { &mut rates.a_c[..] } else { &mut [] };
        write_accelerations(&src, fluid, surface, s, dt, 0, &mut rates.du, a_c, MIN_LEN);
    }
}

/// Pass B over the gathered points, for the particles from `first` on: one per element
/// of `du`, with their homogenisation accelerations in `a_c` unless it is empty, in
/// rayon tasks of at least `task_len` particles.
#[allow(clippy::too_many_arguments)]
pub(super) fn write_accelerations<const D: usize>(
    src: &Sources<'_, D>,
    fluid: &Fluid<D>,
    surface: Option<&SurfaceFields<D>>,
    s: &FluidScheme,
    dt: f64,
    first: usize,
    du: &mut [Vector<D>],
    a_c: &mut [Vector<D>],
    task_len: usize,
) {
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
        let sums = with_accelerations_plan!(terms.plan, P => terms.sums::<P, D>(src, i));
        let AccelSums { mut acc, mut ac, c_ref, p_sum, n_nb } = sums;
        // A reference pressure (the neighbours' mean for BQL) is constant over the
        // sum, so it is applied once here (c_ref is zero without one).
        acc += c_ref * global_mean.unwrap_or(p_sum / n_nb.max(1) as f64);
        if matches!(shifting, Some(Shifting::Sun2019 { .. })) {
            ac *= sun_prefactor;
        }
        if let Some(fs) = surface {
            // eq. (44)
            ac = free_surface::adjust_shift(ac, fs.surface[i], fs.near[i], &fs.normal[i]);
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
pub(super) fn shifting_dt(s: &FluidScheme, dt: f64) -> Option<f64> {
    matches!(s.transport.map(|t| t.shifting), Some(Shifting::Sun2019 { .. } | Shifting::Ipst { .. }))
        .then_some(dt)
}

/// Whether pass B writes the homogenisation acceleration: with a transport velocity whose
/// shifting is not IPST's (without transport there is none; IPST fills it in its own pass).
pub(super) fn writes_homogenisation(s: &FluidScheme) -> bool {
    s.transport.is_some_and(|t| !matches!(t.shifting, Shifting::Ipst { .. }))
}

/// Pass A's EDAC pressure rates (eq. 26) of the particles from `first` on, one per element
/// of `dp`, without the continuity equation, in rayon tasks of at least `task_len`.
pub(super) fn pressure_rates<const D: usize>(
    terms: &RateTerms,
    src: &Sources<'_, D>,
    first: usize,
    dp: &mut [f64],
    task_len: usize,
) {
    let rate = |i: usize| with_rates_plan!(terms.plan, P => terms.sums::<P, D>(src, i)).0;
    dp.par_iter_mut().enumerate().with_min_len(task_len).for_each(|(k, dp)| *dp = rate(first + k));
}

/// The terms of pass A a scheme declares: its plan and the EDAC constants.
pub(super) struct RateTerms {
    plan: u32,
    /// EDAC's `c_s^2` and `nu_edac`.
    cs2: f64,
    nu: f64,
}

impl RateTerms {
    pub(super) fn new(s: &FluidScheme) -> Self {
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

    /// Particle `i`'s `(dp/dt, drho/dt)` under plan `P`: the sums stay in registers across
    /// the loops over the fluid and the walls.
    #[inline(always)]
    fn sums<const P: u32, const D: usize>(&self, src: &Sources<'_, D>, i: usize) -> (f64, f64) {
        let a = src.pts.get(i);
        let mut sums = (0.0, 0.0);
        src.for_each(
            i,
            #[inline(always)]
            |ab, b, _, _| self.add::<P, D>(&mut sums, a, b, ab),
        );
        sums
    }

    /// Adds neighbour `b`'s share of `(dp/dt, drho/dt)` of particle `a`.
    #[inline(always)]
    fn add<const P: u32, const D: usize>(
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
struct AccelSums<const D: usize> {
    /// Acceleration.
    acc: Vector<D>,
    /// Homogenisation acceleration (before its prefactor).
    ac: Vector<D>,
    /// BQL: the weights of the reference pressure,
    c_ref: Vector<D>,
    /// and the neighbours' pressures and their number, for its mean.
    p_sum: f64,
    n_nb: usize,
}

impl<const D: usize> AccelSums<D> {
    fn zero() -> Self {
        Self { acc: Vector::zeros(), ac: Vector::zeros(), c_ref: Vector::zeros(), p_sum: 0.0, n_nb: 0 }
    }
}

/// The terms of pass B a scheme declares: the plan and the terms' constants.
struct AccelTerms {
    plan: u32,
    nu: f64,
    /// Artificial viscosity `(alpha, c)`.
    av: (f64, f64),
    /// Background pressure.
    pb: f64,
    /// Sun 2019: `(W(dx), R, n)`.
    sun: (f64, f64, i32),
}

impl AccelTerms {
    fn new(s: &FluidScheme) -> Self {
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

    #[inline(always)]
    fn has<const P: u32>(&self, t: u32) -> bool {
        plan::has::<P>(self.plan, t)
    }

    /// Particle `i`'s sums over its sources under plan `P`.
    #[inline(always)]
    fn sums<const P: u32, const D: usize>(&self, src: &Sources<'_, D>, i: usize) -> AccelSums<D> {
        let a = src.pts.get(i);
        let mut sums = AccelSums::zero();
        src.for_each(
            i,
            #[inline(always)]
            |ab, b, b_visc, b_fluid| self.add::<P, D>(&mut sums, a, ab, b, b_visc, b_fluid),
        );
        sums
    }

    /// Adds neighbour `b`'s share: `b` as the divergence terms see it, `b_visc` as the
    /// viscous ones do (they differ for walls), `b_fluid` whether it is a fluid particle.
    #[inline(always)]
    fn add<const P: u32, const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        b: &Point<D>,
        b_visc: &Point<D>,
        b_fluid: bool,
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
            s.acc += artificial_viscosity::monaghan(a, b_visc, ab, self.av.0, self.av.1);
        }
        if self.has::<P>(plan::TRANSPORT) {
            if b_fluid {
                s.acc += momentum::artificial_stress(a, b, ab);
                if self.has::<P>(plan::MOMENTUM_CORR) {
                    s.acc += momentum::transport_divergence_correction(a, b, ab);
                }
            }
            if self.has::<P>(plan::BACKGROUND_PRESSURE) {
                s.ac += shifting::background_pressure(a, b, ab, self.pb);
            } else if self.has::<P>(plan::SUN2019) {
                let (w_dx, r, n) = self.sun;
                s.ac += shifting::sun2019(b, ab, w_dx, r, n);
            }
        }
    }
}

fn apply(v: &mut [f64], rate: &[f64], dt: f64) {
    v.par_iter_mut().zip(rate).with_min_len(LIGHT_LOOP_LEN).for_each(|(v, r)| *v += dt * r);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::scheme::{Corrections, FluidSettings, Pst, SchemeName, SurfacePressure};

    /// Every plan the named schemes take on an internal flow (viscous) and a free surface
    /// (artificial viscosity) has loops of its own: none falls back to run-time checks.
    #[test]
    fn named_schemes_run_compiled_plans() {
        let internal = super::super::tests::internal_flow_settings();
        let free_surface = FluidSettings {
            nu: None,
            alpha: Some(0.05),
            density: DensityModel::Continuity,
            free_surface: Some(SurfacePressure::Evolve),
            ..internal
        };
        let (mut accel, mut rates) = (Vec::new(), Vec::new());
        for pst in [Pst::Sun, Pst::Ipst, Pst::None] {
            for corrections in [Corrections::ALL, Corrections::NONE] {
                // Within walls (the cavity) ctvf's `auto` reference is eq. (27) without BQL.
                for (flow, walls, names) in [
                    (internal, false, &[SchemeName::Edac, SchemeName::Tvf, SchemeName::Ctvf][..]),
                    (internal, true, &[SchemeName::Edac, SchemeName::Tvf, SchemeName::Ctvf][..]),
                    (free_surface, true, &[SchemeName::Ctvf][..]),
                ] {
                    for name in names {
                        let mut scheme = name.fluid_scheme(&FluidSettings { pst, corrections, ..flow });
                        scheme.set_walls(walls);
                        let case = format!("{name:?} {pst:?} {corrections:?}");
                        let b = AccelTerms::new(&scheme).plan;
                        assert!(plan::ACCELERATIONS.contains(&b), "{case}: pass B plan {b:#b}");
                        accel.push(b);
                        let a = RateTerms::new(&scheme).plan;
                        // Pass A runs for EDAC or the continuity equation (not tvf's state equation).
                        if a != 0 {
                            assert!(plan::RATES.contains(&a), "{case}: pass A plan {a:#b}");
                            rates.push(a);
                        }
                    }
                }
            }
        }
        for plans in [&mut accel, &mut rates] {
            plans.sort();
            plans.dedup();
        }
        assert_eq!(accel.len(), plan::ACCELERATIONS.len(), "every compiled plan is one a named scheme takes");
        assert_eq!(rates.len(), plan::RATES.len(), "every compiled plan is one a named scheme takes");
    }

    /// A perturbed periodic lattice of 12x12 particles with varied fields (and u~ != u),
    /// with its neighbour list.
    fn perturbed_lattice() -> (Fluid<2>, KernelList<2>) {
        use crate::solver::kernel::KernelKind;
        use crate::solver::nnps::Domain;
        use crate::solver::particles::FluidInit;
        let (n, dx) = (12, 1.0 / 12.0);
        let h = dx;
        let wave = |k: usize, s: f64| (s * (k as f64 + 1.0)).sin();
        let x: Vec<Vector<2>> = (0..n * n)
            .map(|k| {
                Vector::<2>::new(
                    ((k % n) as f64 + 0.5 + 0.2 * wave(k, 1.3)) * dx,
                    ((k / n) as f64 + 0.5 + 0.2 * wave(k, 2.1)) * dx,
                )
            })
            .collect();
        let init = FluidInit {
            u: (0..n * n).map(|k| Vector::<2>::new(wave(k, 0.7), wave(k, 1.9))).collect(),
            m: vec![dx * dx; n * n],
            rho: (0..n * n).map(|k| 1.0 + 0.05 * wave(k, 3.1)).collect(),
            p: (0..n * n).map(|k| 2.0 * wave(k, 0.4)).collect(),
            x,
        };
        let mut fluid = Fluid::new("f", h, init, true).unwrap();
        for (k, uh) in fluid.u_hat.as_mut().unwrap().iter_mut().enumerate() {
            *uh += Vector::<2>::new(0.1 * wave(k, 2.7), 0.1 * wave(k, 0.3));
        }
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let mut cells = CellList::new(Domain::periodic([0.0; 2], [1.0; 2]), kernel.support() * h);
        cells.update(&fluid.x);
        let mut nl = KernelList::new();
        build_kernel_list(&mut nl, &cells, &fluid, &kernel);
        (fluid, nl)
    }

    /// The list's kernel values of every pair: W and `grad W` as the kernel gives them one
    /// pair at a time (bit for bit), and the Laplacian factor equal to
    /// `x_ab . grad W / (r^2 + 0.01 h^2)` computed from the gradient (to rounding).
    #[test]
    fn list_kernel_values_are_the_kernels() {
        let (fluid, nl) = perturbed_lattice();
        let k = Kernel::new(crate::solver::kernel::KernelKind::QuinticSpline, 2).scaled(fluid.h);
        let mut pairs = 0;
        for i in 0..fluid.len() {
            nl.for_each(i, &fluid.x, |_, xij, r2, kw| {
                let (w, f) = k.w_and_grad_factor(r2.sqrt());
                assert_eq!((kw.w, kw.grad_factor), (w, f), "pair {i}: {xij:?}");
                let dw = xij * f;
                let lap = xij.dot(&dw) / (r2 + 0.01 * fluid.h * fluid.h);
                assert!((kw.lap - lap).abs() <= 1e-14 * lap.abs().max(1e-300), "{} vs {lap}", kw.lap);
                pairs += usize::from(r2 > 0.0);
            });
        }
        assert!(pairs > 20 * fluid.len(), "{pairs} pairs");
    }

    /// A reference pressure removes the pressure level from the accelerations: a uniform
    /// pressure added to every particle changes them by rounding only with the neighbours'
    /// or the fluid's mean as reference, and by its zeroth-order gradient error without.
    #[test]
    fn a_reference_pressure_removes_the_level() {
        let (mut fluid, nl) = perturbed_lattice();
        let accelerations = |fluid: &Fluid<2>, reference: PressureReference| {
            let settings = FluidSettings {
                pressure_reference: reference,
                ..super::super::tests::internal_flow_settings()
            };
            let scheme = SchemeName::Ctvf.fluid_scheme(&settings);
            let mut rates = FluidRates::new(fluid.len(), true, false, true);
            FluidPasses::new().accelerations(fluid, &nl, None, None, &scheme, &mut rates, 1e-3);
            rates.du
        };
        for (reference, removed) in [
            (PressureReference::LocalMean, true),
            (PressureReference::GlobalMean, true),
            (PressureReference::None, false),
        ] {
            let before = accelerations(&fluid, reference);
            fluid.p.iter_mut().for_each(|p| *p += 50.0);
            let after = accelerations(&fluid, reference);
            fluid.p.iter_mut().for_each(|p| *p -= 50.0);
            let scale = before.iter().map(|a| a.norm()).fold(0.0, f64::max);
            let change = before.iter().zip(&after).map(|(b, a)| (a - b).norm()).fold(0.0, f64::max);
            if removed {
                assert!(change < 1e-12 * 50.0 * scale, "{reference:?}: change {change:e}, scale {scale:e}");
            } else {
                assert!(change > 0.1 * scale, "{reference:?}: change {change:e}, scale {scale:e}");
            }
        }
    }

    /// A compiled plan sums exactly what the run-time plan sums, bit for bit, in both
    /// passes: on a perturbed periodic lattice with varied fields, for every compiled plan.
    #[test]
    fn compiled_plans_equal_the_run_time_plan() {
        let (fluid, nl) = perturbed_lattice();
        let mut passes = FluidPasses::new();
        let src = passes.gather(&fluid, &nl, None);
        let accel = AccelTerms { plan: 0, nu: 0.01, av: (0.1, 10.0), pb: 100.0, sun: (2.0, 0.2, 4) };
        let rates = RateTerms { plan: 0, cs2: 100.0, nu: 0.05 };
        for &p in &plan::ACCELERATIONS {
            let terms = AccelTerms { plan: p, ..accel };
            for i in 0..fluid.len() {
                let compiled = with_accelerations_plan!(p, P => terms.sums::<P, 2>(&src, i));
                let runtime = terms.sums::<{ plan::RUNTIME }, 2>(&src, i);
                assert_eq!(
                    (compiled.acc, compiled.ac, compiled.c_ref),
                    (runtime.acc, runtime.ac, runtime.c_ref),
                    "plan {p:#b}"
                );
            }
        }
        for &p in &plan::RATES {
            let terms = RateTerms { plan: p, ..rates };
            for i in 0..fluid.len() {
                let compiled = with_rates_plan!(p, P => terms.sums::<P, 2>(&src, i));
                assert_eq!(compiled, terms.sums::<{ plan::RUNTIME }, 2>(&src, i), "plan {p:#b}");
            }
        }
    }
}
