//! The passes of an elastic solid: its density and deviatoric-stress rates (eqs. 25, 31,
//! 32) and their update (eqs. 56, 8, 58), and its accelerations (eq. 30) with Sun's
//! shifting (eq. 36) kept tangential near its free surface (sec. 3.4, eq. 44) or GTVF's
//! background pressure (eq. 20). Gathers over
//! the body's own neighbour list and, where it sums its continuum equations over other
//! solids too ([`Continuum`]), over theirs, each particle writing its own row. The views of
//! every solid's particles are gathered ([`SolidPasses::gather`]) before any solid's pass
//! reads them.

use super::free_surface::SurfaceFields;
use super::ipst::{Ipst, Shifted, Volumes};
use super::{Particles, MIN_LEN};
use crate::solver::equations::shifting::gtvf_background_pressure;
use crate::solver::equations::solid::{correction_matrix, correction_moment, SolidPoint};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::lists::KernelList;
use crate::solver::interactions::solid_continuum::Continuum;
use crate::solver::interactions::solid_solid::{AccelSums, AccelTerms, RateSums, RateTerms};
use crate::solver::kernel::Kernel;
use crate::solver::math::{Matrix, Vector};
use crate::solver::nnps::CellList;
use crate::solver::scheme::{GradientVelocity, SurfaceCone, SurfaceShift};
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
    /// Every particle's kernel-gradient correction L (empty unless the scheme corrects the
    /// gradient), as last [computed](kernel_correction).
    pub(crate) correction: Vec<Matrix<D>>,
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

/// Every particle's kernel-gradient correction `L_a` ([`correction_matrix`] of the summed
/// [`correction_moment`]) over the solid's own list `nl` and the other solids `others`
/// (with their lists) it sums its continuum equations over, into `passes`, whose views
/// must be gathered. Does nothing unless the scheme corrects the gradient.
pub fn kernel_correction<'a, const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    others: impl Iterator<Item = (&'a KernelList<D>, &'a ElasticSolid<D>)>,
) {
    if !solid.physics.kernel_correction {
        passes.correction.clear();
        return;
    }
    let others: Vec<_> = others.collect();
    let SolidPasses { points, correction, .. } = passes;
    let (x, h) = (&solid.x, solid.h);
    correction.resize(solid.len(), Matrix::identity());
    correction.par_iter_mut().enumerate().with_min_len(MIN_LEN).for_each(|(i, l)| {
        let mut moment = Matrix::<D>::zeros();
        nl.for_each(i, x, |j, xij, r2, kw| moment += correction_moment(points[j].vol, &kw.pair(xij, r2, h)));
        for (list, other) in &others {
            list.for_each_from(i, x[i], &other.x, |j, xij, r2, kw| {
                moment += correction_moment(other.m[j] / other.rho[j], &kw.pair(xij, r2, h))
            });
        }
        *l = correction_matrix(&moment);
    });
}

/// Particle `i`'s sums for its density and stress rates over the solid's list `nl` and
/// the solids of `continuum`, with its corrected kernel gradient if it has one.
#[inline(always)]
pub(crate) fn rate_sums<const D: usize>(
    passes: &SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    continuum: Continuum<'_, D>,
    terms: RateTerms,
    i: usize,
) -> RateSums<D> {
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let a = &pts[i];
    let mut sums = RateSums::zero();
    match passes.correction.get(i) {
        None => {
            nl.for_each(i, x, |j, xij, r2, kw| terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h)));
            for other in continuum.iter() {
                other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                    terms.neighbour(&mut sums, a, &other.points[j], &kw.pair(xij, r2, h))
                });
            }
        }
        Some(l) => {
            nl.for_each(i, x, |j, xij, r2, kw| {
                terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h).corrected(l))
            });
            for other in continuum.iter() {
                other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                    terms.neighbour(&mut sums, a, &other.points[j], &kw.pair(xij, r2, h).corrected(l))
                });
            }
        }
    }
    sums
}

