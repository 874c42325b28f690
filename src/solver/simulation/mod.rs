//! A simulation: a domain, a list of named bodies, a list of couplings (who acts on whom,
//! [`interactions`](crate::solver::interactions)), and the kick-drift-kick loop as an
//! ordered list of stages. It names no kind of body and no interaction: each stage calls
//! every body's [`BodyStages`] hook, or every coupling's, in order.
//!
//! A step is PySPH's groups: each stage completes over every body before the next starts.
//!
//! 1. the opening half kick of every body (eqs. 54-55; a wall's prescribed motion);
//! 2. the rates taken at the start positions (sec. 3.7): a solid's density and stress rates
//!    and their update, with the half-step velocities (eqs. 25, 32, 56, 8, 58); a fluid's
//!    density and pressure rates if its [`RatePositions`] says so;
//! 3. the drift of every body (eq. 59), and the moved bodies binned again;
//! 4. every coupling's neighbour lists, the boundaries' extrapolation (eqs. 46-52), the
//!    summation density, the density and pressure rates and update (eqs. 25-26, 56-57),
//!    the extrapolation again, the free surfaces (sec. 3.4), the external accelerations the
//!    couplings add (a load), and the accelerations (eqs. 27, 30): as stages over every
//!    body, or, for a fluid alone in its scene, as a wavefront over tiles
//!    ([`Schedule`]);
//! 5. the shifting (eq. 36 within the accelerations; IPST, eqs. 37-41, here);
//! 6. the forces held over sub-steps, exchanged (below), the closing half kick of every
//!    body (eq. 60), and the blow-up check.
//!
//! A scene without a solid runs none of a solid's stages; one without a fluid none of a
//! fluid's. The time step is the smallest of the bodies' limits (eqs. 61, 62).
//!
//! **Clocks.** A body that a coupling acts on with a force held from a slower clock (an
//! elastic structure in a fluid, thesis ch. 4: its sound speed is often far above the
//! fluid's) steps on its own clock: within each step of `dt` the bodies on it take
//! [`Substeps`] steps of `dt / n` together, each a whole kick-drift-kick of their own, with
//! the couplings among them acting at every sub-step and the fluid's force on them (eq.
//! 4.15) held at the value of its last evaluation. After the fluid's passes have evaluated
//! the new force, a half kick of `dt / 2` times the change brings each structure's impulse
//! over the step to `dt / 2 (F_old + F_new)`, exactly what the fluid's two half kicks take
//! from it: momentum crosses the interface without loss, whatever `n`.
//!
//! **Particles that come and go.** A body can lose particles ([`Simulation::retain`]) or gain
//! them ([`Simulation::extend`]) between steps: the binning and every neighbour list are made
//! again. The survivors keep the rates of the last evaluation for the next opening kick, as
//! kick-drift-kick reuses them (a removed particle's force on its neighbours acts for that
//! half kick, the reaction of the closing kick it took); the new particles start with none,
//! and feel forces from the next evaluation on, half a step later. Particles the change
//! does not reach step as they would have, bit for bit.

mod builder;

pub use crate::solver::integrator::{Divergence, PhaseTimes, Substeps, TimeSettings, BLOWUP_MACH};
pub use crate::solver::schedule::{Schedule, TUNING_STEPS};
pub use builder::Builder;

use crate::solver::integrator::lap;
use crate::solver::interactions::Coupling;
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Domain};
use crate::solver::passes::free_surface::SurfaceFields;
use crate::solver::systems::{
    Body, BodyStages, ElasticSolid, Fluid, FluidRates, Rates, SolidRates, Wall, Work, World,
};
use crate::solver::LIGHT_LOOP_LEN;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The evolving state that a checkpoint must hold to resume bit for bit.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct State<const D: usize> {
    /// The bodies, with the quantities a run measures at its start (IPST's chi_ref, in the
    /// fluid's scheme).
    pub bodies: Vec<Body<D>>,
    /// Each body's rates from the last evaluation (the first kick of the next step uses
    /// them), in the order of the bodies.
    pub rates: Vec<Rates<D>>,
    /// Simulated time.
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// Largest fluid speed at the last step (for the next time step).
    pub u_max: f64,
    /// IPST moves in the last step (a diagnostic written to the time series).
    pub ipst_iterations: usize,
}

