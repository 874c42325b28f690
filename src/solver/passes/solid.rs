//! The passes of an elastic solid: its density and deviatoric-stress rates (eqs. 25, 31,
//! 32) and their update (eqs. 56, 8, 58), and its accelerations (eq. 30) with Sun's
//! shifting (eq. 36) kept tangential near its free surface (sec. 3.4, eq. 44). Gathers over
//! the body's own neighbour list and, where it sums its continuum equations over other
//! solids too ([`Continuum`]), over theirs, each particle writing its own row. The views of
//! every solid's particles are gathered ([`SolidPasses::gather`]) before any solid's pass
//! reads them.

use super::free_surface::SurfaceFields;
use super::ipst::{Ipst, Shifted, Volumes};
use super::{Particles, MIN_LEN};
use crate::solver::equations::free_surface::adjust_shift;
use crate::solver::equations::solid::SolidPoint;
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::interactions::solid_continuum::Continuum;
use crate::solver::interactions::solid_solid::{AccelSums, AccelTerms, RateSums, RateTerms};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::CellList;
use crate::solver::scheme::{GradientVelocity, SurfaceCone};
use crate::solver::systems::{ElasticSolid, SolidRates};
use rayon::prelude::*;

/// What a solid's passes keep between steps: the gathered views, its free surface and
/// IPST's work space.
#[derive(Debug, Default)]
pub struct SolidPasses<const D: usize> {
    /// The views of the particles, as last gathered.
    pub(crate) points: Vec<SolidPoint<D>>,
    /// The free surface, when the scheme detects one.
    pub surface: Option<SurfaceFields<D>>,
    ipst: Ipst<D>,
}

impl<const D: usize> SolidPasses<D> {
    /// Gathers every particle's [`SolidPoint`] from `solid`: the views the passes of this
    /// solid and of those summing over it read.
    pub fn gather(&mut self, solid: &ElasticSolid<D>) {
        let u_hat = solid.u_hat();
        let transport = solid.physics.gradient == GradientVelocity::Transport;
        let artificial_stress = solid.physics.artificial_stress.map(|a| a.eps);
        let point = |i: usize| {
            let v_grad = if transport { u_hat[i] } else { solid.u[i] };
            let point = SolidPoint::new(
                solid.u[i],
                v_grad,
                u_hat[i] - solid.u[i],
                solid.m[i],
                solid.rho[i],
                solid.p[i],
                solid.s[i],
            );
            match artificial_stress {
                Some(eps) => point.with_artificial_stress(eps),
                None => point,
            }
        };
        self.points.resize(solid.len(), point(0));
        self.points.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, p)| *p = point(i));
    }
}

/// The density rates (eq. 25) and deviatoric-stress rates (eq. 32, with the velocity
/// gradient of eq. 31) of `solid` over its list `nl` and the solids of `continuum`, into
/// `rates`, from the views gathered in `passes`.
pub fn density_and_stress_rates<const D: usize>(
    passes: &SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    continuum: Continuum<'_, D>,
    rates: &mut SolidRates<D>,
) {
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let terms = RateTerms { corrections: solid.physics.corrections };
    let g = solid.material.shear_modulus();
    rates.drho.par_iter_mut().zip(rates.ds.par_iter_mut()).enumerate().with_min_len(MIN_LEN).for_each(
        |(i, (drho, ds))| {
            let a = &pts[i];
            let mut sums = RateSums::zero();
            nl.for_each(i, x, |j, xij, r2, kw| terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h)));
            for other in continuum.iter() {
                other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                    terms.neighbour(&mut sums, a, &other.points[j], &kw.pair(xij, r2, h))
                });
            }
            *drho = sums.drho;
            *ds = terms.stress_rate(a, &sums, g);
        },
    );
}

