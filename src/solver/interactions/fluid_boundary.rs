//! Fluid-boundary: a fluid reads a boundary's particles (a wall's or a structure's) as
//! neighbours, with the values the boundary presents (Adami et al. 2012; CTVF sec. 3.6):
//! the divergence terms see its slip velocities and extrapolated pressure (eqs. 48-49, 52),
//! the viscous terms its no-slip velocity (eq. 50). The transport-velocity terms
//! (artificial stress, the momentum correction) sum over the fluid only. The fluid's pair
//! loops read boundaries only through [`Boundaries`]: they never name a wall.

use super::fluid_fluid::{AccelSums, AccelTerms, RateTerms};
use super::lists::{build_kernel_list_cross, KernelList};
use super::Coupling;
use crate::solver::equations::{Pair, Point};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::CellList;
use crate::solver::scheme::plan;
use crate::solver::systems::{Body, BoundaryModel};

/// The list of the boundary particles near each particle of a fluid.
#[derive(Debug)]
pub struct FluidBoundary<const D: usize> {
    /// The fluid body's index in the simulation.
    pub fluid: usize,
    /// The boundary body's index.
    pub boundary: usize,
    /// For every fluid particle, its boundary neighbours with the kernel values.
    pub list: KernelList<D>,
}

impl<const D: usize> FluidBoundary<D> {
    /// The coupling of fluid `fluid` with boundary `boundary`, not listed yet.
    pub fn new(fluid: usize, boundary: usize) -> Self {
        Self { fluid, boundary, list: KernelList::new() }
    }

    /// Lists the neighbours of the fluid's particles `fluid_x` (smoothing length `h`)
    /// among the boundary's `boundary_x`, binned by `boundary_cells`.
    pub fn relist(
        &mut self,
        boundary_cells: &CellList<D>,
        boundary_x: &[Vector<D>],
        fluid_x: &[Vector<D>],
        h: f64,
        kernel: &Kernel,
    ) {
        build_kernel_list_cross(&mut self.list, boundary_cells, boundary_x, fluid_x, h, kernel);
    }
}

/// One boundary as a fluid sees it: its particles' positions, what they present, and the
/// list of them near each fluid particle.
#[derive(Clone, Copy)]
pub struct BoundarySource<'a, const D: usize> {
    /// Positions.
    pub x: &'a [Vector<D>],
    /// Masses, densities and the views of the divergence and viscous terms.
    pub model: &'a BoundaryModel<D>,
    /// For every fluid particle, its neighbours among them.
    pub list: &'a KernelList<D>,
}

/// The boundaries a fluid sees, in the order of its couplings (which is the order their
/// shares are added in).
#[derive(Clone, Copy)]
pub struct Boundaries<'a, const D: usize> {
    couplings: &'a [Coupling<D>],
    idx: &'a [usize],
    bodies: &'a [Body<D>],
}

impl<'a, const D: usize> Boundaries<'a, D> {
    /// The boundaries of the couplings of indices `idx` among `couplings` (each a
    /// [`FluidBoundary`]), among `bodies`.
    pub fn new(couplings: &'a [Coupling<D>], idx: &'a [usize], bodies: &'a [Body<D>]) -> Self {
        Self { couplings, idx, bodies }
    }

    /// No boundary.
    pub fn none() -> Self {
        Self { couplings: &[], idx: &[], bodies: &[] }
    }

    /// Each boundary, in order.
    #[inline(always)]
    pub fn iter(&self) -> impl Iterator<Item = BoundarySource<'a, D>> + 'a {
        let (couplings, bodies) = (self.couplings, self.bodies);
        self.idx.iter().map(move |&k| {
            let c = couplings[k].as_fluid_boundary().expect("a fluid-boundary coupling");
            let (x, model) = bodies[c.boundary].as_boundary().expect("a coupling's boundary presents values");
            BoundarySource { x, model, list: &c.list }
        })
    }
}

impl RateTerms {
    /// Adds boundary neighbour `b`'s share of `(dp/dt, drho/dt)` of particle `a`: the
    /// fluid's terms, with `b` as the divergence terms see it.
    #[inline(always)]
    pub fn boundary_neighbour<const P: u32, const D: usize>(
        &self,
        sums: &mut (f64, f64),
        a: &Point<D>,
        b: &Point<D>,
        ab: &Pair<D>,
    ) {
        self.fluid_neighbour::<P, D>(sums, a, b, ab);
    }
}

impl AccelTerms {
    /// Adds boundary neighbour `b`'s share of particle `a`'s sums under plan `P`, with the
    /// views `[b, b_visc, b_av]` of the divergence terms, the viscosity and the artificial
    /// viscosity; the homogenisation sees the boundary as a neighbour (`b`), so that
    /// particles are not drawn into it.
    #[inline(always)]
    pub fn boundary_neighbour<const P: u32, const D: usize>(
        &self,
        s: &mut AccelSums<D>,
        a: &Point<D>,
        ab: &Pair<D>,
        [b, b_visc, b_av]: [&Point<D>; 3],
    ) {
        self.pressure_and_viscous::<P, D>(s, a, ab, [b, b_visc, b_av]);
        if self.has::<P>(plan::TRANSPORT) {
            self.homogenisation::<P, D>(s, a, ab, b);
        }
    }
}
