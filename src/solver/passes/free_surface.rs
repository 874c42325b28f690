//! Free-surface detection (CTVF sec. 3.4 and Algorithm 1): normals, surface particles and
//! the particles next to them, recomputed every step for bodies that declare a free surface.

use super::Particles;
use crate::solver::equations::free_surface::{cut_normal, in_normal_cone, normal, smoothed_normal};
use crate::solver::equations::Point;
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::math::Vector;
use crate::solver::scheme::SurfacePressure;
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// A particle whose summation density (over fluid and walls) is below this fraction of the
/// reference density is isolated, away from the bulk (sec. 3.4): a surface particle.
const ISOLATED: f64 = 0.5;

/// Per-particle free-surface state of one body.
#[derive(Clone, Debug, Default)]
pub struct SurfaceFields<const D: usize> {
    n_star: Vec<Vector<D>>,
    /// Smoothed unit normal (eq. 43), zero inside the fluid.
    pub normal: Vec<Vector<D>>,
    /// Summation density `sum_b m_b W_ab` over fluid and walls (the low-density rule).
    pub rho_sum: Vec<f64>,
    /// On the free surface.
    pub surface: Vec<bool>,
    /// Not on it, but with a surface particle among its neighbours (h_b < h, Algorithm 1).
    pub near: Vec<bool>,
}

/// Particle `j` of mass `m` and density `rho` as the normals read it (its volume).
#[inline(always)]
fn volume_point<const D: usize>(m: f64, rho: f64) -> Point<D> {
    Point::new(Vector::zeros(), Vector::zeros(), m, rho, 0.0)
}

impl<const D: usize> SurfaceFields<D> {
    /// Detects the surface of the body `particles` (its list `nl`, its `boundaries` as
    /// neighbours) whose reference density is `rho0`: eq. (42) with its cut-off, eq. (43),
    /// the low-density rule (summation density below rho0 / 2), the 60-degree test, and the
    /// neighbours of surface particles.
    pub fn detect(
        &mut self,
        particles: Particles<'_, D>,
        nl: &KernelList<D>,
        boundaries: Boundaries<'_, D>,
        rho0: f64,
    ) {
        let Particles { x, m, rho, h } = particles;
        let n = particles.len();
        self.n_star.resize(n, Vector::zeros());
        self.normal.resize(n, Vector::zeros());
        self.rho_sum.resize(n, 0.0);
        self.surface.resize(n, false);
        self.near.resize(n, false);
        // Eq. (42) and the summation density, over the body and its boundaries.
        self.n_star.par_iter_mut().zip(self.rho_sum.par_iter_mut()).enumerate().for_each(|(i, (ns, rs))| {
            let (mut nv, mut r) = (Vector::<D>::zeros(), 0.0);
            nl.for_each(i, x, |j, xij, r2, kw| {
                nv += normal(&volume_point(m[j], rho[j]), &kw.pair(xij, r2, h));
                r += m[j] * kw.w;
            });
            for b in boundaries.iter() {
                let (bm, brho) = (&b.model.m, &b.model.rho);
                b.list.for_each_from(i, x[i], b.x, |j, xij, r2, kw| {
                    nv += normal(&volume_point(bm[j], brho[j]), &kw.pair(xij, r2, h));
                    r += bm[j] * kw.w;
                });
            }
            *ns = cut_normal(nv, h);
            *rs = r;
        });
        // Eq. (43): smoothed over the fluid, then normalised.
        let n_star = &self.n_star;
        self.normal.par_iter_mut().enumerate().for_each(|(i, out)| {
            let mut nv = Vector::<D>::zeros();
            nl.for_each(i, x, |j, xij, r2, kw| {
                nv += smoothed_normal(&volume_point(m[j], rho[j]), &n_star[j], &kw.pair(xij, r2, h));
            });
            let len = nv.norm();
            *out = if len > 0.0 { nv / len } else { Vector::zeros() };
        });
        // Surface particles: isolated (low density), or with a normal and no neighbour in
        // the 60-degree cone around it.
        let (normals, rho_sum) = (&self.normal, &self.rho_sum);
        self.surface.par_iter_mut().enumerate().for_each(|(i, out)| {
            let na = normals[i];
            if rho_sum[i] < ISOLATED * rho0 {
                *out = true;
                return;
            }
            if na == Vector::<D>::zeros() {
                *out = false;
                return;
            }
            let mut covered = false;
            nl.for_each(i, x, |_, xij, r2, kw| covered |= in_normal_cone(&na, &kw.pair(xij, r2, h)));
            for b in boundaries.iter() {
                b.list.for_each_from(i, x[i], b.x, |_, xij, r2, kw| {
                    covered |= in_normal_cone(&na, &kw.pair(xij, r2, h))
                });
            }
            *out = !covered;
        });
        // Algorithm 1: the particles with a surface particle in their support.
        let surface = &self.surface;
        self.near.par_iter_mut().enumerate().for_each(|(i, out)| {
            let mut near = false;
            if !surface[i] {
                nl.for_each(i, x, |j, _, _, _| near |= surface[j]);
            }
            *out = near;
        });
    }

    /// Applies `mode` to the pressure `p` of the surface particles (the body's reference
    /// density `rho0` tells the isolated ones).
    pub fn apply_surface_pressure(&self, mode: SurfacePressure, rho0: f64, p: &mut [f64]) {
        let rule = |i: usize, p: f64| match mode {
            SurfacePressure::Evolve => p,
            SurfacePressure::Zero if self.surface[i] => 0.0,
            SurfacePressure::ZeroIsolated if self.rho_sum[i] < ISOLATED * rho0 => 0.0,
            SurfacePressure::NonNegative if self.surface[i] => p.max(0.0),
            _ => p,
        };
        if mode != SurfacePressure::Evolve {
            p.par_iter_mut().enumerate().with_min_len(LIGHT_LOOP_LEN).for_each(|(i, p)| *p = rule(i, *p));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_pressure_modes_touch_the_particles_they_name() {
        // Surface particles 0, 2 and 3; particle 3 is isolated (summation density < rho0 / 2).
        let fs = SurfaceFields::<2> {
            surface: vec![true, false, true, true],
            rho_sum: vec![900.0, 1000.0, 700.0, 300.0],
            ..Default::default()
        };
        let p0 = [-3.0, -2.0, 5.0, -4.0];
        let apply = |mode| {
            let mut p = p0.to_vec();
            fs.apply_surface_pressure(mode, 1000.0, &mut p);
            p
        };
        assert_eq!(apply(SurfacePressure::Evolve), p0);
        assert_eq!(apply(SurfacePressure::Zero), [0.0, -2.0, 0.0, 0.0]);
        assert_eq!(apply(SurfacePressure::ZeroIsolated), [-3.0, -2.0, 5.0, 0.0]);
        assert_eq!(apply(SurfacePressure::NonNegative), [0.0, -2.0, 5.0, 0.0]);
    }
}