/// The free surface of `solid` (sec. 3.4) over its own list `nl`, into `passes`, if its
/// scheme detects one: the shifting is zero on it and tangential next to it (eq. 44).
pub fn detect_surface<const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
) {
    if solid.physics.free_surface {
        let particles = Particles { x: &solid.x, m: &solid.m, rho: &solid.rho, h: solid.h };
        let fs = passes.surface.get_or_insert_with(SurfaceFields::default);
        fs.detect(particles, nl, Boundaries::none(), solid.material.rho0, SurfaceCone::Support);
    }
}

/// The accelerations of `solid` (eq. 30 with Monaghan's artificial viscosity, eq. 28,
/// Monaghan's artificial stress if the scheme has it, and the body force) over its list `nl`
/// and the solids of `continuum`, with the external acceleration `rates.a_ext` the couplings
/// added (if any), into `rates.du`; and Sun's shifting (eq. 36, for a step `dt`, over its own
/// particles only) into `rates.a_c`, zero on the free surface [detected](detect_surface) and
/// tangential next to it (eq. 44). Reads the views gathered in `passes`. Fixed particles get
/// zero of both.
pub fn accelerations<const D: usize>(
    passes: &SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    continuum: Continuum<'_, D>,
    rates: &mut SolidRates<D>,
    dt: f64,
) {
    let s = &solid.physics;
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let terms = AccelTerms {
        momentum: crate::solver::equations::solid::momentum_factor(),
        viscosity: s.artificial_viscosity.map(|alpha| (alpha, solid.material.c0())),
        sun: s.shifting.map(|sh| (sh.w_dx, sh.r, sh.n)),
        artificial_stress: s.artificial_stress.map(|a| (a.w_dx, a.n)),
    };
    // Across bodies the continuum terms only: the shifting is each body's own.
    let across = AccelTerms { sun: None, ..terms };
    // -(Ma c0) 2h / dt, eq. (36)
    let sun_prefactor = s.shifting.map_or(0.0, |sh| -sh.ma_c0 * 2.0 * h / dt);
    rates.a_c_dt = s.transports().then_some(dt);
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
        for other in continuum.iter() {
            other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                across.neighbour(&mut sums, a, &other.points[j], &kw.pair(xij, r2, h))
            });
        }
        let mut ac = sums.ac * sun_prefactor;
        if let Some(fs) = surface {
            ac = adjust_shift(ac, fs.surface[i], fs.near[i], &fs.normal[i]);
        }
        (sums.acc + gravity, ac)
    };
    // Without Sun's shifting the homogenisation is IPST's, or none: only du here.
    if s.shifting.is_none() {
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
    // The external acceleration (thesis eq. 4.6's F_FSI / m, a load): zero on fixed particles.
    let SolidRates { du, a_ext, .. } = rates;
    du.iter_mut().zip(a_ext.iter()).for_each(|(du, a)| *du += a);
}

/// IPST's homogenisation of `solid` (eqs. 37-41, for a step `dt`, on step number `step`)
/// into `rates.a_c`, with its own neighbour list `nl` and binning `cells`, no boundary, and
/// the free surface the accelerations pass detected (sec. 3.4: the surface particles are
/// not moved, their neighbours only along it). Fixed particles are not shifted. Does
/// nothing unless the scheme shifts with IPST; returns the moves made.
#[allow(clippy::too_many_arguments)]
pub fn homogenise<const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    cells: &CellList<D>,
    kernel: &Kernel,
    rates: &mut SolidRates<D>,
    dt: f64,
    step: u64,
) -> usize {
    if solid.physics.ipst.is_none() {
        return 0;
    }
    let body = Shifted {
        x: &solid.x,
        vol: Volumes::MassDensity(&solid.m, &solid.rho),
        h: solid.h,
        nl,
        cells,
        boundaries: Boundaries::none(),
    };
    let moves =
        passes.ipst.run(body, passes.surface.as_ref(), kernel, solid.physics.ipst, &mut rates.a_c, dt, step);
    for (ac, _) in rates.a_c.iter_mut().zip(&solid.fixed).filter(|(_, &fixed)| fixed) {
        *ac = Vector::zeros();
    }
    moves
}

