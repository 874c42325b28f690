//! The passes of an elastic solid: its density and deviatoric-stress rates (eqs. 25, 31,
//! 32) and their update (eqs. 56, 8, 58), and its accelerations (eq. 30) with Sun's
//! shifting (eq. 36) kept tangential near its free surface (sec. 3.4, eq. 44). Gathers over
//! the body's own neighbour list, each particle writing its own row.

use super::free_surface::SurfaceFields;
use super::{Particles, MIN_LEN};
use crate::solver::equations::free_surface::adjust_shift;
use crate::solver::equations::solid::SolidPoint;
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::interactions::solid_solid::{AccelSums, AccelTerms, RateSums, RateTerms};
use crate::solver::math::Vector;
use crate::solver::scheme::{GradientVelocity, SurfaceCone};
use crate::solver::systems::{ElasticSolid, SolidRates};
use rayon::prelude::*;

/// What a solid's passes keep between steps: the gathered views and its free surface.
#[derive(Debug, Default)]
pub struct SolidPasses<const D: usize> {
    points: Vec<SolidPoint<D>>,
    /// The free surface, when the scheme detects one.
    pub surface: Option<SurfaceFields<D>>,
}

impl<const D: usize> SolidPasses<D> {
    /// Gathers every particle's [`SolidPoint`] from `solid`.
    fn gather(&mut self, solid: &ElasticSolid<D>) {
        let u_hat = solid.u_hat();
        let transport = solid.physics.gradient == GradientVelocity::Transport;
        let point = |i: usize| {
            let v_grad = if transport { u_hat[i] } else { solid.u[i] };
            SolidPoint::new(
                solid.u[i],
                v_grad,
                u_hat[i] - solid.u[i],
                solid.m[i],
                solid.rho[i],
                solid.p[i],
                solid.s[i],
            )
        };
        self.points.resize(solid.len(), point(0));
        self.points.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, p)| *p = point(i));
    }
}

/// The density rates (eq. 25) and deviatoric-stress rates (eq. 32, with the velocity
/// gradient of eq. 31) of `solid` over its list `nl`, into `rates`.
pub fn density_and_stress_rates<const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    rates: &mut SolidRates<D>,
) {
    passes.gather(solid);
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let terms = RateTerms { corrections: solid.physics.corrections };
    let g = solid.material.shear_modulus();
    rates.drho.par_iter_mut().zip(rates.ds.par_iter_mut()).enumerate().with_min_len(MIN_LEN).for_each(
        |(i, (drho, ds))| {
            let a = &pts[i];
            let mut sums = RateSums::zero();
            nl.for_each(i, x, |j, xij, r2, kw| terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h)));
            *drho = sums.drho;
            *ds = terms.stress_rate(a, &sums, g);
        },
    );
}

/// The accelerations of `solid` (eq. 30 with Monaghan's artificial viscosity, eq. 28, and
/// the body force) over its list `nl` into `rates.du`, and Sun's shifting (eq. 36, for a
/// step `dt`) into `rates.a_c`, after detecting the free surface (sec. 3.4) if the scheme
/// asks, with the shifting zero on it and tangential next to it (eq. 44). Fixed particles
/// get zero of both.
pub fn accelerations<const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    rates: &mut SolidRates<D>,
    dt: f64,
) {
    let s = &solid.physics;
    if s.free_surface {
        let particles = Particles { x: &solid.x, m: &solid.m, rho: &solid.rho, h: solid.h };
        let fs = passes.surface.get_or_insert_with(SurfaceFields::default);
        fs.detect(particles, nl, Boundaries::none(), solid.material.rho0, SurfaceCone::Support);
    }
    passes.gather(solid);
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let terms = AccelTerms {
        viscosity: s.artificial_viscosity.map(|alpha| (alpha, solid.material.c0())),
        sun: s.shifting.map(|sh| (sh.w_dx, sh.r, sh.n)),
    };
    // -(Ma c0) 2h / dt, eq. (36)
    let sun_prefactor = s.shifting.map_or(0.0, |sh| -sh.ma_c0 * 2.0 * h / dt);
    rates.a_c_dt = s.shifting.map(|_| dt);
    let gravity = s.gravity_vector::<D>();
    let surface = passes.surface.as_ref().filter(|_| s.free_surface);
    let fixed = &solid.fixed;
    let rate = |i: usize| -> (Vector<D>, Vector<D>) {
        if fixed[i] {
            return (Vector::zeros(), Vector::zeros());
        }
        let a = &pts[i];
        let mut sums = AccelSums { acc: Vector::zeros(), ac: Vector::zeros() };
        nl.for_each(i, x, |j, xij, r2, kw| terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h)));
        let mut ac = sums.ac * sun_prefactor;
        if let Some(fs) = surface {
            ac = adjust_shift(ac, fs.surface[i], fs.near[i], &fs.normal[i]);
        }
        (sums.acc + gravity, ac)
    };
    if rates.a_c.is_empty() {
        rates.du.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, du)| *du = rate(i).0);
    } else {
        rates
            .du
            .par_iter_mut()
            .zip(rates.a_c.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_LEN)
            .for_each(|(i, (du, ac))| (*du, *ac) = rate(i));
    }
}
