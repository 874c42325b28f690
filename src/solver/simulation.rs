//! A simulation: a domain, the bodies, a scheme and the kick-drift-kick loop.

use crate::solver::integrator::{self, RatePositions};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Domain};
use crate::solver::particles::{Fluid, FluidRates, Wall};
use crate::solver::scheme::{
    build_kernel_list, build_kernel_list_summing_density, ipst_chi_reference, wavefront_applies,
    DensityModel, FluidPasses, FluidScheme, KernelList, PressureModel, Shifting, StepBodies, SurfaceFields,
    SurfacePressure, Tuner, WallSet, Wavefront,
};
pub use crate::solver::scheme::{Schedule, TUNING_STEPS};
use crate::solver::{warm, LIGHT_LOOP_LEN};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Why a run stopped early: the physics blew up. A result, not a crash.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    /// What was found.
    pub reason: String,
    /// The step after which it was found.
    pub step: u64,
    /// Simulated time at that step.
    pub time: f64,
}

/// Settings of the time loop.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct TimeSettings {
    /// The factor of eq. (61).
    pub cfl: f64,
    /// Speed of sound used in the acoustic limit.
    pub c0: f64,
    /// Reference velocity: the acoustic limit uses max(u_ref, max |u|).
    pub u_ref: f64,
    /// A speed above `blowup_factor * c0` counts as a blow-up, so that a run that grows
    /// without turning NaN still stops ([`BLOWUP_MACH`] in every scene).
    pub blowup_factor: f64,
    /// Where the density and pressure rates are evaluated (a checkpoint written before the
    /// choice existed ran `End`, the default).
    #[serde(default)]
    pub rate_positions: RatePositions,
}

impl TimeSettings {
    /// The settings of a scene: eq. (61)'s factor, the speed of sound, the reference speed;
    /// blow-ups at [`BLOWUP_MACH`]; the rates at the default [`RatePositions`].
    pub fn new(cfl: f64, c0: f64, u_ref: f64) -> Self {
        Self { cfl, c0, u_ref, blowup_factor: BLOWUP_MACH, rate_positions: RatePositions::default() }
    }
}

/// The Mach number at which a run counts as blown up. Weakly compressible SPH takes c0 at
/// least ten times the largest flow speed (Ma <= 0.1), so a particle at the speed of sound
/// has left the model by ten times its design margin. The quick preset's completed runs peak
/// at Ma = 0.15 (the Taylor-Green vortex and the cavity, c0 = 10 U) and 0.22 (the dam break);
/// a bound of 10 c0 let a Taylor-Green run at `cfl = 5` reach 45 U and report `completed`.
pub const BLOWUP_MACH: f64 = 1.0;

/// The evolving state that a checkpoint must hold to resume bit for bit.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct State<const D: usize> {
    /// The fluid body.
    pub fluid: Fluid<D>,
    /// Its rates from the last evaluation (the first kick of the next step uses them).
    pub rates: FluidRates<D>,
    /// Simulated time.
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// Largest speed at the last step (for the next time step).
    pub u_max: f64,
    /// The scheme, with quantities measured at the start (IPST chi_ref).
    pub scheme: FluidScheme,
    /// IPST moves in the last step (a diagnostic written to the time series).
    pub ipst_iterations: usize,
}

/// Wall-clock seconds spent in each phase of the step, summed over the run (a few clock
/// reads per step; reported by `sphrepro bench`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct PhaseTimes {
    /// Kicks, drift and the blow-up check.
    pub integrate: f64,
    /// Wrapping, binning, reordering and the neighbour list with its kernel values (and
    /// the fluid's share of a summation density, summed as the list is built).
    pub neighbours: f64,
    /// Summation density: the walls' share.
    pub density: f64,
    /// Density and pressure rates and their update (pass A).
    pub pressure: f64,
    /// Accelerations and homogenisation (pass B).
    pub accelerations: f64,
    /// Iterative shifting.
    pub ipst: f64,
}

impl std::ops::AddAssign for PhaseTimes {
    fn add_assign(&mut self, o: Self) {
        self.integrate += o.integrate;
        self.neighbours += o.neighbours;
        self.density += o.density;
        self.pressure += o.pressure;
        self.accelerations += o.accelerations;
        self.ipst += o.ipst;
    }
}