/// The density rates (eq. 25) and deviatoric-stress rates (eq. 32, with the velocity
/// gradient of eq. 31) of `solid` over its list `nl` and the solids of `continuum`, into
/// `rates`, from the views gathered in `passes`. With the kernel gradient corrected, every
/// gradient of particle a's rates is taken with `L_a grad W` (the divergences of eqs. 25
/// and 32 are traces of the same gradients).
pub fn density_and_stress_rates<const D: usize>(
    passes: &SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    continuum: Continuum<'_, D>,
    rates: &mut SolidRates<D>,
) {
    let pts = &passes.points;
    let terms = RateTerms { corrections: solid.physics.corrections };
    let g = solid.material.shear_modulus();
    rates.drho.par_iter_mut().zip(rates.ds.par_iter_mut()).enumerate().with_min_len(MIN_LEN).for_each(
        |(i, (drho, ds))| {
            let a = &pts[i];
            let sums = rate_sums(passes, solid, nl, continuum, terms, i);
            *drho = sums.drho;
            *ds = terms.stress_rate(a, &sums, g);
        },
    );
}

/// The free surface of `solid` (sec. 3.4) over its own list `nl`, into `passes`, if its
/// scheme detects one: the shifting is zero on it and tangential next to it (eq. 44), or
/// only kept from pointing out of the body ([`SurfaceShift::Outward`]).
pub fn detect_surface<const D: usize>(
    passes: &mut SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
) {
    if solid.physics.free_surface {
        let particles = Particles { x: &solid.x, m: &solid.m, rho: &solid.rho, h: solid.h };
        let fs = passes.surface.get_or_insert_with(SurfaceFields::default);
        fs.outward_only = solid.physics.surface_shift == SurfaceShift::Outward;
        fs.detect(particles, nl, Boundaries::none(), solid.material.rho0, SurfaceCone::Support);
    }
}

