//! The parallel loops. Each pass is a gather over the neighbours of every particle of one
//! body, writing only that particle's own row: a plain rayon loop with no locks or atomics,
//! and a neighbour order fixed by the neighbour list, so results are bit-for-bit identical
//! for any number of threads.

use super::{DensityModel, FluidScheme, PressureGradient, PressureModel, Shifting, SurfaceFields, WallSet};
use crate::solver::equations::{
    artificial_viscosity, continuity, edac, free_surface, momentum, shifting, viscosity, Pair, Point,
};
use crate::solver::kernel::{Kernel, ScaledKernel};
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, NeighbourList, PairSlices};
use crate::solver::particles::{Fluid, FluidRates};
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// Particles per rayon task: large enough that scheduling is noise.
const MIN_LEN: usize = 128;

/// The neighbour list of a fluid body: each pair carries `(W_ab, (1/r) dW/dr)`, evaluated
/// once per step when the list is built.
pub type KernelList<const D: usize> = NeighbourList<D, (f64, f64)>;

/// Builds the neighbour list of `fluid` with the kernel values of each pair.
pub fn build_kernel_list<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    fluid: &Fluid<D>,
    k: &Kernel,
) {
    let k = k.scaled(fluid.h);
    nl.build(cells, &fluid.x, |r2, out| k.w_and_grad_factor_batch(r2, out));
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
    nl.build_cross(cells, sources, queries, |r2, out| k.w_and_grad_factor_batch(r2, out));
}

#[inline(always)]
fn cached_pair<const D: usize>(h: f64, xij: Vector<D>, r2: f64, &(w, f): &(f64, f64)) -> Pair<D> {
    Pair::new(xij, r2, h, w, f)
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
struct Sources<'a, const D: usize> {
    h: f64,
    x: &'a [Vector<D>],
    nl: &'a KernelList<D>,
    pts: &'a [Point<D>],
    walls: Option<(&'a WallSet<D>, &'a [Point<D>], &'a [Point<D>])>,
}

impl<const D: usize> Sources<'_, D> {
    #[inline(always)]
    fn for_each(&self, i: usize, mut f: impl FnMut(&Pair<D>, &Point<D>, &Point<D>, bool)) {
        let h = self.h;
        self.nl.for_each(
            i,
            self.x,
            #[inline(always)]
            |j, xij, r2, kw| {
                let b = &self.pts[j];
                f(&cached_pair(h, xij, r2, kw), b, b, true)
            },
        );
        if let Some((ws, div, visc)) = self.walls {
            ws.fluid_to_wall.for_each_from(
                i,
                self.x[i],
                &ws.wall.x,
                #[inline(always)]
                |j, xij, r2, kw| f(&cached_pair(h, xij, r2, kw), &div[j], &visc[j], false),
            );
        }
    }
}

