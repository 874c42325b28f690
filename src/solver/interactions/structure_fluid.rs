//! Structure-fluid: an elastic solid in a fluid (thesis ch. 4, sec. 4.2.4). The fluid reads
//! the structure's particles as a boundary ([`fluid_boundary`](super::fluid_boundary),
//! unchanged: a structure presents the same views a wall does); this module is the other
//! direction: each structure particle
//!
//! 1. extrapolates its pressure from its fluid neighbours with its own acceleration (eq.
//!    4.14, Adami et al. 2012) and presents its own velocity
//!    ([`structure_ghost`](crate::solver::equations::wall::structure_ghost));
//! 2. gathers the reaction of the fluid's pair force (eq. 4.15): for every fluid neighbour
//!    `f` it evaluates the very terms the fluid's pass B added for this particle (pressure,
//!    viscosity, artificial viscosity, with the same views and the same pair, its kernel
//!    gradient negated), and takes `-m_f` times that acceleration. Each pair's forces are
//!    then equal and opposite to round-off, gathered without atomics in a fixed order.

use super::fluid_fluid::{AccelSums, AccelTerms};
use super::lists::{build_kernel_list_cross, KernelList};
use crate::solver::equations::wall::{structure_ghost, WallSums};
use crate::solver::equations::Point;
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::CellList;
use crate::solver::scheme::{plan, FluidScheme};
use crate::solver::systems::{BoundaryModel, ElasticSolid, Fluid};
use rayon::prelude::*;

/// The list of the fluid particles near each particle of a structure, with their kernel
/// values at the fluid's smoothing length.
#[derive(Debug)]
pub struct StructureFluid<const D: usize> {
    /// The structure's (an elastic solid's) index among the bodies.
    pub structure: usize,
    /// The fluid's index.
    pub fluid: usize,
    list: KernelList<D>,
    /// The fluid's force per unit mass on each particle, as last evaluated.
    force: Vec<Vector<D>>,
}

impl<const D: usize> StructureFluid<D> {
    /// The coupling of structure `structure` with fluid `fluid`, not listed yet.
    pub fn new(structure: usize, fluid: usize) -> Self {
        Self { structure, fluid, list: KernelList::new(), force: Vec::new() }
    }

    /// Lists the fluid neighbours (`fluid`, binned by `fluid_cells` in its current order) of
    /// the structure's particles `structure_x`, with the kernel at the fluid's smoothing
    /// length (the one the fluid's own view of the pair uses).
    pub fn relist(
        &mut self,
        fluid_cells: &CellList<D>,
        fluid: &Fluid<D>,
        structure_x: &[Vector<D>],
        kernel: &Kernel,
    ) {
        build_kernel_list_cross(&mut self.list, fluid_cells, &fluid.x, structure_x, fluid.h, kernel);
    }

    /// Eq. (4.14) on every particle of `solid` from the fluid's current pressure and
    /// velocities, with the particles' accelerations `a` (their last `du/dt`) and gravity
    /// `g`, and the views the fluid's terms read.
    pub fn extrapolate(&self, solid: &mut ElasticSolid<D>, fluid: &Fluid<D>, a: &[Vector<D>], g: Vector<D>) {
        let ElasticSolid { x, u, u_hat, boundary, .. } = solid;
        let u_hat = u_hat.as_deref().unwrap_or(u);
        let Some(BoundaryModel { m, material, ghost: ghosts, rho, div, visc, av }) = boundary.as_mut() else {
            unreachable!("a structure a fluid meets presents a boundary model")
        };
        let (material, m, list) = (*material, &m[..], &self.list);
        let fluid_u_hat = fluid.u_hat();
        let views =
            rho.par_iter_mut().zip(div.par_iter_mut()).zip(visc.par_iter_mut().zip(av.par_iter_mut()));
        ghosts.par_iter_mut().zip(views).enumerate().for_each(|(i, (out, ((rho, div), (visc, av))))| {
            let mut s = WallSums::default();
            list.for_each_from(i, x[i], &fluid.x, |j, x_sf, _, kw| {
                s.add(kw.w, x_sf, fluid.p[j], fluid.rho[j], fluid.u[j], fluid_u_hat[j]);
            });
            *out = structure_ghost(&s, u[i], u_hat[i], a[i], g);
            out.p = material.pressure.apply(out.p);
            let shown = material.present(m[i], u[i], out);
            (*rho, *div, *visc, *av) = (shown.rho, shown.div, shown.visc, shown.av);
        });
    }

    /// The fluid's force on every particle of `solid` per unit mass (the opposite of eq.
    /// 4.15): `-(1/m_s) sum_f m_f a_f<-s`, with `a_f<-s` the acceleration the fluid's terms
    /// (of `physics`) gave fluid particle `f` for this neighbour in pass B, from the same
    /// views (`points`, the fluid's as pass B gathered them; the structure's presented
    /// ones). Fixed particles (a clamp) take none: their motion is prescribed. Kept until
    /// the next evaluation.
    pub fn reaction(
        &mut self,
        solid: &ElasticSolid<D>,
        (points, h): (&[Point<D>], f64),
        fluid_x: &[Vector<D>],
        physics: &FluidScheme,
    ) -> &[Vector<D>] {
        let model = solid.boundary.as_ref().expect("a structure a fluid meets presents a boundary model");
        let terms = AccelTerms::new(physics);
        let list = &self.list;
        self.force.resize(solid.len(), Vector::zeros());
        self.force.par_iter_mut().enumerate().with_min_len(crate::solver::LIGHT_LOOP_LEN).for_each(
            |(i, out)| {
                if solid.fixed[i] {
                    *out = Vector::zeros();
                    return;
                }
                let views = [&model.div[i], &model.visc[i], &model.av[i]];
                let mut force = Vector::<D>::zeros();
                list.for_each_from(i, solid.x[i], fluid_x, |j, x_sf, r2, kw| {
                    // The fluid's pair: x_fs = -x_sf, so its kernel gradient is this one negated.
                    let pair = kw.pair(-x_sf, r2, h);
                    let mut sums = AccelSums::zero();
                    terms.pressure_and_viscous::<{ plan::RUNTIME }, D>(&mut sums, &points[j], &pair, views);
                    force -= sums.acc * points[j].m;
                });
                *out = force / solid.m[i];
            },
        );
        &self.force
    }
}