/// The clock a body steps on (see the module's documentation, *Clocks*).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Clock {
    /// The simulation's step.
    Main,
    /// Sub-steps within it.
    Own,
}

/// Which bodies a stage runs over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum On {
    /// Every body.
    All,
    /// The bodies on this clock.
    Clock(Clock),
}

/// One simulation: a domain, named bodies and the couplings among them, stepped by
/// kick-drift-kick.
pub struct Simulation<const D: usize> {
    /// The box.
    pub domain: Domain<D>,
    /// The smoothing kernel.
    pub kernel: Kernel,
    /// Time-loop settings.
    pub time_settings: TimeSettings,
    /// Everything that evolves.
    pub state: State<D>,
    /// Who acts on whom, in the order of the pairs of bodies.
    couplings: Vec<Coupling<D>>,
    /// Each body's work space.
    work: Vec<Work<D>>,
    /// Each body's binning, in the order of the bodies (a body that does not move is binned
    /// once).
    bins: Vec<CellList<D>>,
    /// The binning of each body on its own clock within a step: over the box around it, not
    /// the whole domain (binning clears every cell of its grid, and a structure is small in
    /// its tank). Unused for the others.
    local_bins: Vec<CellList<D>>,
    /// Each body's clock.
    clocks: Vec<Clock>,
    /// The order bodies are checked for a blow-up in: those whose speed does not set the
    /// time step first.
    check_order: Vec<usize>,
    /// Time per phase of the step, summed over the run.
    pub times: PhaseTimes,
}

impl<const D: usize> Simulation<D> {
    /// A simulation in `domain` with `kernel`, to which bodies are added.
    ///
    /// ```
    /// use sphrepro::solver::kernel::{Kernel, KernelKind};
    /// use sphrepro::solver::math::Vector;
    /// use sphrepro::solver::nnps::Domain;
    /// use sphrepro::solver::scheme::{FluidSettings, SchemeName};
    /// use sphrepro::solver::simulation::Simulation;
    /// use sphrepro::solver::systems::{Fluid, FluidInit};
    ///
    /// // A Taylor-Green vortex of 20 x 20 particles in the periodic unit square, `edac`.
    /// let (n, dx) = (20, 1.0 / 20.0);
    /// let mut init = FluidInit::<2>::default();
    /// for k in 0..n * n {
    ///     let x = Vector::<2>::new(((k % n) as f64 + 0.5) * dx, ((k / n) as f64 + 0.5) * dx);
    ///     let (a, b) = (2.0 * std::f64::consts::PI * x[0], 2.0 * std::f64::consts::PI * x[1]);
    ///     init.u.push(Vector::<2>::new(-a.cos() * b.sin(), a.sin() * b.cos()));
    ///     init.x.push(x);
    ///     init.m.push(dx * dx);
    ///     init.rho.push(1.0);
    ///     init.p.push(0.0);
    /// }
    /// let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    /// // rho0 = 1, c0 = 10, U = 1, h = dx, W(dx), nu = 0.01 (Re = 100)
    /// let settings = FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01);
    /// let fluid = Fluid::new("fluid", dx, init, SchemeName::Edac.fluid_scheme(&settings))?;
    /// let mut sim = Simulation::builder(Domain::periodic([0.0; 2], [1.0; 2]), kernel).body(fluid).build()?;
    /// sim.advance(0.05, 0.05, |_| true).map_err(|d| d.reason)?;
    /// assert!(sim.time() >= 0.05 && sim.max_speed() < 1.0);
    /// # Ok::<(), String>(())
    /// ```
    pub fn builder(domain: Domain<D>, kernel: Kernel) -> Builder<D> {
        Builder::new(domain, kernel)
    }