/// Scratch state of the fluid passes that must survive between steps without allocating:
/// the gathered particle views and the IPST work arrays.
#[derive(Clone, Debug, Default)]
pub struct FluidPasses<const D: usize> {
    x_shift: Vec<Vector<D>>,
    x_next: Vec<Vector<D>>,
    ipst_pairs: Vec<IpstPairs<D>>,
    vol: Vec<f64>,
    wall_vol: Vec<f64>,
    points: Vec<Point<D>>,
    wall_div: Vec<Point<D>>,
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
        Sources {
            h: fluid.h,
            x: &fluid.x,
            nl,
            pts: &self.points,
            walls: walls.map(|ws| (ws, &self.wall_div[..], &self.wall_visc[..])),
        }
    }

    /// Summation density, `rho_a = sum_b m_b W_ab` over the fluid and the walls.
    pub fn summation_density(fluid: &mut Fluid<D>, nl: &KernelList<D>, walls: Option<&WallSet<D>>) {
        let (x, m) = (&fluid.x, &fluid.m);
        fluid.rho.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, rho)| {
            let mut s = 0.0;
            nl.for_each(i, x, |j, _, _, &(w, _)| s += m[j] * w);
            if let Some(ws) = walls {
                ws.fluid_to_wall.for_each_from(i, x[i], &ws.wall.x, |j, _, _, &(w, _)| s += ws.wall.m[j] * w);
            }
            *rho = s;
        });
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
        let corr = s.transport.map(|t| t.corrections);
        let continuity_corr = corr.is_some_and(|c| c.continuity);
        let pressure_corr = corr.is_some_and(|c| c.pressure);
        let edac = match s.pressure {
            PressureModel::Edac { cs, nu } => Some((cs * cs, nu)),
            PressureModel::StateEquation { .. } => None,
        };
        if continuity_on || edac.is_some() {
            let src = self.gather(fluid, nl, walls);
            let terms = RateTerms { edac, pressure_corr, continuity_on, continuity_corr };
            let rate = |i: usize| -> (f64, f64) {
                let a = &src.pts[i];
                let mut sums = (0.0, 0.0);
                src.for_each(
                    i,
                    #[inline(always)]
                    |ab, b, _, _| terms.add(&mut sums, a, b, ab),
                );
                sums
            };
            match (edac.is_some(), continuity_on) {
                (true, true) => rates
                    .dp
                    .par_iter_mut()
                    .zip(rates.drho.par_iter_mut())
                    .enumerate()
                    .with_min_len(MIN_LEN)
                    .for_each(|(i, (dp, drho))| (*dp, *drho) = rate(i)),
                (true, false) => rates
                    .dp
                    .par_iter_mut()
                    .enumerate()
                    .with_min_len(MIN_LEN)
                    .for_each(|(i, dp)| *dp = rate(i).0),
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
        let g = s.gravity_vector::<D>();
        let shifting = s.transport.map(|t| t.shifting);
        let momentum_corr = s.transport.is_some_and(|t| t.corrections.momentum);
        let transport = s.transport.is_some();
        let sun_prefactor = match shifting {
            // -(Ma c0) 2h / dt, eq. (36)
            Some(Shifting::Sun2019 { ma_c0, .. }) => -ma_c0 * 2.0 * fluid.h / dt,
            _ => 0.0,
        };
        let terms = AccelTerms {
            pressure_gradient: s.pressure_gradient,
            viscosity: s.viscosity,
            artificial_viscosity: s.artificial_viscosity,
            transport,
            momentum_corr,
            shifting,
        };
        let rate = |i: usize| -> (Vector<D>, Vector<D>) {
            let a = &src.pts[i];
            let mut sums = AccelSums::zero();
            src.for_each(
                i,
                #[inline(always)]
                |ab, b, b_visc, b_fluid| terms.add(&mut sums, a, ab, b, b_visc, b_fluid),
            );
            let AccelSums { mut acc, mut ac, c_ref, p_sum, n_nb } = sums;
            // BQL: the gradient with the neighbour-mean pressure as reference; the mean is
            // constant over the sum, so it is applied once here (c_ref is zero without BQL).
            acc += c_ref * (p_sum / n_nb.max(1) as f64);
            if matches!(shifting, Some(Shifting::Sun2019 { .. })) {
                ac *= sun_prefactor;
            }
            if let Some(fs) = surface {
                // eq. (44)
                ac = free_surface::adjust_shift(ac, fs.surface[i], fs.near[i], &fs.normal[i]);
            }
            (acc + g, ac)
        };
        let ipst = matches!(shifting, Some(Shifting::Ipst { .. }));
        if transport && !ipst {
            rates
                .du
                .par_iter_mut()
                .zip(rates.a_c.par_iter_mut())
                .enumerate()
                .with_min_len(MIN_LEN)
                .for_each(|(i, (du, ac))| (*du, *ac) = rate(i));
        } else {
            // Without transport there is no a_c; IPST fills it in its own pass.
            rates.du.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, du)| *du = rate(i).0);
        }
    }

    /// IPST (eqs. 37-41): move copies of the particles by `U_max dt sum V_b n_ab W_ab` until
    /// `|max chi - chi_ref| <= tol chi_ref` (eq. 39, chi of eq. 40) or `max_iter` moves,
    /// then set `(du/dt)_c = 2 (r^M - r^0) / dt^2` (eq. 41). The particles themselves are not
    /// moved: the kick of the next step applies the displacement through u~. Walls are
    /// fixed neighbours.
    ///
    /// The iterations reuse the step's neighbour lists with the kernel re-evaluated at the
    /// moved positions. The moves are a small fraction of dx, so the only pairs this misses
    /// are those entering the support from outside it during the iterations, whose kernel
    /// value is of the fifth order in the distance they moved in (quintic spline).
    /// Returns the number of moves made.
    #[allow(clippy::too_many_arguments)]
    pub fn ipst(
        &mut self,
        fluid: &Fluid<D>,
        nl: &KernelList<D>,
        walls: Option<&WallSet<D>>,
        surface: Option<&SurfaceFields<D>>,
        k: &Kernel,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) -> usize {
        let Some(Shifting::Ipst { u_max, tol, max_iter, chi_ref }) = s.transport.map(|t| t.shifting) else {
            return 0;
        };
        let k = k.scaled(fluid.h);
        let n = fluid.len();
        self.x_shift.clear();
        self.x_shift.extend_from_slice(&fluid.x);
        self.x_next.resize(n, Vector::zeros());
        // The volumes gathered by `accelerations` at these positions, as compact arrays
        // (the sweeps read nothing else of the neighbours).
        self.vol.resize(n, 0.0);
        let pts = &self.points;
        self.vol.par_iter_mut().enumerate().with_min_len(LIGHT_LOOP_LEN).for_each(|(i, v)| *v = pts[i].v());
        self.wall_vol.clear();
        self.wall_vol.extend(self.wall_div.iter().map(|p| p.v()));
        let (vol, wall_vol) = (&self.vol, &self.wall_vol);
        let mut iterations = 0;
        while iterations < max_iter {
            // One sweep: chi at the current positions (eq. 40) and the moved positions
            // (eq. 37) into a second buffer, used if chi has not converged.
            let xs: &[Vector<D>] = &self.x_shift;
            // In fixed blocks of particles, each with its own pair arrays kept from step to
            // step (so that the sweeps allocate nothing once they have grown).
            self.ipst_pairs.resize_with(n.div_ceil(IPST_BLOCK), IpstPairs::default);
            // Each block returns its largest chi (max is exact: any grouping gives the same).
            let chi_max = self
                .x_next
                .par_chunks_mut(IPST_BLOCK)
                .zip(self.ipst_pairs.par_iter_mut())
                .enumerate()
                .map(|(c, (next, pairs))| {
                    let mut chi_max = f64::MIN;
                    for (g, next) in next.chunks_mut(IPST_GROUP).enumerate() {
                        let first = c * IPST_BLOCK + g * IPST_GROUP;
                        pairs.evaluate(
                            first..first + next.len(),
                            xs,
                            nl,
                            vol,
                            walls.map(|ws| (ws, &wall_vol[..])),
                            &k,
                        );
                        for (l, next) in next.iter_mut().enumerate() {
                            let i = first + l;
                            let (d, chi) = pairs.sums(l);
                            let mut dr = d * (u_max * dt);
                            if let Some(fs) = surface {
                                // eq. (45)
                                dr = free_surface::adjust_shift(dr, fs.surface[i], fs.near[i], &fs.normal[i]);
                            }
                            chi_max = chi_max.max(chi);
                            // Not wrapped: the list's image shifts refer to the unwrapped positions.
                            *next = xs[i] + dr;
                        }
                    }
                    chi_max
                })
                .reduce(|| f64::MIN, f64::max);
            if (chi_max - chi_ref).abs() <= tol * chi_ref {
                break;
            }
            std::mem::swap(&mut self.x_shift, &mut self.x_next);
            iterations += 1;
        }
        let f = 2.0 / (dt * dt);
        let (x0, xs) = (&fluid.x, &self.x_shift);
        rates.a_c.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, ac)| {
            *ac = (xs[i] - x0[i]) * f;
        });
        iterations
    }
}