#[cfg(test)]
mod tests {
    use crate::solver::equations::solid::j2;
    use crate::solver::interactions::UniformLoad;
    use crate::solver::kernel::{Kernel, KernelKind};
    use crate::solver::math::Vector;
    use crate::solver::nnps::Domain;
    use crate::solver::scheme::{Pst, SolidSchemeName, SolidSettings};
    use crate::solver::simulation::Simulation;
    use crate::solver::systems::{ElasticSolid, SolidInit, SolidMaterial};

    /// The oscillating plate's material (CTVF sec. 4.4).
    fn material() -> SolidMaterial {
        SolidMaterial::new(2.0e6, 0.3975, 1000.0).unwrap()
    }

    /// A lattice of `nx` x `ny` particles of spacing `dx` from the origin, at rest unless
    /// `u` says otherwise.
    fn block(nx: usize, ny: usize, dx: f64, u: impl Fn(Vector<2>) -> Vector<2>) -> SolidInit<2> {
        let mut init = SolidInit::<2>::default();
        for k in 0..nx * ny {
            let x = Vector::<2>::new(((k % nx) as f64 + 0.5) * dx, ((k / nx) as f64 + 0.5) * dx);
            init.x.push(x);
            init.u.push(u(x));
            init.m.push(material().rho0 * dx * dx);
            init.rho.push(material().rho0);
            init.fixed.push(false);
        }
        init
    }

    fn solid(init: SolidInit<2>, dx: f64, pst: Pst, alpha: f64) -> ElasticSolid<2> {
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let settings = SolidSettings {
            pst,
            corrections: true,
            alpha,
            u_ref: 1.0,
            w_dx: kernel.w(dx, dx),
            gravity: [0.0; 3],
        };
        let scheme = SolidSchemeName::Ctvf.solid_scheme(&settings).unwrap();
        ElasticSolid::new("block", dx, init, material(), scheme).unwrap()
    }

    /// A stress-free block at rest stays at rest for 1000 steps. Without shifting every
    /// rate is exactly zero (each term is a difference of equal values), so the block does
    /// not move by a bit. With Sun's shifting (and IPST) the particles near the corners, whose
    /// neighbourhoods are lopsided along the surface too, may be shifted: stated bound, a
    /// largest displacement below 0.01 dx and a largest sqrt(3 J2) and |p| below 1e-6 K.
    #[test]
    fn a_solid_at_rest_stays_at_rest() {
        let dx = 0.01;
        for pst in [Pst::None, Pst::Sun, Pst::Ipst] {
            let init = block(20, 6, dx, |_| Vector::zeros());
            let x0 = init.x.clone();
            let body = solid(init, dx, pst, 1.0);
            let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
            let domain = Domain::bounded([-1.0, -1.0], [1.2, 1.06]);
            let mut sim = Simulation::builder(domain, kernel).body(body).build().unwrap();
            for _ in 0..1000 {
                sim.step(f64::INFINITY).unwrap();
            }
            let s = sim.solids().next().unwrap();
            let moved = s.x.iter().zip(&x0).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            let stress = s.s.iter().map(|m| (3.0 * j2(m)).sqrt()).fold(0.0, f64::max);
            let p = s.p.iter().map(|p| p.abs()).fold(0.0, f64::max);
            let k = material().bulk_modulus();
            if pst == Pst::None {
                assert_eq!((moved, stress, p, s.max_speed()), (0.0, 0.0, 0.0, 0.0));
            } else {
                assert!(moved < 0.01 * dx, "moved {moved:e}");
                assert!(stress < 1e-6 * k && p < 1e-6 * k, "sqrt(3 J2) = {stress:e}, |p| = {p:e}");
            }
        }
    }