impl PhaseTimes {
    /// Every phase multiplied by `f` (e.g. 1 / total, for shares).
    pub fn scaled(&self, f: f64) -> Self {
        Self {
            integrate: self.integrate * f,
            neighbours: self.neighbours * f,
            density: self.density * f,
            pressure: self.pressure * f,
            accelerations: self.accelerations * f,
            ipst: self.ipst * f,
        }
    }
}

/// Adds the time since `start` to `acc` and returns now.
fn lap(start: std::time::Instant, acc: &mut f64) -> std::time::Instant {
    let now = std::time::Instant::now();
    *acc += (now - start).as_secs_f64();
    now
}

/// One simulation of one fluid body, optionally bounded by walls, in a domain.
pub struct Simulation<const D: usize> {
    /// The box.
    pub domain: Domain<D>,
    /// The smoothing kernel.
    pub kernel: Kernel,
    /// Time-loop settings.
    pub time_settings: TimeSettings,
    /// Everything that evolves.
    pub state: State<D>,
    /// The walls, if the scene has any: not integrated, so not part of the state.
    pub walls: Option<WallSet<D>>,
    /// Free-surface particles and normals, when the scheme declares a free surface
    /// (recomputed every step before the accelerations).
    pub surface: Option<SurfaceFields<D>>,
    cells: CellList<D>,
    neighbours: KernelList<D>,
    /// The fluid's share of the summation density, summed as the list is built.
    fluid_density: Vec<f64>,
    passes: FluidPasses<D>,
    /// The tiles of the wavefront step, the schedule asked for and its tuner, and the steps
    /// that ran as a wavefront.
    wave: Wavefront,
    schedule: Schedule,
    /// A tuner for each number of threads the run has stepped on: which order is faster
    /// depends on it (at nx = 200, `edac` ran 8-10 % faster in sweeps on two threads and
    /// 1.25-1.3x faster in tiles on one, session 40).
    tuners: Vec<(usize, Tuner)>,
    last_schedule: Schedule,
    wavefront_steps: u64,
    /// Time per phase of the step, summed over the run.
    pub times: PhaseTimes,
}

impl<const D: usize> Simulation<D> {
    /// Sets up the neighbour search, sorts the particles by cell and evaluates the initial
    /// rates. The scheme's free surface, if any, selects the IPST reference (sec. 3.3.2).
    pub fn new(
        domain: Domain<D>,
        kernel: Kernel,
        fluid: Fluid<D>,
        wall: Option<Wall<D>>,
        mut scheme: FluidScheme,
        time_settings: TimeSettings,
    ) -> Result<Self, String> {
        scheme.set_walls(wall.is_some());
        let radius = kernel.support() * fluid.h;
        domain.check_periodic(radius)?;
        let n = fluid.len();
        let rates = FluidRates::new(
            n,
            matches!(scheme.pressure, PressureModel::Edac { .. }),
            scheme.density == DensityModel::Continuity,
            scheme.transport.is_some(),
        );
        let state = State { fluid, rates, time: 0.0, steps: 0, u_max: 0.0, scheme, ipst_iterations: 0 };
        let mut sim = Self {
            domain,
            kernel,
            time_settings,
            state,
            walls: wall.map(|w| WallSet::new(w, domain, radius)),
            surface: scheme.free_surface.map(|_| SurfaceFields::default()),
            cells: CellList::new(domain, radius),
            neighbours: KernelList::new(),
            fluid_density: Vec::new(),
            passes: FluidPasses::new(),
            wave: Wavefront::new(),
            schedule: Schedule::default(),
            tuners: Vec::new(),
            last_schedule: Schedule::Sweeps,
            wavefront_steps: 0,
            times: PhaseTimes::default(),
        };
        sim.rebuild();
        let free_surface = scheme.free_surface.is_some();
        if let Some(t) = scheme.transport.as_mut() {
            if let Shifting::Ipst { chi_ref, .. } = &mut t.shifting {
                *chi_ref = ipst_chi_reference(
                    &sim.state.fluid,
                    &sim.neighbours,
                    sim.walls.as_ref(),
                    &sim.kernel,
                    free_surface,
                );
            }
        }
        sim.state.scheme = scheme;
        sim.state.u_max = sim.max_speed();
        // Initial accelerations for the first half kick; the pressure is the initial one.
        if sim.state.scheme.density == DensityModel::Summation {
            FluidPasses::summation_density(&mut sim.state.fluid, &sim.fluid_density, sim.walls.as_ref());
        }
        if let PressureModel::StateEquation { .. } = sim.state.scheme.pressure {
            let st = &mut sim.state;
            sim.passes.update_density_and_pressure(
                &mut st.fluid,
                &sim.neighbours,
                sim.walls.as_ref(),
                &st.scheme,
                &mut st.rates,
                0.0,
            );
            sim.extrapolate_walls();
        }
        let dt = sim.nominal_dt();
        sim.evaluate_accelerations(dt, 0);
        Ok(sim)
    }