/// Particles per IPST task, each with its own pair arrays (kept from step to step): more
/// than the passes' `MIN_LEN`, so that the arrays cost a few bytes per particle.
const IPST_BLOCK: usize = 256;
/// Particles whose pairs an IPST sweep evaluates together: their arrays stay in the first
/// cache level, and the vectorised loops run over the group's pairs, padded once.
const IPST_GROUP: usize = 8;
/// Vector lanes the pair arrays are padded to.
const LANES: usize = 8;

/// The pairs of a group of particles at moved positions, as arrays (reused from group to
/// group), for the IPST sums of eqs. (37) and (40): the kernel and the weights are
/// evaluated for all the pairs at once in vectorised loops, then each particle sums its
/// own in the neighbour order.
#[derive(Clone, Debug, Default)]
struct IpstPairs<const D: usize> {
    /// Where each particle's pairs end.
    end: Vec<usize>,
    xij: Vec<Vector<D>>,
    /// |x_ij|^2, then |x_ij|.
    r: Vec<f64>,
    vol: Vec<f64>,
    w: Vec<f64>,
    weight: Vec<f64>,
}

impl<const D: usize> IpstPairs<D> {
    /// Evaluates the pairs of `particles` at positions `xs` over the fluid (volumes `vol`)
    /// and the walls (with theirs).
    fn evaluate(
        &mut self,
        particles: std::ops::Range<usize>,
        xs: &[Vector<D>],
        nl: &KernelList<D>,
        vol: &[f64],
        walls: Option<(&WallSet<D>, &[f64])>,
        k: &ScaledKernel,
    ) {
        let to_wall = walls.map(|(ws, _)| &ws.fluid_to_wall);
        let n: usize = particles.clone().map(|i| nl.count(i) + to_wall.map_or(0, |l| l.count(i))).sum();
        // Whole vectors for the batch loops (no scalar tail). The arrays only grow, so the
        // padding holds earlier (finite) values, which no sum reads.
        let padded = n.next_multiple_of(LANES);
        if self.r.len() < padded {
            self.xij.resize(padded, Vector::zeros());
            for a in [&mut self.r, &mut self.vol, &mut self.w, &mut self.weight] {
                a.resize(padded, 0.0);
            }
        }
        self.end.clear();
        let mut at = 0;
        for i in particles {
            let mut write = |list: &KernelList<D>, sources: &[Vector<D>], vol: &[f64]| {
                let out = PairSlices {
                    xij: &mut self.xij[at..],
                    r2: &mut self.r[at..],
                    value: &mut self.vol[at..],
                };
                list.write_pairs(i, xs[i], sources, vol, out);
                at += list.count(i);
            };
            write(nl, xs, vol);
            if let Some((ws, wall_vol)) = walls {
                write(&ws.fluid_to_wall, &ws.wall.x, wall_vol);
            }
            self.end.push(at);
        }
        let r = &mut self.r[..padded];
        for r in r.iter_mut() {
            *r = r.sqrt();
        }
        k.w_batch_at_distances(r, &mut self.w[..padded]);
        // One vectorised loop for the per-pair factors (`w` then holds the chi shares).
        for (((f, &v), w), &r) in self.weight[..padded].iter_mut().zip(&self.vol).zip(&mut self.w).zip(&*r) {
            *f = shifting::ipst_weight(v, *w, r);
            *w = shifting::ipst_chi(k.h, *w);
        }
    }

