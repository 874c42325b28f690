//! Walls in a scheme: the wall body, its (static) cell list, the two neighbour lists that
//! couple it with the fluid, and the extrapolation pass of Adami et al. (2012).

use super::passes::{build_kernel_list_cross, KernelList};
use crate::solver::equations::wall::{ghost, WallSums};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Domain, NeighbourList};
use crate::solver::particles::{Fluid, Wall};
use rayon::prelude::*;

/// A wall body with the structures that couple it to one fluid.
#[derive(Clone, Debug)]
pub struct WallSet<const D: usize> {
    /// The wall particles.
    pub wall: Wall<D>,
    /// The wall binned once (walls do not move).
    cells: CellList<D>,
    /// For every fluid particle, its wall neighbours with the kernel values.
    pub(crate) fluid_to_wall: KernelList<D>,
    /// For every wall particle, its fluid neighbours with the kernel value.
    wall_to_fluid: NeighbourList<D, f64>,
}

impl<const D: usize> WallSet<D> {
    /// Bins the wall for searches of `radius` in `domain`.
    pub fn new(wall: Wall<D>, domain: Domain<D>, radius: f64) -> Self {
        let mut cells = CellList::new(domain, radius);
        cells.update(&wall.x);
        Self { wall, cells, fluid_to_wall: KernelList::new(), wall_to_fluid: NeighbourList::new() }
    }

    /// Relists the fluid-wall pairs after the fluid moved (`fluid_cells` binned `fluid`).
    pub fn relist(&mut self, fluid: &Fluid<D>, fluid_cells: &CellList<D>, kernel: &Kernel) {
        build_kernel_list_cross(
            &mut self.fluid_to_wall,
            &self.cells,
            &self.wall.x,
            &fluid.x,
            fluid.h,
            kernel,
        );
        let k = kernel.scaled(fluid.h);
        self.wall_to_fluid.build_cross(fluid_cells, &fluid.x, &self.wall.x, |r2, out| k.w_batch(r2, out));
    }

    /// Eqs. (46)-(52): the wall pressure and ghost velocities from the fluid's current
    /// pressure, velocity and transport velocity; `g` is gravity (the walls do not
    /// accelerate).
    pub fn extrapolate(&mut self, fluid: &Fluid<D>, g: Vector<D>) {
        let (wall, list) = (&mut self.wall, &self.wall_to_fluid);
        let u_hat = fluid.u_hat();
        let (x, u_wall, normal, pressure) = (&wall.x, &wall.u_wall, &wall.normal, wall.pressure);
        wall.ghost.resize(
            x.len(),
            ghost(&WallSums::default(), Vector::zeros(), true, Vector::zeros(), Vector::zeros(), g),
        );
        wall.ghost.par_iter_mut().enumerate().for_each(|(i, out)| {
            let mut s = WallSums::default();
            list.for_each_from(i, x[i], &fluid.x, |j, x_wf, _, &w| {
                s.add(w, x_wf, fluid.p[j], fluid.rho[j], fluid.u[j], u_hat[j]);
            });
            // The wall particles do not move: their velocity is the slip of a sliding surface.
            *out = ghost(&s, u_wall[i], true, Vector::zeros(), normal[i], g);
            out.p = pressure.apply(out.p);
        });
    }
}