    /// The stages' view of the simulation, with the global binning or the bodies' own
    /// (`local`, in their sub-steps).
    fn world(&mut self, local: bool) -> World<'_, D> {
        let State { bodies, rates, .. } = &mut self.state;
        World {
            bodies,
            rates,
            work: &mut self.work,
            couplings: &mut self.couplings,
            bins: if local { &mut self.local_bins } else { &mut self.bins },
            kernel: &self.kernel,
            domain: self.domain,
            settings: &self.time_settings,
            times: &mut self.times,
        }
    }

    /// Calls `f` with every body of `on` and its stages; returns whether any call returned
    /// true.
    fn each(
        &mut self,
        on: On,
        local: bool,
        mut f: impl FnMut(&dyn BodyStages<D>, &mut World<D>, usize) -> bool,
    ) -> bool {
        let clocks = std::mem::take(&mut self.clocks);
        let mut any = false;
        {
            let mut w = self.world(local);
            for (i, clock) in clocks.iter().enumerate() {
                if on == On::All || on == On::Clock(*clock) {
                    let stages = w.bodies[i].stages();
                    any |= f(stages, &mut w, i);
                }
            }
        }
        self.clocks = clocks;
        any
    }

    /// Every coupling whose two bodies are on `on` (for [`On::All`], every coupling)
    /// relists its neighbours, then every boundary extrapolates.
    fn relist(&mut self, on: On, local: bool) {
        let clock = std::time::Instant::now();
        let (bodies, bins) = (&self.state.bodies, if local { &self.local_bins } else { &self.bins });
        for c in &mut self.couplings {
            let (dst, src) = c.bodies();
            if on == On::All || (On::Clock(self.clocks[dst]) == on && On::Clock(self.clocks[src]) == on) {
                c.relist(bodies, bins, &self.kernel);
            }
        }
        lap(clock, &mut self.times.neighbours);
        if on == On::All {
            self.extrapolate();
        }
    }

    /// Every boundary's values from its fluid (eqs. 46-52, 4.14).
    fn extrapolate(&mut self) {
        let State { bodies, rates, .. } = &mut self.state;
        for c in &self.couplings {
            c.extrapolate(bodies, rates);
        }
    }

    /// The external accelerations of the bodies on `clock`: reset to their held part, then
    /// each coupling acting on them at this clock adds its force.
    fn forces(&mut self, clock: Clock, local: bool) {
        self.each(On::Clock(clock), local, |s, w, i| {
            s.reset_external(w, i);
            false
        });
        let State { bodies, rates, .. } = &mut self.state;
        for c in &self.couplings {
            let (dst, _) = c.bodies();
            if self.clocks[dst] == clock && !c.holds_force() {
                if let Some(a_ext) = rates[dst].external_mut() {
                    c.add_force(bodies, a_ext);
                }
            }
        }
    }

    /// The forces held over the sub-steps, evaluated anew (see
    /// [`Coupling::exchange`]): with the closing correction kick within a step (`kick`).
    fn exchange(&mut self, kick: Option<f64>) {
        let State { bodies, rates, .. } = &mut self.state;
        for c in self.couplings.iter_mut().filter(|c| c.holds_force()) {
            c.exchange(bodies, rates, &self.work, kick);
        }
    }

    /// The free surfaces, the external accelerations and the accelerations of the bodies on
    /// `clock` for a step `dt` (the boundaries extrapolated again if a surface set
    /// pressures), then their shifting for step number `next_step`.
    fn accelerate(&mut self, clock: Clock, local: bool, dt: f64, next_step: u64) {
        if self.each(On::Clock(clock), local, |s, w, i| s.surface(w, i)) {
            self.extrapolate();
        }
        self.forces(clock, local);
        self.each(On::Clock(clock), local, |s, w, i| {
            s.gather(w, i);
            false
        });
        self.each(On::Clock(clock), local, |s, w, i| {
            s.accelerations(w, i, dt);
            false
        });
        self.homogenise(clock, local, dt, next_step);
    }

    /// The iterative shifting of the bodies on `clock`.
    fn homogenise(&mut self, clock: Clock, local: bool, dt: f64, next_step: u64) {
        let mut moves = 0;
        self.each(On::Clock(clock), local, |s, w, i| {
            moves += s.homogenise(w, i, dt, next_step);
            false
        });
        if clock == Clock::Main {
            self.state.ipst_iterations = moves;
        }
    }

    /// Sorts and lists the particles and evaluates the initial rates: IPST's reference
    /// (sec. 3.3.2), the summation density or the state equation's pressure, and the
    /// accelerations for the first half kick (the pressure is the initial one).
    fn start(&mut self) {
        self.each(On::All, false, |s, w, i| {
            s.rebin(w, i);
            false
        });
        self.relist(On::All, false);
        self.each(On::All, false, |s, w, i| {
            s.reference(w, i);
            false
        });
        self.state.u_max = self.max_speed();
        self.rates_at_rest(0);
    }

    /// The rates of every body at the current state, on the lists just made, for the next
    /// step's opening kick (step number `next_step`): as at the start of a run, the
    /// summation density, a state equation's pressure, the accelerations and the shifting,
    /// and the forces held over the sub-steps.
    fn rates_at_rest(&mut self, next_step: u64) {
        let (dt, n) = self.step_sizes();
        self.evaluate(0.0, true);
        self.accelerate(Clock::Main, false, dt, next_step);
        self.exchange(None);
        self.accelerate(Clock::Own, false, dt / n as f64, next_step);
    }

    /// The evaluations of the bodies on the main clock up to their free surfaces: the
    /// summation density, and the density and pressure rates with their update over `dt`
    /// (at the `start`, a state equation's pressure), each followed by the boundaries'
    /// extrapolation.
    fn evaluate(&mut self, dt: f64, start: bool) {
        let main = On::Clock(Clock::Main);
        self.each(main, false, |s, w, i| {
            s.density(w, i);
            false
        });
        self.each(main, false, |s, w, i| {
            s.pressure(w, i, dt, start);
            false
        });
        // The boundaries follow the fluid's new pressure before the accelerations use it.
        let clock = std::time::Instant::now();
        self.extrapolate();
        lap(clock, &mut self.times.pressure);
    }

    /// Replaces the evolving state by a checkpointed one (taken at a step boundary of a
    /// simulation built from the same parameters). The fluid's particles are stored in cell
    /// order, so re-binning them reproduces the neighbour order, and the run continues bit
    /// for bit.
    pub fn restore(&mut self, state: State<D>) {
        self.state = state;
        for body in &mut self.state.bodies {
            body.resize_boundary();
        }
        self.each(On::All, false, |s, w, i| {
            s.rebin(w, i);
            false
        });
        self.relist(On::All, false);
    }

    /// Removes the particles of body `name` for which `keep` (given the particle's index)
    /// is false, between steps: the survivors keep their rates; the binning and every list
    /// are made again (see the module's documentation). Errors for no such body, a body whose particles cannot change (a
    /// wall, a structure a fluid reads), or one that would be left empty.
    pub fn retain(&mut self, name: &str, keep: impl Fn(usize) -> bool) -> Result<usize, String> {
        let k = self.index_of(name)?;
        let keep: Vec<bool> = (0..self.state.bodies[k].len()).map(keep).collect();
        let removed = keep.iter().filter(|&&k| !k).count();
        if removed == 0 {
            return Ok(0);
        }
        if removed == keep.len() {
            return Err(format!("body `{name}`: removing all its {} particles", keep.len()));
        }
        self.state.bodies[k].retain(&keep)?;
        self.state.rates[k].retain(&keep);
        self.rebuild();
        Ok(removed)
    }

    /// Adds particles to body `name` between steps, their values from `more` (a body of the
    /// same kind and physics, as built): they start with zero rates; the binning and every
    /// list are made again. Errors as [`retain`](Self::retain), and for a body of another
    /// kind or physics.
    pub fn extend(&mut self, name: &str, more: impl Into<Body<D>>) -> Result<usize, String> {
        let k = self.index_of(name)?;
        let more = more.into();
        let added = more.len();
        let zero = more.zero_rates();
        self.state.bodies[k].extend(more)?;
        self.state.rates[k].extend(zero);
        self.rebuild();
        Ok(added)
    }

    /// The index of the body named `name`.
    fn index_of(&self, name: &str) -> Result<usize, String> {
        self.state.bodies.iter().position(|b| b.names().contains(&name)).ok_or_else(|| {
            let names: Vec<&str> = self.state.bodies.iter().flat_map(|b| b.names()).collect();
            format!("no body is named `{name}` (bodies: {})", names.join(", "))
        })
    }

    /// After a change of particles: every body binned again (a fluid sorted) and every list
    /// made again.
    fn rebuild(&mut self) {
        self.each(On::All, false, |s, w, i| {
            s.rebin(w, i);
            false
        });
        self.relist(On::All, false);
    }

    /// The fluid bodies.
    pub fn fluids(&self) -> impl Iterator<Item = &Fluid<D>> {
        self.state.bodies.iter().filter_map(Body::as_fluid)
    }

    /// The index of the first fluid body.
    fn first_fluid(&self) -> Option<usize> {
        self.state.bodies.iter().position(|b| b.as_fluid().is_some())
    }

    /// The first fluid (all its parts). Panics for a simulation without one.
    pub fn fluid(&self) -> &Fluid<D> {
        self.fluids().next().expect("a simulation with a fluid")
    }

    /// The first fluid's rates. Panics for a simulation without a fluid.
    pub fn fluid_rates(&self) -> &FluidRates<D> {
        let f = self.first_fluid().expect("a simulation with a fluid");
        self.state.rates[f].as_fluid().expect("a fluid's rates")
    }

    /// Whether the simulation has a fluid body.
    pub fn has_fluid(&self) -> bool {
        self.first_fluid().is_some()
    }

    /// The elastic solids, in the order of the bodies.
    pub fn solids(&self) -> impl Iterator<Item = &ElasticSolid<D>> {
        self.state.bodies.iter().filter_map(Body::as_solid)
    }

    /// The solid body named `name`, with its rates.
    pub fn solid(&self, name: &str) -> Option<(&ElasticSolid<D>, &SolidRates<D>)> {
        let k = self.state.bodies.iter().position(|b| b.as_solid().is_some_and(|s| s.name == name))?;
        Some((self.state.bodies[k].as_solid()?, self.state.rates[k].as_solid()?))
    }

    /// The free surface of the solid named `name`, if its scheme detects one (after the
    /// first evaluation).
    pub fn solid_surface(&self, name: &str) -> Option<&SurfaceFields<D>> {
        let k = self.state.bodies.iter().position(|b| b.as_solid().is_some_and(|s| s.name == name))?;
        self.work[k].as_solid()?.passes.surface.as_ref()
    }

    /// The bodies, in order.
    pub fn bodies(&self) -> &[Body<D>] {
        &self.state.bodies
    }

    /// The couplings, in order.
    pub fn couplings(&self) -> &[Coupling<D>] {
        &self.couplings
    }

    /// The walls, in the order of the bodies.
    pub fn walls(&self) -> impl Iterator<Item = &Wall<D>> {
        self.state.bodies.iter().filter_map(Body::as_wall)
    }

    /// The first fluid's free surface, if its scheme detects one (after the first
    /// evaluation).
    pub fn surface(&self) -> Option<&SurfaceFields<D>> {
        self.work[self.first_fluid()?].as_fluid()?.surface.as_ref()
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

    /// Steps of this simulation (since it was built) whose listing and passes ran as a
    /// wavefront over tiles.
    pub fn wavefront_steps(&self) -> u64 {
        self.work.iter().filter_map(Work::as_fluid).map(|w| w.wavefront_steps).sum()
    }

    /// How the last step's gather passes ran: sweeps or a wavefront (never
    /// [`Schedule::Tuned`]).
    pub fn last_schedule(&self) -> Schedule {
        self.work
            .iter()
            .filter_map(Work::as_fluid)
            .map(|w| w.last_schedule)
            .next()
            .unwrap_or(Schedule::Sweeps)
    }

    /// How the step's gather passes are ordered ([`Schedule`]; by default the faster of the
    /// sweeps and the wavefront on this host). Every schedule gives the same results, bit
    /// for bit.
    pub fn set_schedule(&mut self, schedule: Schedule) {
        for w in self.work.iter_mut().filter_map(Work::as_fluid_mut) {
            w.schedule = schedule;
        }
    }

    /// Each fluid particle's shifting speed in the coming step, |u~ - u| = dt_c/2 |(du/dt)_c|
    /// (eq. 55, dt_c the step the shifting was scaled for, or the nominal step of eq. 61):
    /// how fast the shifting moves it relative to the flow; `None` without a transport
    /// velocity. (The stored u~ is of the last half step and u of the full step, so their
    /// difference also holds dt/2 du/dt.) Of the first fluid.
    pub fn shift_speeds(&self) -> Option<Vec<f64>> {
        self.fluid().u_hat.as_ref()?;
        let rates = self.fluid_rates();
        let half_dt = 0.5 * rates.a_c_dt.unwrap_or_else(|| self.nominal_dt());
        Some(rates.a_c.iter().map(|a| half_dt * a.norm()).collect())
    }

    /// The time step of eq. (61): the smallest of the bodies' limits at the current largest
    /// speed (a structure in the fluid's as its [`Substeps`] say).
    pub fn nominal_dt(&self) -> f64 {
        self.step_sizes().0
    }

    /// The step of eq. (61) and the number of steps the bodies on their own clock take in
    /// it: the smallest limit of the other bodies, and [`Substeps`] from theirs.
    pub fn step_sizes(&self) -> (f64, u32) {
        let (cfl, u_max) = (self.time_settings.cfl, self.state.u_max);
        let limit = |clock: Clock| {
            let bodies = self.state.bodies.iter().zip(&self.clocks);
            let limits = bodies.filter(|(_, &c)| c == clock).filter_map(|(b, _)| b.dt_limit(cfl, u_max));
            limits.fold(f64::INFINITY, f64::min)
        };
        let (others, own) = (limit(Clock::Main), limit(Clock::Own));
        if own == f64::INFINITY {
            return (others, 1);
        }
        match self.time_settings.solid_substeps {
            Substeps::Auto => (others, (others / own).ceil().max(1.0) as u32),
            Substeps::Fixed(n) => (others.min(n as f64 * own), n.max(1)),
        }
    }

    /// The opening (`open`) or closing half kick of every body on `clock` over `dt`.
    fn kick(&mut self, clock: Clock, open: bool, dt: f64) {
        let State { bodies, rates, .. } = &mut self.state;
        for ((body, rates), _) in
            bodies.iter_mut().zip(rates.iter()).zip(&self.clocks).filter(|b| *b.1 == clock)
        {
            if open {
                body.kick_open(rates, dt);
            } else {
                body.kick_close(rates, dt);
            }
        }
    }

    /// The drift of every body on `clock` over `dt`.
    fn drift(&mut self, clock: Clock, dt: f64) {
        for (body, _) in self.state.bodies.iter_mut().zip(&self.clocks).filter(|b| *b.1 == clock) {
            body.drift(dt);
        }
    }

    /// The rates of the bodies on `clock` at the start positions, and their update over
    /// `dt`.
    fn start_rates(&mut self, clock: Clock, local: bool, dt: f64) {
        let on = On::Clock(clock);
        self.each(on, local, |s, w, i| {
            s.gather(w, i);
            false
        });
        self.each(on, local, |s, w, i| {
            s.start_rates(w, i, dt);
            false
        });
        self.each(on, local, |s, w, i| {
            s.start_update(w, i, dt);
            false
        });
    }

    /// One kick-drift-kick step of at most `max_dt` (eqs. 54-60), in the stages of the
    /// module's documentation.
    pub fn step(&mut self, max_dt: f64) -> Result<(), Divergence> {
        let step_clock = std::time::Instant::now();
        let clock = step_clock;
        let (dt_nominal, substeps) = self.step_sizes();
        let dt = dt_nominal.min(max_dt);
        let next_step = self.state.steps + 1;
        self.kick(Clock::Main, true, dt);
        let clock = lap(clock, &mut self.times.integrate);
        self.start_rates(Clock::Main, false, dt);
        self.drift(Clock::Main, dt);
        self.substeps(dt, substeps, next_step);
        let clock = lap(clock, &mut self.times.integrate);
        self.each(On::All, false, |s, w, i| {
            s.rebin(w, i);
            false
        });
        lap(clock, &mut self.times.neighbours);
        // The listing and the passes, for the next step (its kick applies the
        // homogenisation acceleration): tile by tile for a fluid alone that takes it, else
        // stage by stage.
        let fused = self.state.bodies.len() == 1
            && self.each(On::All, false, |s, w, i| s.fused(w, i, dt, dt_nominal));
        if fused {
            self.homogenise(Clock::Main, false, dt_nominal, next_step);
        } else {
            self.relist(On::All, false);
            self.evaluate(dt, false);
            self.accelerate(Clock::Main, false, dt_nominal, next_step);
        }
        self.exchange(Some(dt));
        let clock = std::time::Instant::now();
        self.kick(Clock::Main, false, dt);
        self.state.time += dt;
        self.state.steps += 1;
        let result = self.check();
        lap(clock, &mut self.times.integrate);
        let seconds = step_clock.elapsed().as_secs_f64();
        for (body, work) in self.state.bodies.iter().zip(&mut self.work) {
            body.stages().timed(work, seconds);
        }
        result
    }

    /// The `n` steps of `dt / n` of the bodies on their own clock within a step `dt`, each
    /// a kick-drift-kick of their own (sec. 3.7), the forces held from the main clock.
    fn substeps(&mut self, dt: f64, n: u32, next_step: u64) {
        if !self.clocks.contains(&Clock::Own) {
            return;
        }
        let dt_s = dt / n as f64;
        // In a box around each body over the step (see `local_bins`), unless the domain is
        // periodic or there is a single sub-step.
        let local = n > 1 && !self.domain.periodic.iter().any(|&p| p);
        if local {
            for (k, body) in
                self.state.bodies.iter().enumerate().filter(|(k, _)| self.clocks[*k] == Clock::Own)
            {
                let radius = self.bins[k].radius();
                self.local_bins[k].reshape(box_around(body.x(), radius), radius);
            }
        }
        for _ in 0..n {
            self.kick(Clock::Own, true, dt_s);
            self.start_rates(Clock::Own, local, dt_s);
            self.drift(Clock::Own, dt_s);
            self.each(On::Clock(Clock::Own), local, |s, w, i| {
                s.rebin(w, i);
                false
            });
            self.relist(On::Clock(Clock::Own), local);
            self.accelerate(Clock::Own, local, dt_s, next_step);
            self.kick(Clock::Own, false, dt_s);
        }
    }

    /// Steps until the time reaches `t_stop` (without shortening steps for it, so output
    /// times never change the solution), shortening only the step that would pass `t_end`,
    /// or until `on_step` (called after every step) returns false. Returns whether `t_stop`
    /// was reached. (The loop is [`step_until`]'s.)
    pub fn advance(
        &mut self,
        t_stop: f64,
        t_end: f64,
        mut on_step: impl FnMut(&Self) -> bool,
    ) -> Result<bool, Divergence> {
        step_until(self, |s| s, (t_stop, t_end), |s| on_step(s))
    }

    /// Largest fluid particle speed (0 without a fluid).
    pub fn max_speed(&self) -> f64 {
        self.fluids()
            .map(|f| {
                f.u.par_iter()
                    .with_min_len(LIGHT_LOOP_LEN)
                    .map(|u| u.norm_squared())
                    .reduce(|| 0.0, f64::max)
                    .sqrt()
            })
            .fold(0.0, f64::max)
    }

    /// Blow-up detection of every body; also records the largest fluid speed for the next
    /// time step.
    fn check(&mut self) -> Result<(), Divergence> {
        let fail = |reason: String| Divergence { reason, step: self.state.steps, time: self.state.time };
        let mut u_max: Option<f64> = None;
        let blowup = self.time_settings.blowup_factor;
        for &k in &self.check_order {
            let body = &self.state.bodies[k];
            match body.stages().check(body, &self.domain, blowup) {
                Err(reason) => return Err(fail(reason)),
                Ok(Some(u)) => u_max = Some(u_max.map_or(u, |m| m.max(u))),
                Ok(None) => {}
            }
        }
        if let Some(u) = u_max {
            self.state.u_max = u;
        }
        Ok(())
    }

    /// The first fluid's positions, wrapped into the box, for output.
    pub fn positions(&self) -> &[Vector<D>] {
        &self.fluid().x
    }
}