    /// Replaces the evolving state by a checkpointed one (taken at a step boundary of a
    /// simulation built from the same parameters). The particles are stored in cell order,
    /// so re-binning them reproduces the neighbour order, and the run continues bit for bit.
    pub fn restore(&mut self, state: State<D>) {
        self.state = state;
        self.cells.update(&self.state.fluid.x);
        self.relist();
    }

    /// The fluid body.
    pub fn fluid(&self) -> &Fluid<D> {
        &self.state.fluid
    }

    /// Simulated time.
    pub fn time(&self) -> f64 {
        self.state.time
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.state.steps
    }

    /// IPST iterations in the last step.
    pub fn last_ipst_iterations(&self) -> usize {
        self.state.ipst_iterations
    }

    /// Wraps positions into the box, sorts the particles by cell and lists neighbours;
    /// then the wall pressure and velocities from the fluid.
    fn rebuild(&mut self) {
        self.rebin();
        self.relist();
    }

    /// Wraps positions into the box and sorts the particles by cell.
    fn rebin(&mut self) {
        let (domain, fluid) = (&self.domain, &mut self.state.fluid);
        fluid.x.par_iter_mut().with_min_len(LIGHT_LOOP_LEN).for_each(|x| domain.wrap(x));
        self.cells.update(&fluid.x);
        fluid.reorder(self.cells.order());
        self.cells.mark_reordered();
    }

    /// Steps of this simulation (since it was built) whose listing and passes ran as a
    /// wavefront over tiles.
    pub fn wavefront_steps(&self) -> u64 {
        self.wavefront_steps
    }

    /// How the last step's gather passes ran: sweeps or a wavefront (never
    /// [`Schedule::Tuned`]).
    pub fn last_schedule(&self) -> Schedule {
        self.last_schedule
    }

    /// How the step's gather passes are ordered ([`Schedule`]; by default the faster of the
    /// sweeps and the wavefront on this host). Every schedule gives the same results, bit
    /// for bit.
    pub fn set_schedule(&mut self, schedule: Schedule) {
        self.schedule = schedule;
    }

