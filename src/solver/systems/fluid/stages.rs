//! What a fluid does at each stage of a step ([`BodyStages`]): its passes over its own
//! neighbour list ([`FluidFluid`]) and the boundaries it reads ([`FluidBoundary`] couplings),
//! its free surface, IPST, and, alone in its simulation, the wavefront that fuses its
//! listing and passes ([`Wavefront`]).

use super::{Fluid, FluidRates};
use crate::solver::integrator::{lap, RatePositions};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::fluid_fluid::FluidFluid;
use crate::solver::interactions::{Coupling, Interaction};
use crate::solver::nnps::Domain;
use crate::solver::passes::free_surface::SurfaceFields;
use crate::solver::passes::ipst::{ipst_chi_reference, Ipst, Shifted, Volumes};
use crate::solver::passes::{accelerations, density, rates, FluidPasses, Particles};
use crate::solver::schedule::wavefront::applies as wavefront_applies;
use crate::solver::schedule::{Schedule, StepBodies, Tuner, Wavefront};
use crate::solver::scheme::{DensityModel, PressureModel, Shifting, SurfacePressure};
use crate::solver::systems::{Body, BodyStages, Rates, Work, World};
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;

/// What a fluid's passes keep from step to step: which couplings they read, the gathered
/// views, IPST's work space, the free surface, and the schedule of its passes.
#[derive(Debug)]
pub struct FluidWork<const D: usize> {
    /// The views pass B gathered (a structure's reaction reads them).
    pub(crate) passes: FluidPasses<D>,
    ipst: Ipst<D>,
    /// The free surface, if the scheme detects one (after the first evaluation).
    pub surface: Option<SurfaceFields<D>>,
    /// The index of its own coupling ([`FluidFluid`]) among the couplings.
    own: usize,
    /// The indices of the boundaries it reads ([`FluidBoundary`](crate::solver::interactions::fluid_boundary::FluidBoundary)
    /// couplings), in the order their shares are added.
    boundaries: Vec<usize>,
    /// IPST's moves in the last step.
    pub ipst_iterations: usize,
    /// Whether a coupling adds an external acceleration to it (a load).
    external: bool,
    /// The tiles of the wavefront step, the schedule asked for and its tuner per thread
    /// count, how the last step ran, whether the tuner times this step, and the steps that
    /// ran as a wavefront.
    pub(crate) wave: Wavefront,
    /// The order asked for.
    pub schedule: Schedule,
    /// A tuner for each number of threads the run has stepped on: which order is faster
    /// depends on it (`edac` at nx = 200 ran 8-10 % faster in sweeps on two threads and
    /// 1.25-1.3x faster in tiles on one, on one host).
    pub(crate) tuners: Vec<(usize, Tuner)>,
    /// How the last step's gather passes ran (never [`Schedule::Tuned`]).
    pub last_schedule: Schedule,
    timed: bool,
    /// Steps whose listing and passes ran as a wavefront.
    pub wavefront_steps: u64,
}

impl<const D: usize> FluidWork<D> {
    /// The boundaries this fluid reads, among `couplings` and `bodies`.
    fn boundaries<'a>(&'a self, couplings: &'a [Coupling<D>], bodies: &'a [Body<D>]) -> Boundaries<'a, D> {
        Boundaries::new(couplings, &self.boundaries, bodies)
    }

    /// The indices of the boundaries it reads among the couplings.
    #[cfg(test)]
    pub(crate) fn boundary_couplings(&self) -> &[usize] {
        &self.boundaries
    }

    /// Its own neighbour list and summation density.
    fn own<'a>(&self, couplings: &'a [Coupling<D>]) -> &'a FluidFluid<D> {
        let Coupling::FluidFluid(c) = &couplings[self.own] else { unreachable!("a fluid's own coupling") };
        c
    }
}

/// The stages of a [`Fluid`].
pub struct FluidStages;

