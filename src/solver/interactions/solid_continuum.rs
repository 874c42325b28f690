//! Solid-continuum: an elastic solid summing its continuum equations (eqs. 25, 30-32: the
//! density, the velocity gradient and the stress transport, the momentum with its artificial
//! viscosity and stress) over the particles of another solid as over its own, while its
//! shifting, IPST and free-surface detection stay over its own particles. Two colliding
//! rings set up as the CTVF authors' code does (two arrays whose continuum sums run over
//! both; Gray et al. 2001 with no contact law): the rings meet through the SPH sums, but the
//! shifting of one ring does not pull its contact face into the other's.
//!
//! The pairs are evaluated at the destination's smoothing length (the builder refuses two
//! solids of different smoothing lengths meeting this way).

use super::lists::{build_kernel_list_cross, KernelList};
use super::Coupling;
use crate::solver::equations::solid::SolidPoint;
use crate::solver::kernel::Kernel;
use crate::solver::math::{Matrix, Vector};
use crate::solver::nnps::CellList;
use crate::solver::systems::{Body, ElasticSolid, Work};

/// The list of the particles of solid `src` near each particle of solid `dst`.
#[derive(Debug)]
pub struct SolidContinuum<const D: usize> {
    /// The solid acted on.
    pub dst: usize,
    /// The solid acting.
    pub src: usize,
    /// For every particle of `dst`, its neighbours among `src`'s, with kernel values.
    pub list: KernelList<D>,
}

impl<const D: usize> SolidContinuum<D> {
    /// The coupling of solid `dst` with solid `src`, not listed yet.
    pub fn new(dst: usize, src: usize) -> Self {
        Self { dst, src, list: KernelList::new() }
    }

    /// Lists the neighbours of `dst`'s particles among `src`'s (binned by `src_cells`).
    pub fn relist(
        &mut self,
        src_cells: &CellList<D>,
        src: &ElasticSolid<D>,
        dst: &ElasticSolid<D>,
        kernel: &Kernel,
    ) {
        build_kernel_list_cross(&mut self.list, src_cells, &src.x, &dst.x, dst.h, kernel);
    }
}

/// One other solid as a solid's passes sum over it: its positions, the views of its
/// particles (as last gathered) and the list of them near each particle.
#[derive(Clone, Copy)]
pub struct Other<'a, const D: usize> {
    /// Positions.
    pub x: &'a [Vector<D>],
    /// Views.
    pub points: &'a [SolidPoint<D>],
    /// Their kernel-gradient corrections (empty unless the solid's gradient is corrected).
    pub correction: &'a [Matrix<D>],
    /// For every particle of the solid summing, its neighbours among them.
    pub list: &'a KernelList<D>,
}

/// The other solids a solid sums its continuum equations over, in the order of its
/// couplings.
#[derive(Clone, Copy)]
pub struct Continuum<'a, const D: usize> {
    couplings: &'a [Coupling<D>],
    idx: &'a [usize],
    bodies: &'a [Body<D>],
    work: &'a [Work<D>],
}

impl<'a, const D: usize> Continuum<'a, D> {
    /// The couplings of indices `idx` among `couplings` (each a [`SolidContinuum`]), over
    /// `bodies` with the views gathered in their `work`.
    pub fn new(
        couplings: &'a [Coupling<D>],
        idx: &'a [usize],
        bodies: &'a [Body<D>],
        work: &'a [Work<D>],
    ) -> Self {
        Self { couplings, idx, bodies, work }
    }

    /// None.
    pub fn none() -> Self {
        Self { couplings: &[], idx: &[], bodies: &[], work: &[] }
    }

    /// Each other solid, in order.
    #[inline(always)]
    pub fn iter(&self) -> impl Iterator<Item = Other<'a, D>> + 'a {
        let (couplings, bodies, work) = (self.couplings, self.bodies, self.work);
        self.idx.iter().map(move |&k| {
            let Coupling::SolidContinuum(c) = &couplings[k] else { unreachable!("a continuum coupling") };
            let x = &bodies[c.src].as_solid().expect("a solid").x;
            let passes = &work[c.src].as_solid().expect("a solid's work").passes;
            Other { x, points: &passes.points, correction: &passes.correction, list: &c.list }
        })
    }

    /// The other solids of the couplings of indices `idx` as they are (before their views
    /// are gathered), each with the list of its particles near each of this solid's.
    pub fn sources(
        couplings: &'a [Coupling<D>],
        idx: &'a [usize],
        bodies: &'a [Body<D>],
    ) -> impl Iterator<Item = (&'a KernelList<D>, &'a ElasticSolid<D>)> + 'a {
        idx.iter().map(move |&k| {
            let Coupling::SolidContinuum(c) = &couplings[k] else { unreachable!("a continuum coupling") };
            (&c.list, bodies[c.src].as_solid().expect("a solid"))
        })
    }
}