    /// How this step's listing and passes run: as the schedule asks, or as the tuner
    /// picks, where the scheme allows a wavefront ([`Wavefront`]) and the body, as binned
    /// now, makes enough tiles for it; else as sweeps. Also whether the tuner times the step.
    fn order(&mut self) -> (Schedule, bool) {
        let st = &self.state;
        let allowed = self.schedule != Schedule::Sweeps
            && self.time_settings.rate_positions == RatePositions::End
            && wavefront_applies(&st.scheme, self.walls.is_some());
        let n = st.fluid.len();
        let (wave, cells) = (&mut self.wave, &self.cells);
        match self.schedule {
            _ if !allowed => (Schedule::Sweeps, false),
            Schedule::Wavefront if wave.plan(cells, n) => (self.schedule, false),
            Schedule::Tuned => {
                let tuner = tuner_for(&mut self.tuners);
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

    /// The listing, summation density, pass A over `dt` and pass B of a step as a
    /// wavefront over the tiles just planned.
    fn wavefront_passes(&mut self, dt: f64, dt_nominal: f64) {
        let st = &mut self.state;
        let bodies = StepBodies {
            fluid: &mut st.fluid,
            cells: &self.cells,
            kernel: &self.kernel,
            list: &mut self.neighbours,
            fluid_density: &mut self.fluid_density,
            scheme: &st.scheme,
            rates: &mut st.rates,
        };
        let t = self.passes.wavefront_step(&mut self.wave, bodies, dt, dt_nominal);
        self.times.neighbours += t.list;
        self.times.pressure += t.pressure;
        self.times.accelerations += t.accelerations;
        self.wavefront_steps += 1;
    }

    /// The listing, summation density, pass A over `dt` (if the rates are taken after the
    /// drift) and pass B of a step, each over the whole body.
    fn swept_passes(&mut self, dt: f64, dt_nominal: f64) {
        let clock = std::time::Instant::now();
        self.relist();
        let mut clock = lap(clock, &mut self.times.neighbours);
        if self.state.scheme.density == DensityModel::Summation {
            let walls = self.walls.as_ref();
            FluidPasses::summation_density(&mut self.state.fluid, &self.fluid_density, walls);
            clock = lap(clock, &mut self.times.density);
        }
        if self.time_settings.rate_positions == RatePositions::End {
            self.update_density_and_pressure(dt);
        }
        // The walls follow the fluid's new pressure before the accelerations use it.
        self.extrapolate_walls();
        lap(clock, &mut self.times.pressure);
        self.accelerations(dt_nominal);
    }

    /// The neighbour lists from the current binning, and the wall extrapolation.
    fn relist(&mut self) {
        let fluid = &self.state.fluid;
        if self.state.scheme.density == DensityModel::Summation {
            let rho = &mut self.fluid_density;
            build_kernel_list_summing_density(&mut self.neighbours, &self.cells, fluid, &self.kernel, rho);
        } else {
            build_kernel_list(&mut self.neighbours, &self.cells, fluid, &self.kernel);
        }
        if let Some(ws) = self.walls.as_mut() {
            ws.relist(fluid, &self.cells, &self.kernel);
        }
        self.extrapolate_walls();
    }

    /// Eqs. (46)-(52) on the walls from the fluid's current state.
    fn extrapolate_walls(&mut self) {
        if let Some(ws) = self.walls.as_mut() {
            ws.extrapolate(&self.state.fluid, self.state.scheme.gravity_vector());
        }
    }

    /// Each fluid particle's shifting speed in the coming step, |u~ - u| = dt_c/2 |(du/dt)_c|
    /// (eq. 55, dt_c the step the shifting was scaled for, or the nominal step of eq. 61):
    /// how fast the shifting moves it relative to the flow; `None` without a transport
    /// velocity. (The stored u~ is of the last half step and u of the full step, so their
    /// difference also holds dt/2 du/dt.)
    pub fn shift_speeds(&self) -> Option<Vec<f64>> {
        self.state.fluid.u_hat.as_ref()?;
        let half_dt = 0.5 * self.state.rates.a_c_dt.unwrap_or_else(|| self.nominal_dt());
        Some(self.state.rates.a_c.iter().map(|a| half_dt * a.norm()).collect())
    }

    /// The time step of eq. (61) from the current largest speed.
    pub fn nominal_dt(&self) -> f64 {
        let s = &self.state.scheme;
        let g = s.gravity.iter().map(|v| v * v).sum::<f64>().sqrt();
        let ts = &self.time_settings;
        integrator::time_step(
            ts.cfl,
            self.state.fluid.h,
            ts.c0,
            ts.u_ref.max(self.state.u_max),
            s.viscosity,
            g,
        )
    }

    /// The accelerations of the state, for step `next_step` (0 the first).
    fn evaluate_accelerations(&mut self, dt_nominal: f64, next_step: u64) {
        self.accelerations(dt_nominal);
        self.homogenise(dt_nominal, next_step);
    }

    /// The free surface, if declared, and pass B.
    fn accelerations(&mut self, dt_nominal: f64) {
        let clock = std::time::Instant::now();
        if let (Some(fs), Some(free)) = (self.surface.as_mut(), self.state.scheme.free_surface) {
            let st = &mut self.state;
            fs.detect(&st.fluid, &self.neighbours, self.walls.as_ref(), free.rho0);
            fs.apply_surface_pressure(free.pressure, free.rho0, &mut st.fluid.p);
            if free.pressure != SurfacePressure::Evolve {
                // The walls' pressure (eqs. 46-52) sums the fluid's, so it follows the
                // surface pressures just set: a wall under a splash's front sees p = 0 there.
                self.extrapolate_walls();
            }
        }
        let (st, walls) = (&mut self.state, self.walls.as_ref());
        let surface = self.surface.as_ref();
        self.passes.accelerations(
            &st.fluid,
            &self.neighbours,
            walls,
            surface,
            &st.scheme,
            &mut st.rates,
            dt_nominal,
        );
        lap(clock, &mut self.times.accelerations);
    }

    /// IPST's pass (eqs. 37-41), if the scheme shifts with it, after pass B.
    fn homogenise(&mut self, dt_nominal: f64, next_step: u64) {
        let clock = std::time::Instant::now();
        let (st, walls) = (&mut self.state, self.walls.as_ref());
        st.ipst_iterations = self.passes.ipst(
            &st.fluid,
            &self.neighbours,
            &self.cells,
            walls,
            self.surface.as_ref(),
            &self.kernel,
            &st.scheme,
            &mut st.rates,
            dt_nominal,
            next_step,
        );
        lap(clock, &mut self.times.ipst);
    }

    /// Pass A: the density and pressure rates (eqs. 25-26) on the current neighbour lists
    /// and walls, and their updates over `dt` (eqs. 56-57).
    fn update_density_and_pressure(&mut self, dt: f64) {
        let (st, walls) = (&mut self.state, self.walls.as_ref());
        self.passes.update_density_and_pressure(
            &mut st.fluid,
            &self.neighbours,
            walls,
            &st.scheme,
            &mut st.rates,
            dt,
        );
    }

    /// One kick-drift-kick step of at most `max_dt` (eqs. 54-60): the half kick and the
    /// transport velocity (eqs. 54-55); the drift (eq. 59); the accelerations at the new
    /// positions and the closing half kick (eq. 60). The density and pressure rates
    /// (eqs. 25-26) and their updates (eqs. 56-57) come after the drift, or before it, at
    /// the start positions, as sec. 3.7 orders them ([`RatePositions`]).
    pub fn step(&mut self, max_dt: f64) -> Result<(), Divergence> {
        let step_clock = std::time::Instant::now();
        let clock = step_clock;
        let dt_nominal = self.nominal_dt();
        let dt = dt_nominal.min(max_dt);
        let rates_at = self.time_settings.rate_positions;
        {
            let st = &mut self.state;
            let Fluid { u, u_hat, .. } = &mut st.fluid;
            let r = &st.rates;
            integrator::kick_transport(u, u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
        }
        let mut clock = lap(clock, &mut self.times.integrate);
        if rates_at == RatePositions::Start {
            // The neighbour lists and the walls are still those of the start positions.
            self.update_density_and_pressure(dt);
            clock = lap(clock, &mut self.times.pressure);
        }
        {
            let Fluid { x, u, u_hat, .. } = &mut self.state.fluid;
            integrator::drift(x, u_hat.as_deref().unwrap_or(u), dt);
        }
        let clock = lap(clock, &mut self.times.integrate);
        self.rebin();
        lap(clock, &mut self.times.neighbours);
        // The listing and the passes, for the next step (its kick applies the
        // homogenisation acceleration): tile by tile or pass by pass, as the schedule says.
        let (schedule, timed) = self.order();
        self.last_schedule = schedule;
        if schedule == Schedule::Wavefront {
            self.wavefront_passes(dt, dt_nominal);
        } else {
            self.swept_passes(dt, dt_nominal);
        }
        self.homogenise(dt_nominal, self.state.steps + 1);
        let clock = std::time::Instant::now();
        let st = &mut self.state;
        integrator::kick(&mut st.fluid.u, &st.rates.du, dt);
        st.time += dt;
        st.steps += 1;
        let result = self.check();
        lap(clock, &mut self.times.integrate);
        if timed {
            // The whole step: a schedule also changes what the phases after it find in cache.
            tuner_for(&mut self.tuners).record(schedule, step_clock.elapsed().as_secs_f64());
        }
        result
    }

    /// Steps until the time reaches `t_stop` (without shortening steps for it, so output
    /// times never change the solution), shortening only the step that would pass `t_end`,
    /// or until `on_step` (called after every step) returns false. Returns whether `t_stop`
    /// was reached.
    pub fn advance(
        &mut self,
        t_stop: f64,
        t_end: f64,
        mut on_step: impl FnMut(&Self) -> bool,
    ) -> Result<bool, Divergence> {
        let eps = 1e-12 * t_end.abs().max(1.0);
        warm::keep_warm(|| loop {
            let remaining = t_end - self.state.time;
            if self.state.time >= t_stop - eps || remaining <= eps {
                return Ok(true);
            }
            self.step(remaining)?;
            if !on_step(self) {
                return Ok(false);
            }
        })
    }

    /// Largest particle speed.
    pub fn max_speed(&self) -> f64 {
        self.state
            .fluid
            .u
            .par_iter()
            .with_min_len(LIGHT_LOOP_LEN)
            .map(|u| u.norm_squared())
            .reduce(|| 0.0, f64::max)
            .sqrt()
    }

    /// Blow-up detection: non-finite fields, speeds beyond the bound, particles outside a
    /// bounded domain. Also records the largest speed for the next time step.
    fn check(&mut self) -> Result<(), Divergence> {
        let f = &self.state.fluid;
        let domain = &self.domain;
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
        let fail = |reason: String| Divergence { reason, step: self.state.steps, time: self.state.time };
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
            return Err(fail(format!(
                "{what} (particle {} of body `{}`, at {:?})",
                f.id[bad],
                f.name,
                f.x[bad].as_slice()
            )));
        }
        let u_max = u2.sqrt();
        let bound = self.time_settings.blowup_factor * self.time_settings.c0;
        if u_max > bound {
            // Which particle (found only now, on the way out), so that the report says where.
            let fast = (0..f.len()).max_by(|&a, &b| f.u[a].norm_squared().total_cmp(&f.u[b].norm_squared()));
            let fast = fast.expect("a body has particles");
            return Err(fail(format!(
                "max |u| = {u_max:.4e} exceeds {} c0 = {bound:.4e}: the flow has left the weakly compressible model (particle {} of body `{}`, at {:?}, p = {:.4e}, rho = {:.4e})",
                self.time_settings.blowup_factor,
                f.id[fast],
                f.name,
                f.x[fast].as_slice(),
                f.p[fast],
                f.rho[fast]
            )));
        }
        self.state.u_max = u_max;
        Ok(())
    }

    /// Positions wrapped into the box, for output.
    pub fn positions(&self) -> &[Vector<D>] {
        &self.state.fluid.x
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::kernel::KernelKind;
    use crate::solver::particles::FluidInit;
    use crate::solver::scheme::{FluidSettings, Pst, SchemeName};

    /// A Taylor-Green-like vortex on a perturbed 16x16 lattice in a periodic unit box,
    /// CTVF with IPST, with the rates taken at `rates_at`.
    fn vortex(rates_at: RatePositions) -> Simulation<2> {
        vortex_with(rates_at, Pst::Ipst)
    }

    fn vortex_with(rates_at: RatePositions, pst: Pst) -> Simulation<2> {
        vortex_sized(16, SchemeName::Ctvf, pst, rates_at)
    }

    /// The vortex on an `n` x `n` lattice with `scheme`.
    fn vortex_sized(n: usize, scheme: SchemeName, pst: Pst, rates_at: RatePositions) -> Simulation<2> {
        vortex_of(n, KernelKind::QuinticSpline, scheme, pst, rates_at)
    }

    /// The same with the kernel `kind`.
    fn vortex_of(
        n: usize,
        kind: KernelKind,
        scheme: SchemeName,
        pst: Pst,
        rates_at: RatePositions,
    ) -> Simulation<2> {
        let dx = 1.0 / n as f64;
        let mut init = FluidInit::<2>::default();
        for j in 0..n {
            for i in 0..n {
                let wobble = 0.1 * dx * ((7 * i + 3 * j) as f64).sin();
                let x = Vector::<2>::new((i as f64 + 0.5) * dx + wobble, (j as f64 + 0.5) * dx - wobble);
                let (a, b) = (2.0 * std::f64::consts::PI * x[0], 2.0 * std::f64::consts::PI * x[1]);
                init.x.push(x);
                init.u.push(Vector::<2>::new(-a.cos() * b.sin(), a.sin() * b.cos()));
                init.m.push(dx * dx);
                init.rho.push(1.0);
                init.p.push(0.0);
            }
        }
        let kernel = Kernel::new(kind, 2);
        let settings =
            FluidSettings { pst, ..FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01) };
        let scheme = scheme.fluid_scheme(&settings);
        let fluid = Fluid::new("fluid", dx, init, true).unwrap();
        let time = TimeSettings { rate_positions: rates_at, ..TimeSettings::new(0.25, 10.0, 1.0) };
        Simulation::new(Domain::periodic([0.0; 2], [1.0; 2]), kernel, fluid, None, scheme, time).unwrap()
    }

    /// Eq. (55) with eqs. (36) and (41): the shifting techniques divide (du/dt)_c by the step
    /// it is evaluated for, so a shorter step (the last before an end time) keeps the
    /// shifting velocity `dt/2 (du/dt)_c` of that step, not its own `dt'/2 (du/dt)_c`.
    #[test]
    fn a_shortened_step_keeps_the_shifting_velocity() {
        for pst in [Pst::Sun, Pst::Ipst] {
            let mut sim = vortex_with(RatePositions::End, pst);
            for _ in 0..5 {
                sim.step(f64::INFINITY).unwrap();
            }
            let dt = sim.nominal_dt();
            assert_eq!(sim.state.rates.a_c_dt, Some(dt), "{pst:?}: scaled for the nominal step");
            let before = sim.state.clone();
            let short = 0.25 * dt;
            sim.step(short).unwrap();
            let f = &before.fluid;
            let (u, du, ac) = (f.by_id(&f.u), f.by_id(&before.rates.du), f.by_id(&before.rates.a_c));
            let after = &sim.state.fluid;
            let u_hat = after.by_id(after.u_hat.as_ref().unwrap());
            let mut largest_shift: f64 = 0.0;
            for i in 0..u.len() {
                let expected = u[i] + du[i] * (0.5 * short) + ac[i] * (0.5 * dt);
                assert!(
                    (u_hat[i] - expected).norm() <= 1e-14 * expected.norm().max(1.0),
                    "{pst:?}: particle {i}"
                );
                largest_shift = largest_shift.max((ac[i] * (0.5 * dt)).norm());
            }
            assert!(largest_shift > 1e-6, "{pst:?}: the test needs a shifting velocity ({largest_shift:e})");
        }
    }

    /// Sec. 3.7: the pressure and density of step n+1 come from the rates at the start
    /// positions x^n with the half-step velocities; `RatePositions::End` takes them after the
    /// drift, so its pressure differs.
    #[test]
    fn the_rates_are_taken_where_rate_positions_says() {
        for (rates_at, at_start) in [(RatePositions::Start, true), (RatePositions::End, false)] {
            let mut sim = vortex(rates_at);
            for _ in 0..20 {
                sim.step(f64::INFINITY).unwrap();
            }
            // By hand: the half kick and u~ (eqs. 54-55), then pass A on the start lists.
            let dt = sim.nominal_dt();
            let mut probe = sim.state.clone();
            let Fluid { u, u_hat, .. } = &mut probe.fluid;
            let r = &probe.rates;
            integrator::kick_transport(u, u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
            let walls = sim.walls.as_ref();
            sim.passes.update_density_and_pressure(
                &mut probe.fluid,
                &sim.neighbours,
                walls,
                &probe.scheme,
                &mut probe.rates,
                dt,
            );
            sim.step(f64::INFINITY).unwrap();
            let bits = |f: &Fluid<2>| f.by_id(&f.p).iter().map(|p| p.to_bits()).collect::<Vec<_>>();
            let same = bits(&probe.fluid) == bits(&sim.state.fluid);
            assert_eq!(same, at_start, "{rates_at:?}");
        }
    }

    /// Each number of threads tunes its own schedule: once a run has kept one on two
    /// threads, its steps on one thread go through the trials of both orders again, and its
    /// steps back on two threads keep what two threads kept.
    #[test]
    fn each_thread_count_tunes_its_own_schedule() {
        let pool = |t: usize| rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
        let (one, two) = (pool(1), pool(2));
        let mut sim = vortex_sized(128, SchemeName::Edac, Pst::None, RatePositions::End);
        let steps = |sim: &mut Simulation<2>, n: usize| {
            let mut ran = Vec::new();
            for _ in 0..n {
                sim.step(f64::INFINITY).unwrap();
                ran.push(sim.last_schedule());
            }
            ran
        };
        two.install(|| steps(&mut sim, TUNING_STEPS));
        let kept = sim.tuners[0].1.chosen().expect("two threads kept a schedule");
        let on_one = one.install(|| steps(&mut sim, TUNING_STEPS));
        assert!(on_one.contains(&Schedule::Sweeps) && on_one.contains(&Schedule::Wavefront), "{on_one:?}");
        assert_eq!(sim.tuners.iter().map(|t| t.0).collect::<Vec<_>>(), [2, 1]);
        assert!(sim.tuners[1].1.chosen().is_some(), "one thread kept a schedule");
        assert_eq!(two.install(|| steps(&mut sim, 3)), [kept; 3]);
    }

    /// A body of four tiles (64 x 64), the fewest a wave runs in, on two threads: two
    /// regions of two tiles, each region's first passes waiting on the other's last
    /// listing. One step equals the sweeps' bit for bit. Under Miri, which checks the
    /// tiles' shared access, 28 x 28 with the cubic spline in smaller chunks, 20 minutes:
    /// `MIRIFLAGS="-Zmiri-tree-borrows -Zmiri-ignore-leaks -Zmiri-deterministic-floats"`
    /// (Miri otherwise adds random rounding errors to `sin` and `cos`, so that two set-ups
    /// of one body differ).
    #[test]
    fn four_tiles_on_two_threads_step_as_the_sweeps() {
        // Under Miri the cubic spline's narrower support makes four tiles of fewer particles.
        let (n, kernel) =
            if cfg!(miri) { (28, KernelKind::CubicSpline) } else { (64, KernelKind::QuinticSpline) };
        let run = |schedule: Schedule| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
            pool.install(|| {
                let mut sim = vortex_of(n, kernel, SchemeName::Edac, Pst::None, RatePositions::End);
                sim.wave = Wavefront::with_min_tiles(4);
                sim.set_schedule(schedule);
                sim.step(f64::INFINITY).unwrap();
                assert_eq!(sim.wavefront_steps, u64::from(schedule == Schedule::Wavefront));
                if schedule == Schedule::Wavefront {
                    assert_eq!(sim.wave.tiles(), 4);
                }
                let (f, r) = (&sim.state.fluid, &sim.state.rates);
                let mut bits: Vec<u64> = f.p.iter().chain(&f.rho).map(|x| x.to_bits()).collect();
                bits.extend(r.du.iter().chain(&f.u).flat_map(|v| v.iter().map(|c| c.to_bits())));
                bits
            })
        };
        assert_eq!(run(Schedule::Wavefront), run(Schedule::Sweeps));
    }

    /// The wavefront step sums what the sweeps sum, in the same order: the same state, bit
    /// for bit, for `edac`, `ctvf`+`sun` and `ctvf`+`ipst`, on one, two and three threads
    /// (each its wave over a region of the tiles), and when the tuner changes the order
    /// from block to block. Tiles of three chunks cut the 128 x 128 body into ten, so that
    /// the first and last meet across the periodic edge, and the regions' ends meet, and the
    /// list's storage is handed from tile to tile.
    #[test]
    fn the_wavefront_step_is_the_sweeps_bit_for_bit() {
        let cases =
            [(SchemeName::Edac, Pst::None), (SchemeName::Ctvf, Pst::Sun), (SchemeName::Ctvf, Pst::Ipst)];
        for (scheme, pst) in cases {
            let run = |schedule: Schedule, threads: usize, steps: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| {
                    let mut sim = vortex_sized(128, scheme, pst, RatePositions::End);
                    sim.set_schedule(schedule);
                    for _ in 0..steps {
                        sim.step(f64::INFINITY).unwrap();
                    }
                    let (waves, tiles) = match schedule {
                        Schedule::Sweeps => (0..1, None),
                        // The tuner's blocks of sweeps and of tiles.
                        Schedule::Tuned => (1..steps, None),
                        Schedule::Wavefront => (steps..steps + 1, Some(10)),
                    };
                    let ran = sim.wavefront_steps as usize;
                    assert!(waves.contains(&ran), "{scheme:?} {pst:?} {schedule:?}: {ran} steps tiled");
                    if let Some(tiles) = tiles {
                        assert_eq!(sim.wave.tiles(), tiles, "{scheme:?} {pst:?} {schedule:?}");
                    }
                    let f = &sim.state.fluid;
                    let r = &sim.state.rates;
                    let vectors = [&f.x, &f.u, &r.du, &r.a_c];
                    let mut bits: Vec<u64> =
                        [&f.rho, &f.p, &r.dp].iter().flat_map(|v| v.iter().map(|x| x.to_bits())).collect();
                    bits.extend(
                        vectors.iter().flat_map(|v| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits()))),
                    );
                    bits
                })
            };
            let sweeps = run(Schedule::Sweeps, 1, 4);
            for threads in 1..=3 {
                assert_eq!(
                    run(Schedule::Wavefront, threads, 4),
                    sweeps,
                    "{scheme:?} {pst:?}, {threads} threads"
                );
            }
            let steps = TUNING_STEPS + 2;
            assert_eq!(
                run(Schedule::Tuned, 2, steps),
                run(Schedule::Sweeps, 1, steps),
                "{scheme:?} {pst:?}, tuned"
            );
        }
    }
}
