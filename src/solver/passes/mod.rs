//! The physics passes: the parallel loops over a body's particles. Each pass is a gather
//! over the neighbours of every particle of one body, writing only that particle's own row:
//! a plain rayon loop with no locks or atomics, and a neighbour order fixed by the
//! neighbour lists, so results are bit-for-bit identical for any number of threads. What a
//! particle gathers from each neighbour is its interaction's
//! ([`interactions`](crate::solver::interactions)); a pass only loops.
//!
//! - [`density`]: the summation density;
//! - [`rates`]: pass A, the density and pressure rates (eqs. 25-26) and their update;
//! - [`accelerations`]: pass B, the accelerations (eq. 27) and the homogenisation;
//! - [`free_surface`]: the detection of a free surface (sec. 3.4);
//! - [`ipst`]: the iterative shifting (eqs. 37-41), whose sweeps evaluate each pair once;
//! - [`solid`]: an elastic solid's rates (eqs. 25, 31, 32) and accelerations (eq. 30).
//!
//! Detection, the summation density and IPST read a body as [`Particles`] and its
//! boundaries as [`Boundaries`], so that any body kind can use them.

pub mod accelerations;
pub mod density;
pub mod free_surface;
pub mod ipst;
pub mod rates;
pub mod solid;

use crate::solver::equations::{Pair, Point};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::math::Vector;
use crate::solver::nnps::Gather;
use crate::solver::systems::Fluid;
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// Particles per rayon task: large enough that scheduling is noise.
pub(crate) const MIN_LEN: usize = 128;

/// A body's particles as the summation density, free-surface detection and IPST read
/// them: positions, masses and densities, and the body's smoothing length.
#[derive(Clone, Copy)]
pub struct Particles<'a, const D: usize> {
    /// Positions.
    pub x: &'a [Vector<D>],
    /// Masses.
    pub m: &'a [f64],
    /// Densities.
    pub rho: &'a [f64],
    /// Smoothing length.
    pub h: f64,
}

impl<'a, const D: usize> Particles<'a, D> {
    /// A fluid's particles.
    pub fn of(f: &'a Fluid<D>) -> Self {
        Self { x: &f.x, m: &f.m, rho: &f.rho, h: f.h }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// What a fluid particle does with each neighbour of a gather: a fluid neighbour `b`, or a
/// boundary neighbour as the divergence terms, the viscous terms and the artificial
/// viscosity see it (`[b, b_visc, b_av]`).
pub(crate) trait Gatherer<const D: usize> {
    /// A fluid neighbour.
    fn fluid(&mut self, ab: &Pair<D>, b: &Point<D>);
    /// A boundary neighbour.
    fn boundary(&mut self, ab: &Pair<D>, views: [&Point<D>; 3]);
}

/// The sources a fluid particle sums over: its own body, then each boundary.
#[derive(Clone, Copy)]
pub(crate) struct Sources<'a, const D: usize> {
    h: f64,
    x: &'a [Vector<D>],
    nl: &'a KernelList<D>,
    /// Read one at a time: the wavefront step writes other tiles' meanwhile.
    pub(crate) pts: Gather<'a, Point<D>>,
    boundaries: Boundaries<'a, D>,
}

impl<'a, const D: usize> Sources<'a, D> {
    /// The fluid's own particles (their views read from `pts`) and its `boundaries`.
    pub(crate) fn new(
        fluid: &'a Fluid<D>,
        nl: &'a KernelList<D>,
        pts: Gather<'a, Point<D>>,
        boundaries: Boundaries<'a, D>,
    ) -> Self {
        Self { h: fluid.h, x: &fluid.x, nl, pts, boundaries }
    }

    /// Gives particle `i`'s neighbours to `g`: its fluid neighbours in the order of the
    /// list, then each boundary's.
    #[inline(always)]
    pub(crate) fn gather(&self, i: usize, g: &mut impl Gatherer<D>) {
        let (h, xi) = (self.h, self.x[i]);
        self.nl.for_each_with(
            i,
            xi,
            self.x,
            self.pts,
            #[inline(always)]
            |_, xij, r2, kw, b| g.fluid(&kw.pair(xij, r2, h), b),
        );
        for b in self.boundaries.iter() {
            let (div, visc, av) = (&b.model.div, &b.model.visc, &b.model.av);
            b.list.for_each_from(
                i,
                xi,
                b.x,
                #[inline(always)]
                |j, xij, r2, kw| g.boundary(&kw.pair(xij, r2, h), [&div[j], &visc[j], &av[j]]),
            );
        }
    }
}

#[inline(always)]
fn point<const D: usize>(f: &Fluid<D>, u_hat: &[Vector<D>], i: usize) -> Point<D> {
    Point::new(f.u[i], u_hat[i], f.m[i], f.rho[i], f.p[i])
}

/// Every particle's [`Point`], gathered once per pass so that each neighbour visit reads
/// one record and divides nothing.
pub(crate) fn gather_points<const D: usize>(f: &Fluid<D>, out: &mut Vec<Point<D>>) {
    let u_hat = f.u_hat();
    out.resize(f.len(), point(f, u_hat, 0));
    out.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, p)| *p = point(f, u_hat, i));
}

/// Sets the density and pressure of the particles from `first` on (one per element of
/// `points`, `rho` and `p`) with `set(i, rho_i, p_i)` and gathers their views anew from
/// `fluid`'s other fields, in rayon tasks of at least `task_len` particles.
pub(crate) fn set_and_regather<const D: usize>(
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
pub(crate) struct FluidViews<'a, const D: usize> {
    u: &'a [Vector<D>],
    u_hat: &'a [Vector<D>],
    m: &'a [f64],
}

impl<'a, const D: usize> FluidViews<'a, D> {
    pub(crate) fn of(f: &'a Fluid<D>) -> Self {
        Self { u: &f.u, u_hat: f.u_hat(), m: &f.m }
    }
}

/// Scratch state of the fluid passes that must survive between steps without allocating:
/// the fluid's particles as the passes read them (IPST takes its volumes from them).
#[derive(Debug, Default)]
pub struct FluidPasses<const D: usize> {
    pub(crate) points: Vec<Point<D>>,
}

impl<const D: usize> FluidPasses<D> {
    /// Empty work space; it grows on first use.
    pub fn new() -> Self {
        Self::default()
    }

    /// Gathers the fluid's views for a pass and returns its sources.
    pub(crate) fn gather<'a>(
        &'a mut self,
        fluid: &'a Fluid<D>,
        nl: &'a KernelList<D>,
        boundaries: Boundaries<'a, D>,
    ) -> Sources<'a, D> {
        gather_points(fluid, &mut self.points);
        Sources::new(fluid, nl, self.points[..].into(), boundaries)
    }
}

/// `v += dt rate`, element by element.
pub(crate) fn apply(v: &mut [f64], rate: &[f64], dt: f64) {
    v.par_iter_mut().zip(rate).with_min_len(LIGHT_LOOP_LEN).for_each(|(v, r)| *v += dt * r);
}

#[cfg(test)]
mod tests;