/// Body `i`, a fluid, with its rates and work.
fn parts<'b, 'r, 'k, const D: usize>(
    bodies: &'b [Body<D>],
    rates: &'r mut [Rates<D>],
    work: &'k mut [Work<D>],
    i: usize,
) -> (&'b Fluid<D>, &'r mut FluidRates<D>, &'k mut FluidWork<D>) {
    let (Body::Fluid(f), Rates::Fluid(r), Work::Fluid(k)) = (&bodies[i], &mut rates[i], &mut work[i]) else {
        unreachable!("a fluid's rates and work are a fluid's")
    };
    (f, r, k)
}

impl<const D: usize> BodyStages<D> for FluidStages {
    fn work(&self, body: &Body<D>, couplings: &[Coupling<D>], incoming: &[usize]) -> Work<D> {
        let fluid = body.as_fluid().expect("a fluid");
        let of =
            |kind: Interaction| incoming.iter().copied().filter(move |&k| couplings[k].interaction() == kind);
        let own = of(Interaction::FluidFluid).next().expect("a fluid's own coupling");
        Work::Fluid(Box::new(FluidWork {
            passes: FluidPasses::default(),
            ipst: Ipst::default(),
            surface: fluid.physics.free_surface.map(|_| SurfaceFields::default()),
            own,
            boundaries: of(Interaction::FluidBoundary).collect(),
            ipst_iterations: 0,
            external: incoming.iter().any(|&k| couplings[k].interaction() == Interaction::Load),
            wave: Wavefront::new(),
            schedule: Schedule::default(),
            tuners: Vec::new(),
            last_schedule: Schedule::Sweeps,
            timed: false,
            wavefront_steps: 0,
        }))
    }

    /// Wraps the positions into the box and sorts the particles by cell.
    fn rebin(&self, w: &mut World<D>, i: usize) {
        let domain = w.domain;
        let fluid = w.bodies[i].as_fluid_mut().expect("a fluid");
        fluid.x.par_iter_mut().with_min_len(LIGHT_LOOP_LEN).for_each(|x| domain.wrap(x));
        let cells = &mut w.bins[i];
        cells.update(&fluid.x);
        fluid.reorder(cells.order());
        cells.mark_reordered();
    }

    /// IPST's reference chi (sec. 3.3.2), the largest on the initial configuration.
    fn reference(&self, w: &mut World<D>, i: usize) {
        let World { bodies, rates, work, couplings, kernel, .. } = w;
        let (fluid, _, work) = parts(bodies, rates, work, i);
        let free_surface = fluid.physics.free_surface.is_some();
        let reference = ipst_chi_reference(
            (&fluid.x, fluid.h),
            &work.own(couplings).list,
            work.boundaries(couplings, bodies),
            kernel,
            free_surface,
        );
        let fluid = bodies[i].as_fluid_mut().expect("a fluid");
        if let Some(t) = fluid.physics.transport.as_mut() {
            if let Shifting::Ipst { chi_ref, .. } = &mut t.shifting {
                *chi_ref = reference;
            }
        }
    }

    /// Pass A at the start positions, where the scheme takes its rates there (sec. 3.7).
    fn start_rates(&self, w: &mut World<D>, i: usize, dt: f64) {
        if w.settings.rate_positions == RatePositions::Start {
            let clock = std::time::Instant::now();
            density_and_pressure(w, i, dt);
            lap(clock, &mut w.times.pressure);
        }
    }

    /// The summation density: its own share, summed as its list was built, and each
    /// boundary's.
    fn density(&self, w: &mut World<D>, i: usize) {
        let World { bodies, work, couplings, times, .. } = w;
        if bodies[i].as_fluid().expect("a fluid").physics.density != DensityModel::Summation {
            return;
        }
        let clock = std::time::Instant::now();
        // Out of the body while the boundaries, among the bodies, are read (a move, no copy).
        let mut rho = std::mem::take(&mut bodies[i].as_fluid_mut().expect("a fluid").rho);
        let work = work[i].as_fluid().expect("a fluid's work");
        let x = &bodies[i].as_fluid().expect("a fluid").x;
        density::summation_density(
            &mut rho,
            x,
            &work.own(couplings).density,
            work.boundaries(couplings, bodies),
        );
        bodies[i].as_fluid_mut().expect("a fluid").rho = rho;
        lap(clock, &mut times.density);
    }