    /// `(sum V_b n_ab W_ab, sum h^2 W_ab)` of the `l`-th particle of the group last
    /// evaluated.
    #[inline(always)]
    fn sums(&self, l: usize) -> (Vector<D>, f64) {
        let from = if l == 0 { 0 } else { self.end[l - 1] };
        let to = self.end[l];
        let (mut d, mut chi) = (Vector::<D>::zeros(), 0.0);
        for ((&xij, &f), &w) in self.xij[from..to].iter().zip(&self.weight[from..to]).zip(&self.w[from..to]) {
            d += xij * f;
            chi += w;
        }
        (d, chi)
    }
}

/// chi_ref of eq. (39): the mean of `chi = h^2 sum W` over the initial configuration for
/// internal flows (the authors' internal-flow choice: a perturbed lattice has no single
/// value), the maximum with a free surface (CTVF sec. 3.3.2).
pub fn ipst_chi_reference<const D: usize>(
    fluid: &Fluid<D>,
    nl: &KernelList<D>,
    walls: Option<&WallSet<D>>,
    free_surface: bool,
) -> f64 {
    let chi: Vec<f64> = (0..fluid.len())
        .map(|i| {
            let mut s = 0.0;
            let mut add = |_, _, kw: (f64, f64)| s += shifting::ipst_chi(fluid.h, kw.0);
            nl.for_each(i, &fluid.x, |_, xij, r2, &kw| add(xij, r2, kw));
            if let Some(ws) = walls {
                ws.fluid_to_wall.for_each_from(i, fluid.x[i], &ws.wall.x, |_, xij, r2, &kw| add(xij, r2, kw));
            }
            s
        })
        .collect();
    if free_surface {
        chi.iter().fold(f64::MIN, |m, &v| m.max(v))
    } else {
        chi.iter().sum::<f64>() / chi.len() as f64
    }
}