/// The stepping loop of every run: steps the simulation `sim(owner)` until its time reaches
/// `t_stop` (without shortening steps for it, so output times never change the solution),
/// shortening only the step that would pass `t_end`, and calls `after_step(owner)` after every
/// step, until it returns false (a scene following its probes at every step passes itself as
/// `owner`). Returns whether `t_stop` was reached. The pool's workers are kept warm while it
/// steps ([`keep_warm`](crate::solver::schedule::warm::keep_warm)): a loop of its own would
/// wake them at every parallel pass.
pub fn step_until<S, const D: usize>(
    owner: &mut S,
    sim: fn(&mut S) -> &mut Simulation<D>,
    (t_stop, t_end): (f64, f64),
    mut after_step: impl FnMut(&mut S) -> bool,
) -> Result<bool, Divergence> {
    let eps = 1e-12 * t_end.abs().max(1.0);
    crate::solver::schedule::warm::keep_warm(|| loop {
        let s = sim(owner);
        let remaining = t_end - s.state.time;
        if s.state.time >= t_stop - eps || remaining <= eps {
            return Ok(true);
        }
        s.step(remaining)?;
        if !after_step(owner) {
            return Ok(false);
        }
    })
}

/// A box of margin four radii around the points `x`: a body's binning within one step, over
/// which it moves far less (points that did leave the box would be binned in its edge
/// cells, still found).
fn box_around<const D: usize>(x: &[Vector<D>], radius: f64) -> Domain<D> {
    let (mut lo, mut hi) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
    for p in x {
        for k in 0..D {
            (lo[k], hi[k]) = (lo[k].min(p[k] - 4.0 * radius), hi[k].max(p[k] + 4.0 * radius));
        }
    }
    Domain::bounded(lo, hi)
}

impl<const D: usize> From<Fluid<D>> for Body<D> {
    fn from(f: Fluid<D>) -> Self {
        Body::Fluid(f)
    }
}

impl<const D: usize> From<ElasticSolid<D>> for Body<D> {
    fn from(s: ElasticSolid<D>) -> Self {
        Body::ElasticSolid(s)
    }
}

impl<const D: usize> From<Wall<D>> for Body<D> {
    fn from(w: Wall<D>) -> Self {
        Body::Wall(w)
    }
}

#[cfg(test)]
mod tests;