    /// Pass A after the drift over `dt`, unless the scheme takes it at the start positions;
    /// at the start of a run, a state equation's pressure from the initial density (EDAC's
    /// pressure is the initial one).
    fn pressure(&self, w: &mut World<D>, i: usize, dt: f64, start: bool) {
        let clock = std::time::Instant::now();
        let fluid = w.bodies[i].as_fluid().expect("a fluid");
        let state_equation = matches!(fluid.physics.pressure, PressureModel::StateEquation { .. });
        let now = if start { state_equation } else { w.settings.rate_positions == RatePositions::End };
        if now {
            density_and_pressure(w, i, dt);
        }
        lap(clock, &mut w.times.pressure);
    }

    /// The free surface (sec. 3.4), if the scheme declares one, and the pressure it asks
    /// there.
    fn surface(&self, w: &mut World<D>, i: usize) -> bool {
        let World { bodies, rates, work, couplings, times, .. } = w;
        let clock = std::time::Instant::now();
        let (fluid, _, work) = parts(bodies, rates, work, i);
        let Some(free) = fluid.physics.free_surface else { return false };
        let boundaries = Boundaries::new(couplings, &work.boundaries, bodies);
        let nl = &match &couplings[work.own] {
            Coupling::FluidFluid(c) => c,
            _ => unreachable!("a fluid's own coupling"),
        }
        .list;
        let fs = work.surface.get_or_insert_with(SurfaceFields::default);
        fs.detect(Particles::of(fluid), nl, boundaries, free.rho0, free.cone);
        let fluid = bodies[i].as_fluid_mut().expect("a fluid");
        fs.apply_surface_pressure(free.pressure, free.rho0, &mut fluid.p);
        lap(clock, &mut times.accelerations);
        // The boundaries' pressure (eqs. 46-52) sums the fluid's, so it follows the surface
        // pressures just set: a wall under a splash's front sees p = 0 there.
        free.pressure != SurfacePressure::Evolve
    }

    /// Pass B.
    fn accelerations(&self, w: &mut World<D>, i: usize, dt_nominal: f64) {
        let World { bodies, rates, work, couplings, times, .. } = w;
        let clock = std::time::Instant::now();
        let (fluid, rates, work) = parts(bodies, rates, work, i);
        let Coupling::FluidFluid(own) = &couplings[work.own] else { unreachable!("a fluid's own coupling") };
        let boundaries = Boundaries::new(couplings, &work.boundaries, bodies);
        let FluidWork { passes, surface, .. } = work;
        accelerations::accelerations(
            passes,
            fluid,
            &own.list,
            boundaries,
            surface.as_ref(),
            rates,
            dt_nominal,
        );
        // The external acceleration the couplings added (a load).
        let FluidRates { du, a_ext, .. } = rates;
        du.iter_mut().zip(a_ext.iter()).for_each(|(du, a)| *du += a);
        lap(clock, &mut times.accelerations);
    }

    /// The external acceleration reset to zero before the couplings add theirs.
    fn reset_external(&self, w: &mut World<D>, i: usize) {
        if !w.work[i].as_fluid().expect("a fluid's work").external {
            return;
        }
        let n = w.bodies[i].len();
        let Rates::Fluid(r) = &mut w.rates[i] else { unreachable!("a fluid's rates") };
        r.a_ext.clear();
        r.a_ext.resize(n, crate::solver::math::Vector::zeros());
    }