/// The accelerations of `solid` (eq. 30 with Monaghan's artificial viscosity, eq. 28,
/// Monaghan's artificial stress if the scheme has it, and the body force) over its list `nl`
/// and the solids of `continuum`, with the external acceleration `rates.a_ext` the couplings
/// added (if any), into `rates.du`; and, over its own particles only, Sun's shifting
/// (eq. 36, for a step `dt`) into `rates.a_c`, zero on the free surface
/// [detected](detect_surface) and tangential next to it (eq. 44), or GTVF's
/// background-pressure homogenisation (eq. 20 with `kernel` at h/2). Reads the views
/// gathered in `passes`. Fixed particles get zero of both.
pub fn accelerations<const D: usize>(
    passes: &SolidPasses<D>,
    solid: &ElasticSolid<D>,
    nl: &KernelList<D>,
    continuum: Continuum<'_, D>,
    rates: &mut SolidRates<D>,
    (kernel, dt): (&Kernel, f64),
) {
    let s = &solid.physics;
    let (pts, x, h) = (&passes.points, &solid.x, solid.h);
    let terms = AccelTerms {
        momentum: crate::solver::equations::solid::momentum_factor(),
        viscosity: s.artificial_viscosity.map(|alpha| (alpha, solid.material.c0())),
        sun: s.shifting.map(|sh| (sh.w_dx, sh.r, sh.n)),
        gtvf: s.background_pressure.map(|_| kernel.scaled(0.5 * h)),
        artificial_stress: s.artificial_stress.map(|a| (a.w_dx, a.n)),
    };
    // Across bodies the continuum terms only: the homogenisation is each body's own.
    let across = AccelTerms { sun: None, gtvf: None, ..terms };
    // The homogenisation sum's prefactor: -(Ma c0) 2h / dt (eq. 36), or -p0_a / rho_a^2
    // (eq. 20).
    let sun_prefactor = s.shifting.map_or(0.0, |sh| -sh.ma_c0 * 2.0 * h / dt);
    let prefactor = |i: usize| match s.background_pressure {
        Some(b) => -gtvf_background_pressure(solid.p[i], b.p_ref) / (solid.rho[i] * solid.rho[i]),
        None => sun_prefactor,
    };
    rates.a_c_dt = s.transports().then_some(dt);
    let gravity = s.gravity_vector::<D>();
    let surface = passes.surface.as_ref().filter(|_| s.free_surface);
    let correction = &passes.correction;
    let fixed = &solid.fixed;
    let rate = |i: usize| -> (Vector<D>, Vector<D>) {
        if fixed[i] {
            return (Vector::zeros(), Vector::zeros());
        }
        let a = &pts[i];
        let mut sums = AccelSums { acc: Vector::zeros(), ac: Vector::zeros() };
        match correction.get(i) {
            None => {
                nl.for_each(i, x, |j, xij, r2, kw| {
                    terms.neighbour(&mut sums, a, &pts[j], &kw.pair(xij, r2, h))
                });
                for other in continuum.iter() {
                    other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                        across.neighbour(&mut sums, a, &other.points[j], &kw.pair(xij, r2, h))
                    });
                }
            }
            Some(l_a) => {
                nl.for_each(i, x, |j, xij, r2, kw| {
                    terms.neighbour_corrected(
                        &mut sums,
                        (a, l_a),
                        (&pts[j], &correction[j]),
                        &kw.pair(xij, r2, h),
                    )
                });
                for other in continuum.iter() {
                    other.list.for_each_from(i, x[i], other.x, |j, xij, r2, kw| {
                        let b = (&other.points[j], &other.correction[j]);
                        across.neighbour_corrected(&mut sums, (a, l_a), b, &kw.pair(xij, r2, h))
                    });
                }
            }
        }
        let mut ac = sums.ac * prefactor(i);
        if let Some(fs) = surface {
            ac = fs.adjust(i, ac);
        }
        (sums.acc + gravity, ac)
    };
    // Without Sun's shifting or GTVF's the homogenisation is IPST's, or none: only du here.
    if terms.sun.is_none() && terms.gtvf.is_none() {
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
    use super::{kernel_correction, rate_sums, SolidPasses};
    use crate::solver::equations::solid::j2;
    use crate::solver::interactions::lists::{build_kernel_list, KernelList};
    use crate::solver::interactions::solid_continuum::Continuum;
    use crate::solver::interactions::solid_solid::RateTerms;
    use crate::solver::interactions::UniformLoad;
    use crate::solver::kernel::{Kernel, KernelKind};
    use crate::solver::math::Matrix;
    use crate::solver::math::Vector;
    use crate::solver::nnps::CellList;
    use crate::solver::nnps::Domain;
    use crate::solver::scheme::{Pst, SolidGradient, SolidSchemeName, SolidSettings};
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
        solid_with(init, dx, pst, alpha, SolidGradient::Paper)
    }

    fn solid_with(
        init: SolidInit<2>,
        dx: f64,
        pst: Pst,
        alpha: f64,
        gradient: SolidGradient,
    ) -> ElasticSolid<2> {
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let settings = SolidSettings { alpha, gradient, ..SolidSettings::for_tests(pst, kernel.w(dx, dx)) };
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

    /// GTVF's homogenisation (eq. 20 with p0 = min(10 |p|, p_ref), grad W at h/2) on a
    /// 12 x 12 block: at the reference density (p = 0) it is exactly zero everywhere; under a
    /// uniform pressure (density 1e-3 above rho0) it pushes a particle displaced by 0.2 dx
    /// back towards its lattice site and leaves a particle 3 dx away, farther than the
    /// support at h/2 (1.5 dx) reaches, with a shift below 1e-9 of the displaced one's.
    #[test]
    fn gtvfs_background_pressure_restores_a_displaced_particle() {
        let (n, dx) = (12, 0.01);
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let settings = |p_ref| SolidSettings {
            corrections: false,
            alpha: 0.0,
            p_ref,
            ..SolidSettings::for_tests(Pst::None, kernel.w(dx, dx))
        };
        let centre = 6 * n + 6;
        let far = 6 * n + 3;
        let shifts = |density: f64| -> Vec<Vector<2>> {
            let mut init = block(n, n, dx, |_| Vector::zeros());
            init.x[centre][0] += 0.2 * dx;
            init.rho.iter_mut().for_each(|r| *r = density);
            let scheme = SolidSchemeName::Gtvf.solid_scheme(&settings(material().bulk_modulus())).unwrap();
            let solid = ElasticSolid::new("block", dx, init, material(), scheme).unwrap();
            let mut cells = CellList::new(Domain::bounded([-1.0, -1.0], [1.5, 1.5]), kernel.support() * dx);
            cells.update(&solid.x);
            let mut nl = KernelList::new();
            build_kernel_list(&mut nl, &cells, &solid.x, solid.h, &kernel);
            let mut passes = SolidPasses::default();
            passes.gather(&solid);
            let mut rates = crate::solver::systems::SolidRates::of(&solid);
            super::accelerations(&passes, &solid, &nl, Continuum::none(), &mut rates, (&kernel, 1e-5));
            rates.a_c
        };
        assert!(shifts(material().rho0).iter().all(|a| *a == Vector::<2>::zeros()), "p = 0: no shift");
        let a = shifts(material().rho0 * (1.0 + 1e-3));
        assert!(a[centre][0] < 0.0, "the displaced particle is pushed back: {:?}", a[centre]);
        assert!(a[far].norm() < 1e-9 * a[centre].norm(), "{:?} against {:?}", a[far], a[centre]);
    }

    /// The velocity gradients (the sums of eq. 31, with the solid's kernel gradient) at the
    /// particles of `solid` as they stand.
    fn gradients(solid: &ElasticSolid<2>) -> Vec<Matrix<2>> {
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let mut cells = CellList::new(Domain::bounded([-1.0, -1.0], [1.5, 1.5]), kernel.support() * solid.h);
        cells.update(&solid.x);
        let mut nl = KernelList::new();
        build_kernel_list(&mut nl, &cells, &solid.x, solid.h, &kernel);
        let mut passes = SolidPasses::default();
        passes.gather(solid);
        kernel_correction(&mut passes, solid, &nl, std::iter::empty());
        let terms = RateTerms { corrections: false };
        (0..solid.len()).map(|i| rate_sums(&passes, solid, &nl, Continuum::none(), terms, i).grad_v).collect()
    }

    /// The corrected kernel gradient makes the SPH gradient of a linear velocity field
    /// exact at every particle of a block, its surfaces and corners included (to 1e-10 of
    /// the field's gradient), where the paper's gradient at a corner sees a quarter of a
    /// support and is off by more than 20 %.
    #[test]
    fn the_corrected_gradient_of_a_linear_field_is_exact_at_every_particle() {
        let dx = 0.01;
        let grad = Matrix::<2>::new(0.3, -1.1, 0.7, 0.2);
        let v = |x: Vector<2>| grad * x + Vector::<2>::new(0.5, -0.25);
        for (gradient, hdx) in
            [(SolidGradient::Corrected, 1.0), (SolidGradient::Corrected, 1.3), (SolidGradient::Paper, 1.0)]
        {
            let mut body = solid_with(block(20, 6, dx, v), dx, Pst::None, 1.0, gradient);
            body.h = hdx * dx;
            let worst = gradients(&body).iter().map(|g| (g - grad).norm() / grad.norm()).fold(0.0, f64::max);
            match gradient {
                SolidGradient::Corrected => assert!(worst < 1e-10, "hdx {hdx}: {worst:e}"),
                SolidGradient::Paper => assert!(worst > 0.2, "{worst}"),
            }
        }
    }

    /// A pure bending field (`u_x = kappa x y`, `u_y = -kappa x^2 / 2`, y from the mid-plane:
    /// the strain rate `kappa y` across the thickness) seen by the surface row of a beam.
    /// The corrected gradient is exact for linear fields only: this one is quadratic, and
    /// at a row whose neighbourhood is lopsided in y the corrected strain is that of the
    /// neighbourhood's centroid, `kappa (y_a + m_a)` with
    /// `m_a = sum V_b F_ab dx_ab^2 dy_ba / sum V_b F_ab dx_ab^2` (F = (1/r) dW/dr; the
    /// neighbourhood is symmetric in x, so the correction matrix is diagonal): checked
    /// against that sum to 1e-9. Measured with the quintic spline and h = dx, the surface
    /// row gets 0.689, 0.729 and 0.748 of its strain with the paper's gradient and 0.883,
    /// 0.935 and 0.958 with the corrected one at 6, 10 and 15 particles across: a
    /// first-order error, the correction's limit (a second-order one would remove it).
    #[test]
    fn the_surface_row_of_a_bent_beam_gets_its_neighbourhood_centroid_strain() {
        let (dx, nx, kappa) = (0.01, 60, 2.0);
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        for (ny, paper, corrected) in [(6usize, 0.6889, 0.8832), (10, 0.7294, 0.9351), (15, 0.7475, 0.9583)] {
            let half = 0.5 * ny as f64 * dx;
            let v = |x: Vector<2>| Vector::<2>::new(kappa * x[0] * (x[1] - half), -0.5 * kappa * x[0] * x[0]);
            let top = (ny - 1) * nx + nx / 2;
            let mut ratios = Vec::new();
            for gradient in [SolidGradient::Paper, SolidGradient::Corrected] {
                let body = solid_with(block(nx, ny, dx, v), dx, Pst::None, 1.0, gradient);
                let g = gradients(&body);
                let y = body.x[top][1] - half;
                ratios.push(g[top][(0, 0)] / (kappa * y));
                if gradient == SolidGradient::Corrected {
                    let (mut num, mut den) = (0.0, 0.0);
                    for (j, xb) in body.x.iter().enumerate().filter(|(j, _)| *j != top) {
                        let d = xb - body.x[top];
                        let r = d.norm();
                        if r < kernel.support() * dx {
                            let f = kernel.w_and_grad_factor(r, dx).1 * body.m[j] / body.rho[j];
                            num += f * d[0] * d[0] * d[1];
                            den += f * d[0] * d[0];
                        }
                    }
                    let want = kappa * (y + num / den);
                    assert!(
                        (g[top][(0, 0)] - want).abs() < 1e-9 * want.abs(),
                        "{ny}: {} against {want}",
                        g[top][(0, 0)]
                    );
                }
            }
            // The measured ratios, to the four digits quoted.
            assert!(
                (ratios[0] - paper).abs() < 1e-4 && (ratios[1] - corrected).abs() < 1e-4,
                "{ny}: {ratios:?}"
            );
        }
    }

    /// Objectivity at the surfaces: a stress-free block (20 x 6, corners and all) turned
    /// rigidly by 0.5 rad about its centre, its positions and velocities prescribed
    /// (`u = omega x (x - c)`) and its stress integrated by the Jaumann rate of eq. (4) from
    /// its SPH velocity gradient (midpoint rule, 100 steps), stays stress-free with the
    /// corrected gradient: the largest von Mises stress below 1e-6 E (the target). With the
    /// paper's, the surface particles' gradient of the rotation has a symmetric part, a
    /// spurious strain: the same turn leaves more than 1e-3 E there.
    #[test]
    fn a_rigid_turn_leaves_the_corrected_solid_stress_free() {
        let (dx, omega, turns) = (0.01, 1.0, 100);
        let c = Vector::<2>::new(0.1, 0.03);
        let spin = Matrix::<2>::new(0.0, -omega, omega, 0.0);
        let e = material().youngs_modulus;
        let shear = material().shear_modulus();
        for gradient in [SolidGradient::Corrected, SolidGradient::Paper] {
            let mut body = solid_with(block(20, 6, dx, |_| Vector::zeros()), dx, Pst::None, 1.0, gradient);
            let x0 = body.x.clone();
            let dt = 0.5 / omega / turns as f64;
            let place = |body: &mut ElasticSolid<2>, theta: f64| {
                let r = nalgebra::Rotation2::new(theta).into_inner();
                for (x, (u, x0)) in body.x.iter_mut().zip(body.u.iter_mut().zip(&x0)) {
                    *x = c + r * (x0 - c);
                    *u = spin * (*x - c);
                }
            };
            for k in 0..turns {
                let theta = omega * dt * k as f64;
                let s0 = body.s.clone();
                // Midpoint: the rate at the half turn with the stress carried there.
                place(&mut body, theta);
                let half: Vec<Matrix<2>> = gradients(&body)
                    .iter()
                    .zip(&s0)
                    .map(|(g, s)| s + crate::solver::equations::solid::jaumann_rate(s, g, shear) * (0.5 * dt))
                    .collect();
                place(&mut body, theta + 0.5 * omega * dt);
                body.s.clone_from(&half);
                let g = gradients(&body);
                for ((s, s0), (g, sh)) in body.s.iter_mut().zip(&s0).zip(g.iter().zip(&half)) {
                    *s = s0 + crate::solver::equations::solid::jaumann_rate(sh, g, shear) * dt;
                }
            }
            let worst = body.s.iter().map(|s| (3.0 * j2(s)).sqrt()).fold(0.0, f64::max);
            println!("{gradient:?}: largest von Mises stress after 0.5 rad {worst:e} Pa = {:e} E", worst / e);
            match gradient {
                SolidGradient::Corrected => assert!(worst < 1e-6 * e, "von Mises {worst:e} Pa"),
                SolidGradient::Paper => assert!(worst > 1e-3 * e, "von Mises {worst:e} Pa"),
            }
        }
    }
}