    /// A uniform load (a coupling of the block with itself) accelerates the particles of its
    /// range and no other, by exactly its acceleration: ten particles farther apart than the kernel's support (no
    /// neighbours, so no stress and no density change), no shifting, no viscosity; the load
    /// on particles 3..7, one of them fixed. After 100 steps the loaded free particles move
    /// at `a t` and the others, and the fixed one, are at rest (to rounding: 1e-12 a t).
    #[test]
    fn an_external_load_acts_on_its_range_only() {
        let dx = 0.01;
        let mut init = SolidInit::<2>::default();
        for k in 0..10 {
            init.x.push(Vector::<2>::new(5.0 * dx * k as f64, 0.0));
            init.u.push(Vector::zeros());
            init.m.push(material().rho0 * dx * dx);
            init.rho.push(material().rho0);
            init.fixed.push(k == 5);
        }
        let body = solid(init, dx, Pst::None, 0.0);
        let a = [0.0, -2.5, 0.0];
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let domain = Domain::bounded([-1.0, -1.0], [1.0, 1.0]);
        let load = UniformLoad::new(a, 3..7);
        let mut sim = Simulation::builder(domain, kernel).body(body).load("block", load).build().unwrap();
        for _ in 0..100 {
            sim.step(f64::INFINITY).unwrap();
        }
        let (t, s) = (sim.time(), sim.solids().next().unwrap());
        for (k, u) in s.u.iter().enumerate() {
            let expected = if (3..7).contains(&k) && k != 5 { a[1] * t } else { 0.0 };
            assert!(
                (u[1] - expected).abs() <= 1e-12 * (a[1] * t).abs() && u[0] == 0.0,
                "particle {k}: {u:?}"
            );
        }
    }

    /// A periodic block under a small longitudinal velocity wave, `u_x = U sin(2 pi x / L)`,
    /// is a standing P-wave of period `L / c_p`, `c_p^2 = (K + 4G/3) / rho0` (the plane-strain
    /// deviator of eq. 4 with the pressure of eq. 8). The wave's amplitude
    /// `a(t) = sum u_x sin(2 pi x / L)` goes as `cos(2 pi t c_p / L)`: its first zero comes
    /// at a quarter period. Stated bound: the speed measured from it within 2 % of c_p
    /// (40 particles a wavelength), no shifting, no artificial viscosity.
    #[test]
    fn a_small_strain_wave_travels_at_the_elastic_wave_speed() {
        let (n, l) = (40, 0.4);
        let dx = l / n as f64;
        let m = material();
        let c_p = ((m.bulk_modulus() + 4.0 / 3.0 * m.shear_modulus()) / m.rho0).sqrt();
        let k = 2.0 * std::f64::consts::PI / l;
        let amplitude = 1e-3 * c_p;
        let init = block(n, 8, dx, |x| Vector::<2>::new(amplitude * (k * x[0]).sin(), 0.0));
        let body = solid(init, dx, Pst::None, 0.0);
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let domain = Domain::periodic([0.0, 0.0], [l, 8.0 * dx]);
        let mut sim = Simulation::builder(domain, kernel).body(body).build().unwrap();
        let a = |sim: &Simulation<2>| {
            let s = sim.solids().next().unwrap();
            s.x.iter().zip(&s.u).map(|(x, u)| u[0] * (k * x[0]).sin()).sum::<f64>()
        };
        let (mut t0, mut a0) = (0.0, a(&sim));
        let quarter = loop {
            sim.step(f64::INFINITY).unwrap();
            let (t1, a1) = (sim.time(), a(&sim));
            if a1 <= 0.0 {
                break t0 + (t1 - t0) * a0 / (a0 - a1);
            }
            (t0, a0) = (t1, a1);
            assert!(t1 < l / c_p, "no zero within a period");
        };
        let c = l / (4.0 * quarter);
        println!("measured c = {c}, c_p = {c_p}");
        assert!((c - c_p).abs() < 0.02 * c_p, "c = {c} against c_p = {c_p}");
    }
}