    /// IPST's pass (eqs. 37-41), if the fluid shifts with it, after pass B.
    fn homogenise(&self, w: &mut World<D>, i: usize, dt_nominal: f64, next_step: u64) -> usize {
        let World { bodies, rates, work, couplings, bins, kernel, times, .. } = w;
        let clock = std::time::Instant::now();
        let (fluid, rates, work) = parts(bodies, rates, work, i);
        let Coupling::FluidFluid(own) = &couplings[work.own] else { unreachable!("a fluid's own coupling") };
        let body = Shifted {
            x: &fluid.x,
            // The views pass B gathered at these positions: IPST reads their volumes.
            vol: Volumes::Points(&work.passes.points),
            h: fluid.h,
            nl: &own.list,
            cells: &bins[i],
            boundaries: Boundaries::new(couplings, &work.boundaries, bodies),
        };
        let shifting = fluid.physics.transport.map(|t| t.shifting);
        let moves = work.ipst.run(
            body,
            work.surface.as_ref(),
            kernel,
            shifting,
            &mut rates.a_c,
            dt_nominal,
            next_step,
        );
        work.ipst_iterations = moves;
        lap(clock, &mut times.ipst);
        moves
    }

    /// The listing, summation density, pass A over `dt` and pass B of a step as a wavefront
    /// over tiles, where the schedule (or the tuner) asks for one, the fluid is alone and
    /// its scheme [allows](wavefront_applies) it, and the body makes enough tiles.
    fn fused(&self, w: &mut World<D>, i: usize, dt: f64, dt_nominal: f64) -> bool {
        let World { bodies, rates, work, couplings, bins, kernel, settings, times, .. } = w;
        // Alone in its scene, with no coupling besides its own (a load is added after pass B).
        let alone = bodies.len() == 1 && !work[i].as_fluid().expect("a fluid's work").external;
        let fluid = bodies[i].as_fluid().expect("a fluid");
        let allowed =
            settings.rate_positions == RatePositions::End && wavefront_applies(&fluid.physics, alone);
        let n = fluid.len();
        let work = work[i].as_fluid_mut().expect("a fluid's work");
        let (schedule, timed) = order(work, &bins[i], n, allowed);
        work.last_schedule = schedule;
        work.timed = timed;
        if schedule != Schedule::Wavefront {
            return false;
        }
        let (Body::Fluid(fluid), Rates::Fluid(rates)) = (&mut bodies[i], &mut rates[i]) else {
            unreachable!("a fluid's rates are a fluid's")
        };
        let Coupling::FluidFluid(own) = &mut couplings[work.own] else {
            unreachable!("a fluid's own coupling")
        };
        let FluidWork { passes, wave, .. } = work;
        let step = StepBodies { fluid, cells: &bins[i], kernel, own, passes, rates };
        let t = wave.step(step, dt, dt_nominal);
        times.neighbours += t.list;
        times.pressure += t.pressure;
        times.accelerations += t.accelerations;
        work.wavefront_steps += 1;
        true
    }

    fn timed(&self, work: &mut Work<D>, seconds: f64) {
        let work = work.as_fluid_mut().expect("a fluid's work");
        if work.timed {
            // The whole step: a schedule also changes what the phases after it find in cache.
            let schedule = work.last_schedule;
            tuner_for(&mut work.tuners).record(schedule, seconds);
        }
    }

    fn sets_flow_speed(&self) -> bool {
        true
    }

