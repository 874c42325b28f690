//! Boundary-fluid: a boundary extrapolates its pressure and velocities from its fluid
//! neighbours (Adami, Hu & Adams 2012; CTVF eqs. 46-52), with its own velocity and
//! acceleration: a wall that translates at an acceleration a_w (a piston, an accelerated
//! tank) holds the fluid with the pressure of `g - a_w` (eq. 52).

use crate::solver::equations::wall::{ghost, WallSums};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, NeighbourList};
use crate::solver::systems::{BoundaryModel, Fluid, Wall, WallMotion};
use rayon::prelude::*;

/// The list of the fluid particles near each particle of a boundary, with their kernel
/// values.
#[derive(Debug)]
pub struct BoundaryFluid<const D: usize> {
    /// The boundary body's index in the simulation.
    pub boundary: usize,
    /// The fluid body's index.
    pub fluid: usize,
    list: NeighbourList<D, f64>,
}

impl<const D: usize> BoundaryFluid<D> {
    /// The coupling of boundary `boundary` with fluid `fluid`, not listed yet.
    pub fn new(boundary: usize, fluid: usize) -> Self {
        Self { boundary, fluid, list: NeighbourList::new() }
    }

    /// Lists the fluid neighbours (`fluid`, binned by `fluid_cells` in its current order)
    /// of the boundary's particles `boundary_x`, with the kernel at the fluid's smoothing
    /// length.
    pub fn relist(
        &mut self,
        fluid_cells: &CellList<D>,
        fluid: &Fluid<D>,
        boundary_x: &[Vector<D>],
        kernel: &Kernel,
    ) {
        let k = kernel.scaled(fluid.h);
        self.list.build_cross(fluid_cells, &fluid.x, boundary_x, |r2, out| k.w_batch(r2, out));
    }

    /// Eqs. (46)-(52) on `wall` from the fluid's current pressure, velocity and transport
    /// velocity, with gravity `g`: each particle's pressure and ghost velocities, then its
    /// density and the views the fluid's terms read.
    pub fn extrapolate(&self, wall: &mut Wall<D>, fluid: &Fluid<D>, g: Vector<D>) {
        let Wall { x, normal, motion, boundary, .. } = wall;
        let list = &self.list;
        let u_hat = fluid.u_hat();
        // A sliding wall's particles stay put while its surface moves (a lid); a
        // translating one moves whole, at its acceleration.
        let (velocity, acceleration, sliding) = match &*motion {
            WallMotion::Sliding { u } => (Velocity::PerParticle(u), Vector::zeros(), true),
            WallMotion::Translating { velocity, acceleration } => {
                (Velocity::Uniform(*velocity), *acceleration, false)
            }
        };
        let BoundaryModel { m, material, ghost: ghosts, rho, div, visc, av } = boundary;
        let (material, m) = (*material, &m[..]);
        assert!(ghosts.len() == x.len(), "the boundary's values are sized for its particles");
        let views =
            rho.par_iter_mut().zip(div.par_iter_mut()).zip(visc.par_iter_mut().zip(av.par_iter_mut()));
        ghosts.par_iter_mut().zip(views).enumerate().for_each(|(i, (out, ((rho, div), (visc, av))))| {
            let mut s = WallSums::default();
            list.for_each_from(i, x[i], &fluid.x, |j, x_wf, _, &w| {
                s.add(w, x_wf, fluid.p[j], fluid.rho[j], fluid.u[j], u_hat[j]);
            });
            let u_p = match velocity {
                Velocity::PerParticle(u) => u[i],
                Velocity::Uniform(u) => u,
            };
            *out = ghost(&s, u_p, sliding, acceleration, normal[i], g);
            out.p = material.pressure.apply(out.p);
            let shown = material.present(m[i], u_p, out);
            (*rho, *div, *visc, *av) = (shown.rho, shown.div, shown.visc, shown.av);
        });
    }
}

/// The velocity of a boundary's particles.
#[derive(Clone, Copy)]
enum Velocity<'a, const D: usize> {
    PerParticle(&'a [Vector<D>]),
    Uniform(Vector<D>),
}
