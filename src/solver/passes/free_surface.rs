//! Free-surface detection (CTVF sec. 3.4 and Algorithm 1): normals, surface particles and
//! the particles next to them, recomputed every step for bodies that declare a free surface.

use super::Particles;
use crate::solver::equations::free_surface::{self, cut_normal, in_normal_cone, normal, smoothed_normal};
use crate::solver::equations::Point;
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::math::Vector;
use crate::solver::scheme::{SurfaceCone, SurfacePressure};
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
    /// Near the surface, remove a shift's normal component only when it points out of the
    /// body (the authors' code for solids) rather than always (eq. 44 as printed).
    pub outward_only: bool,
}

/// Particle `j` of mass `m` and density `rho` as the normals read it (its volume).
#[inline(always)]
fn volume_point<const D: usize>(m: f64, rho: f64) -> Point<D> {
    Point::new(Vector::zeros(), Vector::zeros(), m, rho, 0.0)
}

impl<const D: usize> SurfaceFields<D> {
    /// Particle `i`'s shift (an acceleration or a displacement) adjusted at the free
    /// surface: eqs. (44)-(45), or as the authors' code adjusts a solid's
    /// ([`outward_only`](Self::outward_only)).
    #[inline(always)]
    pub fn adjust(&self, i: usize, shift: Vector<D>) -> Vector<D> {
        if self.outward_only {
            free_surface::adjust_shift_outward(shift, self.surface[i], self.near[i], &self.normal[i])
        } else {
            free_surface::adjust_shift(shift, self.surface[i], self.near[i], &self.normal[i])
        }
    }

    /// Detects the surface of the body `particles` (its list `nl`, its `boundaries` as
    /// neighbours) whose reference density is `rho0`: eq. (42) with its cut-off, eq. (43),
    /// the low-density rule (summation density below rho0 / 2), the 60-degree test over the
    /// neighbours `cone` names, and the neighbours of surface particles.
    pub fn detect(
        &mut self,
        particles: Particles<'_, D>,
        nl: &KernelList<D>,
        boundaries: Boundaries<'_, D>,
        rho0: f64,
        cone: SurfaceCone,
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
            match cone {
                SurfaceCone::Support => {
                    // One neighbour in the cone settles it: the rest are not tested.
                    nl.for_each(i, x, |_, xij, r2, kw| {
                        covered = covered || in_normal_cone(&na, &kw.pair(xij, r2, h))
                    });
                    for b in boundaries.iter() {
                        b.list.for_each_from(i, x[i], b.x, |_, xij, r2, kw| {
                            covered = covered || in_normal_cone(&na, &kw.pair(xij, r2, h))
                        });
                    }
                }
                SurfaceCone::Fluid2h => {
                    let reach2 = 4.0 * h * h;
                    nl.for_each(i, x, |_, xij, r2, kw| {
                        covered = covered || (r2 < reach2 && in_normal_cone(&na, &kw.pair(xij, r2, h)))
                    });
                }
            }
            *out = !covered;
        });
        // Algorithm 1: the particles with a surface particle in their support.
        let surface = &self.surface;
        self.near.par_iter_mut().enumerate().for_each(|(i, out)| {
            *out = !surface[i] && nl.any(i, |j| surface[j]);
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

    /// The 60-degree test of a particle on the top row of a block of fluid, with one more
    /// particle straight above it 2.5 h away: within the support it covers the particle,
    /// which is then not on the surface; the authors' test looks within 2h only, and finds
    /// the particle on the surface.
    #[test]
    fn the_cone_reaches_as_far_as_it_is_told() {
        use crate::solver::interactions::lists::build_kernel_list;
        use crate::solver::kernel::{Kernel, KernelKind};
        use crate::solver::nnps::{CellList, Domain};
        let (n, dx) = (12usize, 0.1);
        let mut x: Vec<Vector<2>> =
            (0..n * n).map(|k| Vector::<2>::new((k % n) as f64 * dx, (k / n) as f64 * dx)).collect();
        let top = n * n - n / 2; // a particle in the middle of the top row
        x.push(x[top] + Vector::<2>::new(0.0, 2.5 * dx));
        let (m, rho) = (vec![1.0 * dx * dx; x.len()], vec![1.0; x.len()]);
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let mut cells = CellList::new(Domain::bounded([-1.0; 2], [3.0; 2]), kernel.support() * dx);
        cells.update(&x);
        let mut nl = crate::solver::interactions::lists::KernelList::new();
        build_kernel_list(&mut nl, &cells, &x, dx, &kernel);
        let particles = Particles { x: &x, m: &m, rho: &rho, h: dx };
        let on_surface = |cone| {
            let mut fs = SurfaceFields::<2>::default();
            fs.detect(particles, &nl, Boundaries::none(), 1.0, cone);
            assert!(fs.normal[top][1] > 0.9, "the top row's normal points up: {:?}", fs.normal[top]);
            fs.surface[top]
        };
        assert!(!on_surface(SurfaceCone::Support), "covered by the particle 2.5 h above");
        assert!(on_surface(SurfaceCone::Fluid2h), "nothing within 2h above");
    }
}