    /// Non-finite fields, a particle outside a bounded domain, a speed beyond `blowup` c0.
    fn check(&self, body: &Body<D>, domain: &Domain<D>, blowup: f64) -> Result<Option<f64>, String> {
        let f = body.as_fluid().expect("a fluid");
        // (max |u|^2, first bad particle index) over particles; max and min are exact
        // and order-independent, so the outcome does not depend on the thread count.
        let (u2, bad) = (0..f.len())
            .into_par_iter()
            .with_min_len(LIGHT_LOOP_LEN)
            .map(|i| {
                let ok = f.x[i].iter().all(|v| v.is_finite())
                    && f.u[i].iter().all(|v| v.is_finite())
                    && f.p[i].is_finite()
                    && f.rho[i].is_finite()
                    && domain.contains(&f.x[i]);
                (if ok { f.u[i].norm_squared() } else { 0.0 }, if ok { usize::MAX } else { i })
            })
            .reduce(|| (0.0, usize::MAX), |a, b| (a.0.max(b.0), a.1.min(b.1)));
        if bad != usize::MAX {
            let what = if !f.u[bad].iter().all(|v| v.is_finite()) {
                "velocity is not finite"
            } else if !f.p[bad].is_finite() {
                "pressure is not finite"
            } else if !f.rho[bad].is_finite() {
                "density is not finite"
            } else if !f.x[bad].iter().all(|v| v.is_finite()) {
                "position is not finite"
            } else {
                "particle left the domain"
            };
            return Err(format!(
                "{what} (particle {} of body `{}`, at {:?})",
                f.id[bad],
                f.part_of(f.id[bad]),
                f.x[bad].as_slice()
            ));
        }
        let u_max = u2.sqrt();
        let bound = blowup * f.physics.c0;
        if u_max > bound {
            // Which particle (found only now, on the way out), so that the report says where.
            let fast = (0..f.len()).max_by(|&a, &b| f.u[a].norm_squared().total_cmp(&f.u[b].norm_squared()));
            let fast = fast.expect("a body has particles");
            return Err(format!(
                "max |u| = {u_max:.4e} exceeds {blowup} c0 = {bound:.4e}: the flow has left the weakly compressible model (particle {} of body `{}`, at {:?}, p = {:.4e}, rho = {:.4e})",
                f.id[fast],
                f.part_of(f.id[fast]),
                f.x[fast].as_slice(),
                f.p[fast],
                f.rho[fast]
            ));
        }
        Ok(Some(u_max))
    }
}

/// Pass A of fluid `i`: the density and pressure rates (eqs. 25-26) on its current
/// neighbour lists and boundaries, and their update over `dt` (eqs. 56-57).
fn density_and_pressure<const D: usize>(w: &mut World<D>, i: usize, dt: f64) {
    let World { bodies, rates, work, couplings, .. } = w;
    let (fluid, r, work) = parts(bodies, rates, work, i);
    let Coupling::FluidFluid(own) = &couplings[work.own] else { unreachable!("a fluid's own coupling") };
    let boundaries = Boundaries::new(couplings, &work.boundaries, bodies);
    rates::density_and_pressure_rates(&mut work.passes, fluid, &own.list, boundaries, r);
    let (Body::Fluid(fluid), Rates::Fluid(r)) = (&mut bodies[i], &rates[i]) else {
        unreachable!("a fluid's rates are a fluid's")
    };
    rates::update_density_and_pressure(fluid, r, dt);
}

/// How this step's listing and passes run: as the schedule asks, or as the tuner picks,
/// where the wavefront is `allowed` and the body of `n` particles, as binned by `cells` now,
/// makes enough tiles for it; else as sweeps. Also whether the tuner times the step.
fn order<const D: usize>(
    work: &mut FluidWork<D>,
    cells: &crate::solver::nnps::CellList<D>,
    n: usize,
    allowed: bool,
) -> (Schedule, bool) {
    let allowed = allowed && work.schedule != Schedule::Sweeps;
    let wave = &mut work.wave;
    match work.schedule {
        _ if !allowed => (Schedule::Sweeps, false),
        Schedule::Wavefront if wave.plan(cells, n) => (work.schedule, false),
        Schedule::Tuned => {
            let tuner = tuner_for(&mut work.tuners);
            if tuner.needs_candidates() {
                // Once the body makes tiles (one too small for them asks every step).
                if !wave.plan(cells, n) {
                    return (Schedule::Sweeps, false);
                }
                tuner.offer(vec![Schedule::Sweeps, Schedule::Wavefront]);
            }
            match tuner.next() {
                Schedule::Wavefront if !wave.plan(cells, n) => (Schedule::Sweeps, false),
                schedule => (schedule, tuner.chosen().is_none()),
            }
        }
        _ => (Schedule::Sweeps, false),
    }
}

/// The tuner of `tuners` for the current pool's number of threads, added on first use.
fn tuner_for(tuners: &mut Vec<(usize, Tuner)>) -> &mut Tuner {
    let threads = rayon::current_num_threads();
    let k = match tuners.iter().position(|t| t.0 == threads) {
        Some(k) => k,
        None => {
            tuners.push((threads, Tuner::default()));
            tuners.len() - 1
        }
    };
    &mut tuners[k].1
}