/// The terms of pass A a scheme declares. Their sum over one neighbour is an
/// always-inlined method, so the per-particle sums stay in registers across the loops over
/// the fluid and the walls.
struct RateTerms {
    /// EDAC's `(c_s^2, nu_edac)`, if the pressure evolves by EDAC.
    edac: Option<(f64, f64)>,
    pressure_corr: bool,
    continuity_on: bool,
    continuity_corr: bool,
}

impl RateTerms {
    /// Adds neighbour `b`'s share of `(dp/dt, drho/dt)` of particle `a`.
    #[inline(always)]
    fn add<const D: usize>(&self, (dp, drho): &mut (f64, f64), a: &Point<D>, b: &Point<D>, ab: &Pair<D>) {
        if let Some((cs2, nu)) = self.edac {
            *dp += edac::compressibility(a, b, ab, cs2) + edac::diffusion(a, b, ab, nu);
            if self.pressure_corr {
                *dp += edac::transport_correction(a, b, ab);
            }
        }
        if self.continuity_on {
            *drho += continuity::transport_divergence(a, b, ab);
            if self.continuity_corr {
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

/// The terms of pass B a scheme declares (see [`RateTerms`] for why a struct).
struct AccelTerms {
    pressure_gradient: PressureGradient,
    viscosity: Option<f64>,
    artificial_viscosity: Option<(f64, f64)>,
    transport: bool,
    momentum_corr: bool,
    shifting: Option<Shifting>,
}

impl AccelTerms {
    /// Adds neighbour `b`'s share: `b` as the divergence terms see it, `b_visc` as the
    /// viscous ones do (they differ for walls), `b_fluid` whether it is a fluid particle.
    #[inline(always)]
    fn add<const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        b: &Point<D>,
        b_visc: &Point<D>,
        b_fluid: bool,
    ) {
        match self.pressure_gradient {
            PressureGradient::Symmetric { bql } => {
                s.acc += momentum::pressure_gradient(a, b, ab);
                if bql {
                    s.c_ref += momentum::pressure_reference_weight(a, b, ab);
                }
            }
            PressureGradient::Adami { bql } => {
                s.acc += momentum::pressure_gradient_adami(a, b, ab);
                if bql {
                    s.c_ref += momentum::adami_weight(a, b, ab);
                }
            }
        }
        s.p_sum += b.p;
        s.n_nb += 1;
        if let Some(nu) = self.viscosity {
            s.acc += viscosity::morris(a, b_visc, ab, nu);
        }
        if let Some((alpha, c)) = self.artificial_viscosity {
            s.acc += artificial_viscosity::monaghan(a, b_visc, ab, alpha, c);
        }
        if self.transport {
            if b_fluid {
                s.acc += momentum::artificial_stress(a, b, ab);
                if self.momentum_corr {
                    s.acc += momentum::transport_divergence_correction(a, b, ab);
                }
            }
            match self.shifting {
                Some(Shifting::BackgroundPressure { pb }) => {
                    s.ac += shifting::background_pressure(a, b, ab, pb)
                }
                Some(Shifting::Sun2019 { w_dx, r, n, .. }) => s.ac += shifting::sun2019(b, ab, w_dx, r, n),
                _ => {}
            }
        }
    }
}

fn apply(v: &mut [f64], rate: &[f64], dt: f64) {
    v.par_iter_mut().zip(rate).with_min_len(LIGHT_LOOP_LEN).for_each(|(v, r)| *v += dt * r);
}
