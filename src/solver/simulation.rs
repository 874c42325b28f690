//! A simulation: a domain, a list of named bodies, who acts on whom, and the
//! kick-drift-kick loop as an ordered list of stages.
//!
//! A step is PySPH's groups: each stage completes over every body before the next starts.
//!
//! 1. the opening half kick of every body (eqs. 54-55; a wall's prescribed motion);
//! 2. (with [`RatePositions::Start`]) the fluid's density and pressure rates and their
//!    update at the start positions;
//! 3. the drift of every body (eq. 59), and the moved bodies binned again;
//! 4. the neighbour lists of every interacting pair, the boundaries' extrapolation
//!    (eqs. 46-52), the summation density, the density and pressure rates and update
//!    (eqs. 25-26, 56-57), the extrapolation again, the free surface (sec. 3.4) and the
//!    accelerations (eq. 27): as sweeps over each body, or, for a scene of one fluid body,
//!    as a wavefront over tiles ([`Schedule`]);
//! 5. IPST (eqs. 37-41);
//! 6. the closing half kick of every body (eq. 60), and the blow-up check.
//!
//! An elastic solid follows sec. 3.7 in the same stages: after the opening kick its density,
//! pressure and deviatoric stress are updated by rates taken at the start positions with
//! the half-step velocities (eqs. 25, 32, 56, 8, 58); after the drift it is listed again and
//! its accelerations (eq. 30) and shifting (eq. 36) evaluated for the closing kick. A scene
//! without a solid runs none of this; one without a fluid runs none of the fluid's stages.
//!
//! The time step is the smallest of the bodies' limits (eqs. 61, 62).
//!
//! **A structure in a fluid** (an elastic solid the fluid reads as a boundary, thesis ch. 4)
//! steps on its own clock: its sound speed is often far above the fluid's, so within each
//! fluid step of `dt` it takes [`Substeps`] steps of `dt / n`, each a whole kick-drift-kick
//! of its own, with the fluid's force on it (eq. 4.15) held at the value of the last
//! evaluation. After the fluid's passes have evaluated the new force, a half kick of
//! `dt / 2` times the change brings the structure's impulse over the step to
//! `dt / 2 (F_old + F_new)`, exactly what the fluid's two half kicks take from it: momentum
//! crosses the interface without loss, whatever `n`.

use crate::solver::integrator::RatePositions;
use crate::solver::interactions::boundary_fluid::BoundaryFluid;
use crate::solver::interactions::fluid_boundary::{Boundaries, FluidBoundary};
use crate::solver::interactions::fluid_fluid::AccelTerms;
use crate::solver::interactions::fluid_fluid::FluidFluid;
use crate::solver::interactions::solid_solid::SolidSolid;
use crate::solver::interactions::structure_fluid::StructureFluid;
use crate::solver::interactions::{interaction, Interaction};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Domain};
use crate::solver::passes::free_surface::SurfaceFields;
use crate::solver::passes::ipst::{ipst_chi_reference, Ipst, Shifted, Volumes};
use crate::solver::passes::solid::SolidPasses;
use crate::solver::passes::{accelerations, density, rates, solid, FluidPasses, Particles};
use crate::solver::schedule::wavefront::applies as wavefront_applies;
use crate::solver::schedule::{warm, StepBodies, Tuner, Wavefront};
pub use crate::solver::schedule::{Schedule, TUNING_STEPS};
use crate::solver::scheme::{DensityModel, PressureModel, Shifting, SurfacePressure};
use crate::solver::systems::{Body, ElasticSolid, Fluid, FluidRates, Rates, SolidRates, Wall};
use crate::solver::LIGHT_LOOP_LEN;
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
    /// A speed above `blowup_factor` times a fluid's speed of sound counts as a blow-up, so
    /// that a run that grows without turning NaN still stops ([`BLOWUP_MACH`] in every
    /// scene).
    pub blowup_factor: f64,
    /// Where the density and pressure rates are evaluated.
    #[serde(default)]
    pub rate_positions: RatePositions,
    /// How many steps a structure in a fluid takes per step of the fluid.
    #[serde(default)]
    pub solid_substeps: Substeps,
}

/// How many steps a structure in a fluid takes per step of the fluid (see the module's
/// documentation). A solid no fluid meets steps with the fluid, at the smallest limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Substeps {
    /// As many as the two time-step limits ask: `ceil(fluid's limit / structure's limit)`,
    /// the fluid at its own limit.
    #[default]
    Auto,
    /// This many (at least one): the fluid's step is its own limit or `n` times the
    /// structure's, whichever is shorter. With one, both step together at the smaller
    /// limit: the run without sub-steps.
    Fixed(u32),
}

impl TimeSettings {
    /// The settings of a scene: eq. (61)'s factor; blow-ups at [`BLOWUP_MACH`]; the rates at
    /// the default [`RatePositions`].
    pub fn new(cfl: f64) -> Self {
        Self {
            cfl,
            blowup_factor: BLOWUP_MACH,
            rate_positions: RatePositions::default(),
            solid_substeps: Substeps::default(),
        }
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

/// Wall-clock seconds spent in each phase of the step, summed over the run (a few clock
/// reads per step; reported by `sphrepro bench`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct PhaseTimes {
    /// Kicks, drift and the blow-up check.
    pub integrate: f64,
    /// Wrapping, binning, reordering and the neighbour lists with their kernel values (and
    /// the fluid's share of a summation density, summed as the list is built).
    pub neighbours: f64,
    /// Summation density: the boundaries' share.
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

/// The interactions of a simulation's bodies, as [`interaction`] decides them, each with
/// its neighbour lists.
#[derive(Debug)]
struct Couplings<const D: usize> {
    /// The fluid among itself.
    fluid_fluid: FluidFluid<D>,
    /// The fluid reading each boundary, in the order of the bodies.
    fluid_boundary: Vec<FluidBoundary<D>>,
    /// Each boundary extrapolating from the fluid.
    boundary_fluid: Vec<BoundaryFluid<D>>,
    /// Each elastic solid among itself, with its passes' work space.
    solids: Vec<(SolidSolid<D>, SolidPasses<D>)>,
    /// Each structure (an elastic solid the fluid meets) with the fluid.
    structures: Vec<StructureFluid<D>>,
    /// Per body: whether it is a structure in the fluid (stepped on its own clock).
    in_fluid: Vec<bool>,
}

/// What a fluid's passes keep from step to step: the gathered views, IPST's work space,
/// the free surface.
#[derive(Debug, Default)]
struct FluidWork<const D: usize> {
    passes: FluidPasses<D>,
    ipst: Ipst<D>,
    surface: Option<SurfaceFields<D>>,
}

/// How a simulation is put together ([`Simulation::builder`]).
pub struct Builder<const D: usize> {
    domain: Domain<D>,
    kernel: Kernel,
    bodies: Vec<Body<D>>,
    without: Vec<(String, String)>,
    time: TimeSettings,
}

impl<const D: usize> Builder<D> {
    /// Adds a body. Fluid bodies of the same physics become parts of one fluid
    /// ([`Fluid::merge`]), in the order they are added.
    pub fn body(mut self, body: impl Into<Body<D>>) -> Self {
        self.bodies.push(body.into());
        self
    }

    /// Switches the interaction of the bodies named `a` and `b` off, both ways: neither
    /// acts on the other.
    pub fn without(mut self, a: &str, b: &str) -> Self {
        self.without.push((a.into(), b.into()));
        self
    }

    /// The time loop's settings (by default those of [`TimeSettings::new`] at `cfl` 0.25).
    pub fn time(mut self, time: TimeSettings) -> Self {
        self.time = time;
        self
    }

    /// Builds the simulation: merges the fluids, decides the interactions, bins and lists
    /// the particles (the fluid's sorted by cell), and evaluates the initial rates. Errors
    /// name the body or the setting at fault.
    pub fn build(self) -> Result<Simulation<D>, String> {
        let Self { domain, kernel, bodies: given, without, time } = self;
        let mut bodies: Vec<Body<D>> = Vec::with_capacity(given.len());
        let mut fluid: Option<usize> = None;
        for body in given {
            match (body, fluid) {
                (Body::Fluid(more), Some(f)) => {
                    bodies[f].as_fluid_mut().expect("the fluid's index").merge(more)?;
                }
                (body, _) => {
                    if matches!(body, Body::Fluid(_)) {
                        fluid = Some(bodies.len());
                    }
                    bodies.push(body);
                }
            }
        }
        if fluid.is_none() && !bodies.iter().any(|b| matches!(b, Body::ElasticSolid(_))) {
            return Err("a simulation needs a fluid or a solid body".into());
        }
        let names: Vec<&str> = bodies.iter().flat_map(|b| b.names()).collect();
        for (k, name) in names.iter().enumerate() {
            if names[..k].contains(name) {
                return Err(format!("two bodies are named `{name}`"));
            }
        }
        let index_of = |name: &str| {
            bodies
                .iter()
                .position(|b| b.names().contains(&name))
                .ok_or_else(|| format!("no body is named `{name}` (bodies: {})", names.join(", ")))
        };
        let mut off = Vec::new();
        for (a, b) in &without {
            let (i, j) = (index_of(a)?, index_of(b)?);
            if i == j {
                return Err(format!("bodies `{a}` and `{b}` are one body: its particles always interact"));
            }
            off.extend([(i, j), (j, i)]);
        }
        // One exhaustive decision per ordered pair of bodies.
        let mut fluid_boundary = Vec::new();
        let mut boundary_fluid = Vec::new();
        let mut solids = Vec::new();
        let mut structures = Vec::new();
        for (i, dst) in bodies.iter().enumerate() {
            for (j, src) in bodies.iter().enumerate() {
                if off.contains(&(i, j)) {
                    continue;
                }
                match interaction(dst.kind(), src.kind()) {
                    // Within the one fluid: its own list.
                    Some(Interaction::FluidFluid) => debug_assert_eq!(i, j, "one fluid"),
                    Some(Interaction::FluidBoundary) => fluid_boundary.push(FluidBoundary::new(i, j)),
                    Some(Interaction::BoundaryFluid) => boundary_fluid.push(BoundaryFluid::new(i, j)),
                    // A solid with itself; two solid bodies do not meet yet (no contact).
                    Some(Interaction::SolidSolid) if i == j => {
                        solids.push((SolidSolid::new(i), SolidPasses::default()))
                    }
                    Some(Interaction::StructureFluid) => structures.push(StructureFluid::new(i, j)),
                    Some(Interaction::SolidSolid) | None => {}
                }
            }
        }
        if let Some(c) = fluid_boundary.iter().find(|c| bodies[c.boundary].as_boundary().is_none()) {
            return Err(format!(
                "solid `{}` meets the fluid but presents nothing to it: give it the fluid's boundary model (`ElasticSolid::facing_fluid`), or keep them apart (`without`)",
                bodies[c.boundary].names()[0]
            ));
        }
        let mut in_fluid = vec![false; bodies.len()];
        for c in &structures {
            in_fluid[c.structure] = true;
        }
        // The search radius of the fluid's kernel, or of the widest solid's without a fluid
        // (or with a wider solid).
        let mut radius: f64 = 0.0;
        let mut surface = None;
        if let Some(fluid) = fluid {
            let f = bodies[fluid].as_fluid_mut().expect("the fluid's index");
            f.physics.resolve_reference(!fluid_boundary.is_empty());
            radius = kernel.support() * f.h;
            surface = f.physics.free_surface.map(|_| SurfaceFields::default());
        }
        for s in bodies.iter().filter_map(Body::as_solid) {
            radius = radius.max(kernel.support() * s.h);
        }
        domain.check_periodic(radius)?;
        // Each body's cell list spans the box: one far larger than its particles need (a
        // box holding a long prescribed travel, say) would take the memory, or overflow.
        let cells = CellList::<D>::cell_count(&domain, radius);
        let particles: usize = bodies.iter().map(Body::len).sum();
        if cells > 64.0 * particles as f64 + 4e6 {
            return Err(format!(
                "the box from {:?} to {:?} makes {cells:.3e} cells of the search radius {radius:.3e} for {particles} particles: too large a box for its particles",
                domain.min, domain.max
            ));
        }
        let rates = bodies
            .iter()
            .map(|b| match b {
                Body::Fluid(f) => Rates::Fluid(FluidRates::of(f)),
                Body::ElasticSolid(s) => Rates::Solid(SolidRates::of(s)),
                Body::Wall(_) => Rates::None,
            })
            .collect();
        // Every body binned with the fluid's search radius (its particles query them all).
        let bins = bodies
            .iter()
            .map(|b| {
                let mut cells = CellList::new(domain, radius);
                if !matches!(b, Body::Fluid(_)) {
                    cells.update(b.x());
                }
                cells
            })
            .collect();
        let state = State { bodies, rates, time: 0.0, steps: 0, u_max: 0.0, ipst_iterations: 0 };
        let mut sim = Simulation {
            domain,
            kernel,
            time_settings: time,
            state,
            fluid,
            bins,
            couplings: Couplings {
                fluid_fluid: FluidFluid::new(),
                fluid_boundary,
                boundary_fluid,
                solids,
                structures,
                in_fluid,
            },
            work: FluidWork { surface, ..Default::default() },
            wave: Wavefront::new(),
            schedule: Schedule::default(),
            tuners: Vec::new(),
            last_schedule: Schedule::Sweeps,
            wavefront_steps: 0,
            times: PhaseTimes::default(),
        };
        sim.start();
        Ok(sim)
    }
}

/// One simulation: a domain, named bodies (at most one fluid, any number of walls and
/// elastic solids) and who acts on whom, stepped by kick-drift-kick.
pub struct Simulation<const D: usize> {
    /// The box.
    pub domain: Domain<D>,
    /// The smoothing kernel.
    pub kernel: Kernel,
    /// Time-loop settings.
    pub time_settings: TimeSettings,
    /// Everything that evolves.
    pub state: State<D>,
    /// The index of the fluid among the bodies, if there is one.
    fluid: Option<usize>,
    /// Each body's binning, in the order of the bodies (a body that does not move is binned
    /// once).
    bins: Vec<CellList<D>>,
    couplings: Couplings<D>,
    work: FluidWork<D>,
    /// The tiles of the wavefront step, the schedule asked for and its tuner, and the steps
    /// that ran as a wavefront.
    wave: Wavefront,
    schedule: Schedule,
    /// A tuner for each number of threads the run has stepped on: which order is faster
    /// depends on it (`edac` at nx = 200 ran 8-10 % faster in sweeps on two threads and
    /// 1.25-1.3x faster in tiles on one, on one host).
    tuners: Vec<(usize, Tuner)>,
    last_schedule: Schedule,
    wavefront_steps: u64,
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
        Builder { domain, kernel, bodies: Vec::new(), without: Vec::new(), time: TimeSettings::new(0.25) }
    }

    /// Sorts and lists the particles and evaluates the initial rates: IPST's reference
    /// (sec. 3.3.2), the summation density or the state equation's pressure, and the
    /// accelerations for the first half kick (the pressure is the initial one).
    fn start(&mut self) {
        self.rebin();
        self.relist();
        if self.fluid.is_some() {
            self.start_fluid();
        }
        self.start_solids();
        self.structure_reactions(None);
        let (dt, n) = self.step_sizes();
        self.solid_accelerations(false, dt, 0);
        self.solid_accelerations(true, dt / n as f64, 0);
    }

    /// The solids' part of [`start`](Self::start): IPST's reference chi of each solid that
    /// shifts with it, the largest on its initial configuration (a solid always has a free
    /// surface, sec. 3.4).
    fn start_solids(&mut self) {
        for (c, _) in &self.couplings.solids {
            let Body::ElasticSolid(solid) = &mut self.state.bodies[c.body] else { unreachable!("a solid") };
            if let Some(Shifting::Ipst { chi_ref, .. }) = solid.physics.ipst.as_mut() {
                *chi_ref =
                    ipst_chi_reference((&solid.x, solid.h), &c.list, Boundaries::none(), &self.kernel, true);
            }
        }
    }

    /// The fluid's part of [`start`](Self::start).
    fn start_fluid(&mut self) {
        let free_surface = self.fluid().physics.free_surface.is_some();
        let fluid = self.fluid();
        let reference = ipst_chi_reference(
            (&fluid.x, fluid.h),
            &self.couplings.fluid_fluid.list,
            self.boundaries(),
            &self.kernel,
            free_surface,
        );
        let f = self.f();
        let fluid = self.state.bodies[f].as_fluid_mut().expect("the fluid's index");
        if let Some(t) = fluid.physics.transport.as_mut() {
            if let Shifting::Ipst { chi_ref, .. } = &mut t.shifting {
                *chi_ref = reference;
            }
        }
        self.state.u_max = self.max_speed();
        if self.fluid().physics.density == DensityModel::Summation {
            self.summation_density();
        }
        if let PressureModel::StateEquation { .. } = self.fluid().physics.pressure {
            self.density_and_pressure(0.0);
            self.extrapolate();
        }
        let dt = self.nominal_dt();
        self.accelerations(dt);
        self.homogenise(dt, 0);
    }

    /// Replaces the evolving state by a checkpointed one (taken at a step boundary of a
    /// simulation built from the same parameters). The fluid's particles are stored in cell
    /// order, so re-binning them reproduces the neighbour order, and the run continues bit
    /// for bit.
    pub fn restore(&mut self, state: State<D>) {
        self.state = state;
        for (k, body) in self.state.bodies.iter_mut().enumerate() {
            match body {
                Body::Wall(w) => {
                    w.boundary.resize();
                    self.bins[k].update(&w.x);
                }
                Body::ElasticSolid(s) => {
                    if let Some(b) = s.boundary.as_mut() {
                        b.resize();
                    }
                    self.bins[k].update(&s.x)
                }
                Body::Fluid(_) => {}
            }
        }
        if let Some(f) = self.fluid {
            self.bins[f].update(self.state.bodies[f].x());
        }
        self.relist();
    }

    /// The fluid's index; panics for a simulation without one (the fluid's stages run only
    /// when there is one).
    fn f(&self) -> usize {
        self.fluid.expect("a simulation with a fluid")
    }

    /// The fluid (all its parts). Panics for a simulation without a fluid.
    pub fn fluid(&self) -> &Fluid<D> {
        self.state.bodies[self.f()].as_fluid().expect("the fluid's index")
    }

    /// The fluid's rates. Panics for a simulation without a fluid.
    pub fn fluid_rates(&self) -> &FluidRates<D> {
        self.state.rates[self.f()].as_fluid().expect("the fluid's rates")
    }

    /// Whether the simulation has a fluid body.
    pub fn has_fluid(&self) -> bool {
        self.fluid.is_some()
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
        let bodies = &self.state.bodies;
        let (_, passes) = self.couplings.solids.iter().find(|(c, _)| bodies[c.body].names() == [name])?;
        passes.surface.as_ref()
    }

    /// The bodies, in order.
    pub fn bodies(&self) -> &[Body<D>] {
        &self.state.bodies
    }

    /// The walls, in the order of the bodies.
    pub fn walls(&self) -> impl Iterator<Item = &Wall<D>> {
        self.state.bodies.iter().filter_map(Body::as_wall)
    }

    /// The fluid's free surface, if its scheme detects one (after the first evaluation).
    pub fn surface(&self) -> Option<&SurfaceFields<D>> {
        self.work.surface.as_ref()
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

    /// The boundaries the fluid reads.
    fn boundaries(&self) -> Boundaries<'_, D> {
        Boundaries::new(&self.couplings.fluid_boundary, &self.state.bodies)
    }

    /// Wraps the fluid's positions into the box and sorts its particles by cell, and bins
    /// again every other body that moves.
    fn rebin(&mut self) {
        let domain = self.domain;
        for (body, cells) in self.state.bodies.iter_mut().zip(&mut self.bins) {
            match body {
                Body::Fluid(fluid) => {
                    fluid.x.par_iter_mut().with_min_len(LIGHT_LOOP_LEN).for_each(|x| domain.wrap(x));
                    cells.update(&fluid.x);
                    fluid.reorder(cells.order());
                    cells.mark_reordered();
                }
                Body::Wall(wall) if wall.moves() => cells.update(&wall.x),
                Body::Wall(_) => {}
                // A solid keeps its particles in the order given (no reordering).
                Body::ElasticSolid(solid) => {
                    solid.x.iter_mut().for_each(|x| domain.wrap(x));
                    cells.update(&solid.x)
                }
            }
        }
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
    /// picks, where the scene allows a wavefront (one fluid body, a scheme it
    /// [applies](wavefront_applies) to) and the body, as binned now, makes enough tiles for
    /// it; else as sweeps. Also whether the tuner times the step.
    fn order(&mut self) -> (Schedule, bool) {
        let Some(f) = self.fluid else { return (Schedule::Sweeps, false) };
        let fluid = self.fluid();
        let allowed = self.schedule != Schedule::Sweeps
            && self.time_settings.rate_positions == RatePositions::End
            && wavefront_applies(&fluid.physics, self.state.bodies.len() == 1);
        let n = fluid.len();
        let (wave, cells) = (&mut self.wave, &self.bins[f]);
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
        let f = self.f();
        let st = &mut self.state;
        let bodies = StepBodies {
            fluid: st.bodies[f].as_fluid_mut().expect("the fluid's index"),
            cells: &self.bins[f],
            kernel: &self.kernel,
            own: &mut self.couplings.fluid_fluid,
            passes: &mut self.work.passes,
            rates: st.rates[f].as_fluid_mut().expect("the fluid's rates"),
        };
        let t = self.wave.step(bodies, dt, dt_nominal);
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
        if self.fluid().physics.density == DensityModel::Summation {
            self.summation_density();
            clock = lap(clock, &mut self.times.density);
        }
        if self.time_settings.rate_positions == RatePositions::End {
            self.density_and_pressure(dt);
        }
        // The boundaries follow the fluid's new pressure before the accelerations use it.
        self.extrapolate();
        lap(clock, &mut self.times.pressure);
        self.accelerations(dt_nominal);
    }

    /// The neighbour lists of every interacting pair from the current binning, and the
    /// boundaries' extrapolation.
    fn relist(&mut self) {
        let (bodies, bins, kernel) = (&self.state.bodies, &self.bins, &self.kernel);
        for (c, _) in &mut self.couplings.solids {
            c.relist(&bins[c.body], bodies[c.body].as_solid().expect("a solid"), kernel);
        }
        let Some(f) = self.fluid else { return };
        let fluid = bodies[f].as_fluid().expect("the fluid's index");
        self.couplings.fluid_fluid.relist(&bins[f], fluid, kernel);
        for c in &mut self.couplings.fluid_boundary {
            c.relist(&bins[c.boundary], bodies[c.boundary].x(), &fluid.x, fluid.h, kernel);
        }
        for c in &mut self.couplings.boundary_fluid {
            c.relist(&bins[c.fluid], fluid, bodies[c.boundary].x(), kernel);
        }
        for c in &mut self.couplings.structures {
            c.relist(&bins[c.fluid], fluid, bodies[c.structure].x(), kernel);
        }
        self.extrapolate();
    }

    /// Eqs. (46)-(52) on every boundary from the fluid's current state.
    fn extrapolate(&mut self) {
        for c in &self.couplings.boundary_fluid {
            let [boundary, fluid] =
                self.state.bodies.get_disjoint_mut([c.boundary, c.fluid]).expect("a boundary and a fluid");
            let fluid = fluid.as_fluid().expect("a boundary extrapolates from a fluid");
            let g = fluid.physics.gravity_vector();
            match boundary {
                Body::Wall(wall) => c.extrapolate(wall, fluid, g),
                Body::Fluid(_) | Body::ElasticSolid(_) => unreachable!("a wall extrapolates here"),
            }
        }
        let State { bodies, rates, .. } = &mut self.state;
        for c in &self.couplings.structures {
            let [structure, fluid] =
                bodies.get_disjoint_mut([c.structure, c.fluid]).expect("a structure and a fluid");
            let fluid = fluid.as_fluid().expect("a structure extrapolates from a fluid");
            // Eq. (4.14) takes the structure's acceleration: its last du/dt.
            let a = &rates[c.structure].as_solid().expect("a structure's rates").du;
            match structure {
                Body::ElasticSolid(solid) => c.extrapolate(solid, fluid, a, fluid.physics.gravity_vector()),
                Body::Fluid(_) | Body::Wall(_) => unreachable!("a structure is an elastic solid"),
            }
        }
    }

    /// The fluid's summation density: its own share, summed as its list was built, and
    /// each boundary's.
    fn summation_density(&mut self) {
        let f = self.f();
        // Out of the body while the boundaries, among the bodies, are read (a move, no copy).
        let mut rho = std::mem::take(&mut self.state.bodies[f].as_fluid_mut().expect("the fluid").rho);
        let boundaries = Boundaries::new(&self.couplings.fluid_boundary, &self.state.bodies);
        let own = &self.couplings.fluid_fluid.density;
        density::summation_density(&mut rho, self.state.bodies[f].x(), own, boundaries);
        self.state.bodies[f].as_fluid_mut().expect("the fluid").rho = rho;
    }

    /// Each fluid particle's shifting speed in the coming step, |u~ - u| = dt_c/2 |(du/dt)_c|
    /// (eq. 55, dt_c the step the shifting was scaled for, or the nominal step of eq. 61):
    /// how fast the shifting moves it relative to the flow; `None` without a transport
    /// velocity. (The stored u~ is of the last half step and u of the full step, so their
    /// difference also holds dt/2 du/dt.)
    pub fn shift_speeds(&self) -> Option<Vec<f64>> {
        self.fluid?;
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

    /// The step of eq. (61) and the number of steps a structure in the fluid takes in it:
    /// the smallest limit of the other bodies, and [`Substeps`] from the structures'.
    pub fn step_sizes(&self) -> (f64, u32) {
        let (cfl, u_max) = (self.time_settings.cfl, self.state.u_max);
        let limit = |structures: bool| {
            let bodies = self.state.bodies.iter().zip(&self.couplings.in_fluid);
            let limits = bodies.filter(|(_, &s)| s == structures).filter_map(|(b, _)| b.dt_limit(cfl, u_max));
            limits.fold(f64::INFINITY, f64::min)
        };
        let (others, structures) = (limit(false), limit(true));
        if structures == f64::INFINITY {
            return (others, 1);
        }
        match self.time_settings.solid_substeps {
            Substeps::Auto => (others, (others / structures).ceil().max(1.0) as u32),
            Substeps::Fixed(n) => (others.min(n as f64 * structures), n.max(1)),
        }
    }

    /// The free surface, if declared, and pass B.
    fn accelerations(&mut self, dt_nominal: f64) {
        let clock = std::time::Instant::now();
        let f = self.f();
        let free = self.fluid().physics.free_surface;
        if let (Some(fs), Some(free)) = (self.work.surface.as_mut(), free) {
            let fluid = self.state.bodies[f].as_fluid().expect("the fluid");
            let boundaries = Boundaries::new(&self.couplings.fluid_boundary, &self.state.bodies);
            let nl = &self.couplings.fluid_fluid.list;
            fs.detect(Particles::of(fluid), nl, boundaries, free.rho0, free.cone);
            let fluid = self.state.bodies[f].as_fluid_mut().expect("the fluid");
            fs.apply_surface_pressure(free.pressure, free.rho0, &mut fluid.p);
            if free.pressure != SurfacePressure::Evolve {
                // The boundaries' pressure (eqs. 46-52) sums the fluid's, so it follows the
                // surface pressures just set: a wall under a splash's front sees p = 0 there.
                self.extrapolate();
            }
        }
        let st = &mut self.state;
        let fluid = st.bodies[f].as_fluid().expect("the fluid");
        let boundaries = Boundaries::new(&self.couplings.fluid_boundary, &st.bodies);
        let rates = st.rates[f].as_fluid_mut().expect("the fluid's rates");
        accelerations::accelerations(
            &mut self.work.passes,
            fluid,
            &self.couplings.fluid_fluid.list,
            boundaries,
            self.work.surface.as_ref(),
            rates,
            dt_nominal,
        );
        lap(clock, &mut self.times.accelerations);
    }

    /// IPST's pass (eqs. 37-41), if the fluid shifts with it, after pass B.
    fn homogenise(&mut self, dt_nominal: f64, next_step: u64) {
        let clock = std::time::Instant::now();
        let f = self.f();
        let st = &mut self.state;
        let fluid = st.bodies[f].as_fluid().expect("the fluid");
        let rates = st.rates[f].as_fluid_mut().expect("the fluid's rates");
        let body = Shifted {
            x: &fluid.x,
            // The views pass B gathered at these positions: IPST reads their volumes.
            vol: Volumes::Points(&self.work.passes.points),
            h: fluid.h,
            nl: &self.couplings.fluid_fluid.list,
            cells: &self.bins[f],
            boundaries: Boundaries::new(&self.couplings.fluid_boundary, &st.bodies),
        };
        let shifting = fluid.physics.transport.map(|t| t.shifting);
        st.ipst_iterations = self.work.ipst.run(
            body,
            self.work.surface.as_ref(),
            &self.kernel,
            shifting,
            &mut rates.a_c,
            dt_nominal,
            next_step,
        );
        lap(clock, &mut self.times.ipst);
    }

    /// Pass A: the density and pressure rates (eqs. 25-26) on the current neighbour lists
    /// and boundaries, and their updates over `dt` (eqs. 56-57).
    fn density_and_pressure(&mut self, dt: f64) {
        let f = self.f();
        let st = &mut self.state;
        let fluid = st.bodies[f].as_fluid().expect("the fluid");
        let boundaries = Boundaries::new(&self.couplings.fluid_boundary, &st.bodies);
        let r = st.rates[f].as_fluid_mut().expect("the fluid's rates");
        rates::density_and_pressure_rates(
            &mut self.work.passes,
            fluid,
            &self.couplings.fluid_fluid.list,
            boundaries,
            r,
        );
        let fluid = st.bodies[f].as_fluid_mut().expect("the fluid");
        rates::update_density_and_pressure(fluid, st.rates[f].as_fluid().expect("the fluid's rates"), dt);
    }

    /// One kick-drift-kick step of at most `max_dt` (eqs. 54-60), in the stages of the
    /// module's documentation.
    pub fn step(&mut self, max_dt: f64) -> Result<(), Divergence> {
        let step_clock = std::time::Instant::now();
        let clock = step_clock;
        let (dt_nominal, substeps) = self.step_sizes();
        let dt = dt_nominal.min(max_dt);
        let rates_at = self.time_settings.rate_positions;
        let own_clock = &self.couplings.in_fluid;
        for ((body, rates), _) in
            self.state.bodies.iter_mut().zip(&self.state.rates).zip(own_clock).filter(|b| !b.1)
        {
            body.kick_open(rates, dt);
        }
        let mut clock = lap(clock, &mut self.times.integrate);
        if rates_at == RatePositions::Start && self.fluid.is_some() {
            // The neighbour lists and the boundaries are still those of the start positions.
            self.density_and_pressure(dt);
            clock = lap(clock, &mut self.times.pressure);
        }
        // Sec. 3.7: a solid's rates at the start positions, its lists still theirs.
        self.solid_rates_and_update(dt);
        for (body, _) in self.state.bodies.iter_mut().zip(&self.couplings.in_fluid).filter(|b| !b.1) {
            body.drift(dt);
        }
        self.step_structures(dt, substeps, self.state.steps + 1);
        let clock = lap(clock, &mut self.times.integrate);
        self.rebin();
        lap(clock, &mut self.times.neighbours);
        // The listing and the passes, for the next step (its kick applies the
        // homogenisation acceleration): tile by tile or pass by pass, as the schedule says.
        let (schedule, timed) = self.order();
        self.last_schedule = schedule;
        if self.fluid.is_none() {
            self.relist();
        } else if schedule == Schedule::Wavefront {
            self.wavefront_passes(dt, dt_nominal);
        } else {
            self.swept_passes(dt, dt_nominal);
        }
        if self.fluid.is_some() {
            self.homogenise(dt_nominal, self.state.steps + 1);
        }
        self.solid_accelerations(false, dt_nominal, self.state.steps + 1);
        self.structure_reactions(Some(dt));
        let clock = std::time::Instant::now();
        let own_clock = &self.couplings.in_fluid;
        for ((body, rates), _) in
            self.state.bodies.iter_mut().zip(&self.state.rates).zip(own_clock).filter(|b| !b.1)
        {
            body.kick_close(rates, dt);
        }
        let st = &mut self.state;
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

    /// Largest fluid particle speed (0 without a fluid).
    pub fn max_speed(&self) -> f64 {
        if self.fluid.is_none() {
            return 0.0;
        }
        self.fluid()
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
        self.check_solids()?;
        if self.fluid.is_none() {
            return Ok(());
        }
        let f = self.fluid();
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
                f.part_of(f.id[bad]),
                f.x[bad].as_slice()
            )));
        }
        let u_max = u2.sqrt();
        let bound = self.time_settings.blowup_factor * f.physics.c0;
        if u_max > bound {
            // Which particle (found only now, on the way out), so that the report says where.
            let fast = (0..f.len()).max_by(|&a, &b| f.u[a].norm_squared().total_cmp(&f.u[b].norm_squared()));
            let fast = fast.expect("a body has particles");
            return Err(fail(format!(
                "max |u| = {u_max:.4e} exceeds {} c0 = {bound:.4e}: the flow has left the weakly compressible model (particle {} of body `{}`, at {:?}, p = {:.4e}, rho = {:.4e})",
                self.time_settings.blowup_factor,
                f.id[fast],
                f.part_of(f.id[fast]),
                f.x[fast].as_slice(),
                f.p[fast],
                f.rho[fast]
            )));
        }
        self.state.u_max = u_max;
        Ok(())
    }

    /// The density, pressure and deviatoric-stress rates of every solid that steps with the
    /// fluid (all but the structures in it) at the current positions and velocities (eqs.
    /// 25, 31, 32), and their update over `dt` (eqs. 56, 8, 58).
    fn solid_rates_and_update(&mut self, dt: f64) {
        let in_fluid = &self.couplings.in_fluid;
        for (c, passes) in self.couplings.solids.iter_mut().filter(|(c, _)| !in_fluid[c.body]) {
            solid_update(c, passes, &mut self.state, dt);
        }
    }

    /// The accelerations (eq. 30, with the fluid's force if any) and shifting (eq. 36 or
    /// IPST's eqs. 37-41, for a step `dt` and step number `next_step`) of every solid in
    /// the fluid (`in_fluid`) or of every other.
    fn solid_accelerations(&mut self, in_fluid: bool, dt: f64, next_step: u64) {
        let of = &self.couplings.in_fluid;
        for (c, passes) in self.couplings.solids.iter_mut().filter(|(c, _)| of[c.body] == in_fluid) {
            solid_passes(c, passes, &mut self.state, (&self.bins[c.body], &self.kernel), dt, next_step);
        }
    }

    /// The `n` steps of `dt / n` of every structure in the fluid within a step `dt` of the
    /// fluid, each a kick-drift-kick of its own (sec. 3.7), with the fluid's force held.
    fn step_structures(&mut self, dt: f64, n: u32, next_step: u64) {
        let dt_s = dt / n as f64;
        let (domain, kernel) = (self.domain, &self.kernel);
        let in_fluid = &self.couplings.in_fluid;
        for (c, passes) in self.couplings.solids.iter_mut().filter(|(c, _)| in_fluid[c.body]) {
            let st = &mut self.state;
            // The sub-steps bin the structure in a box around it, not in the whole domain:
            // binning clears every cell of its grid, and a structure is small in its tank.
            let mut local = (n > 1 && !domain.periodic.iter().any(|&p| p))
                .then(|| structure_cells(st.bodies[c.body].x(), self.bins[c.body].radius()));
            for _ in 0..n {
                st.bodies[c.body].kick_open(&st.rates[c.body], dt_s);
                solid_update(c, passes, st, dt_s);
                let Body::ElasticSolid(solid) = &mut st.bodies[c.body] else { unreachable!("a solid") };
                solid.drift(dt_s);
                solid.x.iter_mut().for_each(|x| domain.wrap(x));
                let cells = local.as_mut().unwrap_or(&mut self.bins[c.body]);
                cells.update(&solid.x);
                c.relist(cells, solid, kernel);
                solid_passes(c, passes, st, (cells, kernel), dt_s, next_step);
                st.bodies[c.body].kick_close(&st.rates[c.body], dt_s);
            }
        }
    }

    /// The fluid's force on every structure (the opposite of eq. 4.15) from the fluid's
    /// pass B just evaluated. Within a step (`kick` = the step), the half kick of `dt / 2`
    /// times its change since the force held over the sub-steps (see the module's
    /// documentation); at the start, the force only.
    fn structure_reactions(&mut self, kick: Option<f64>) {
        let Some(f) = self.fluid else { return };
        let State { bodies, rates, .. } = &mut self.state;
        let fluid = bodies[f].as_fluid().expect("the fluid's index");
        let terms = AccelTerms::new(&fluid.physics);
        let points = (&self.work.passes.points[..], fluid.h);
        let forces: Vec<Vec<Vector<D>>> = (self.couplings.structures.iter())
            .map(|c| {
                let solid = bodies[c.structure].as_solid().expect("a structure is a solid");
                let mut new = vec![Vector::zeros(); solid.len()];
                c.reaction(solid, points, &fluid.x, &terms, &mut new);
                new
            })
            .collect();
        for (c, new) in self.couplings.structures.iter().zip(forces) {
            let r = rates[c.structure].as_solid_mut().expect("a solid's rates");
            if let Some(dt) = kick {
                let Body::ElasticSolid(solid) = &mut bodies[c.structure] else { unreachable!("a solid") };
                for ((u, du), (new, held)) in solid.u.iter_mut().zip(&mut r.du).zip(new.iter().zip(&r.a_fsi))
                {
                    let change = new - held;
                    *u += change * (0.5 * dt);
                    *du += change;
                }
            }
            r.a_fsi = new;
        }
    }

    /// Blow-up detection of the solids: non-finite fields, a particle outside a bounded
    /// domain, a speed beyond `blowup_factor` times the solid's speed of sound.
    fn check_solids(&self) -> Result<(), Divergence> {
        let fail = |reason: String| Divergence { reason, step: self.state.steps, time: self.state.time };
        for s in self.solids() {
            let finite = |i: usize| {
                s.x[i].iter().chain(s.u[i].iter()).chain(s.s[i].iter()).all(|v| v.is_finite())
                    && s.p[i].is_finite()
                    && s.rho[i].is_finite()
            };
            if let Some(i) = (0..s.len()).find(|&i| !finite(i)) {
                return Err(fail(format!("a field is not finite (particle {i} of solid `{}`)", s.name)));
            }
            if let Some(i) = (0..s.len()).find(|&i| !self.domain.contains(&s.x[i])) {
                return Err(fail(format!("particle {i} of solid `{}` left the domain", s.name)));
            }
            let bound = self.time_settings.blowup_factor * s.material.c0();
            if s.max_speed() > bound {
                return Err(fail(format!(
                    "max |u| = {:.4e} of solid `{}` exceeds {} c0 = {bound:.4e}",
                    s.max_speed(),
                    s.name,
                    self.time_settings.blowup_factor
                )));
            }
        }
        Ok(())
    }

    /// The fluid's positions, wrapped into the box, for output.
    pub fn positions(&self) -> &[Vector<D>] {
        &self.fluid().x
    }
}

/// The density, pressure and deviatoric-stress rates of solid `c` at its current positions
/// and velocities (eqs. 25, 31, 32), and their update over `dt` (eqs. 56, 8, 58).
fn solid_update<const D: usize>(c: &SolidSolid<D>, passes: &mut SolidPasses<D>, st: &mut State<D>, dt: f64) {
    let solid = st.bodies[c.body].as_solid().expect("a solid");
    let rates = st.rates[c.body].as_solid_mut().expect("a solid's rates");
    solid::density_and_stress_rates(passes, solid, &c.list, rates);
    let Body::ElasticSolid(solid) = &mut st.bodies[c.body] else { unreachable!("a solid") };
    solid.update_state(st.rates[c.body].as_solid().expect("a solid's rates"), dt);
}

/// Solid `c`'s accelerations (eq. 30) with the fluid's force on it if it is a structure in
/// one (held from its last evaluation), and its shifting for a step `dt` (eq. 36 or IPST's
/// eqs. 37-41), on its lists of now (binned by `cells`).
fn solid_passes<const D: usize>(
    c: &SolidSolid<D>,
    passes: &mut SolidPasses<D>,
    st: &mut State<D>,
    (cells, kernel): (&CellList<D>, &Kernel),
    dt: f64,
    next_step: u64,
) {
    let solid = st.bodies[c.body].as_solid().expect("a solid");
    let rates = st.rates[c.body].as_solid_mut().expect("a solid's rates");
    solid::accelerations(passes, solid, &c.list, rates, dt);
    // Eq. (4.6)'s F_FSI / m (empty for a solid no fluid meets).
    let SolidRates { du, a_fsi, .. } = rates;
    du.iter_mut().zip(a_fsi.iter()).for_each(|(du, a)| *du += a);
    solid::homogenise(passes, solid, &c.list, cells, kernel, rates, dt, next_step);
}

/// A cell list of search radius `radius` over the box around the points `x` with a margin
/// of four radii: a structure's binning within one fluid step, over which it moves far
/// less (points that did leave the box would be binned in its edge cells, still found).
fn structure_cells<const D: usize>(x: &[Vector<D>], radius: f64) -> CellList<D> {
    let (mut lo, mut hi) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
    for p in x {
        for k in 0..D {
            (lo[k], hi[k]) = (lo[k].min(p[k] - 4.0 * radius), hi[k].max(p[k] + 4.0 * radius));
        }
    }
    CellList::new(Domain::bounded(lo, hi), radius)
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
mod tests {
    use super::*;
    use crate::solver::integrator;
    use crate::solver::kernel::KernelKind;
    use crate::solver::scheme::{FluidSettings, Pst, SchemeName, Transport};
    use crate::solver::systems::FluidInit;

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
        let fluid = Fluid::new("fluid", dx, init, scheme.fluid_scheme(&settings)).unwrap();
        let time = TimeSettings { rate_positions: rates_at, ..TimeSettings::new(0.25) };
        Simulation::builder(Domain::periodic([0.0; 2], [1.0; 2]), kernel)
            .body(fluid)
            .time(time)
            .build()
            .unwrap()
    }

    /// A fluid split into two named bodies (its lower and upper halves, each added as a body
    /// of its own) steps as the whole does, bit for bit, on one and two threads: both parts
    /// are one fluid to the passes, so every sum runs over the same neighbours in the same
    /// order. Each part keeps its name and its particles.
    #[test]
    fn a_fluid_split_into_two_bodies_steps_as_one() {
        let whole = vortex_sized(32, SchemeName::Ctvf, Pst::Ipst, RatePositions::End);
        let f = whole.fluid();
        let half = f.len() / 2;
        let init_part = |range: std::ops::Range<usize>| FluidInit {
            x: f.by_id(&f.x)[range.clone()].to_vec(),
            u: f.by_id(&f.u)[range.clone()].to_vec(),
            m: f.by_id(&f.m)[range.clone()].to_vec(),
            rho: vec![1.0; range.len()],
            p: vec![0.0; range.len()],
        };
        let (lower, upper) = (init_part(0..half), init_part(half..f.len()));
        let physics = {
            let mut s = f.physics;
            if let Some(Transport { shifting: Shifting::Ipst { chi_ref, .. }, .. }) = s.transport.as_mut() {
                *chi_ref = f64::NAN;
            }
            s
        };
        let (h, kernel, domain, time) = (f.h, whole.kernel, whole.domain, whole.time_settings);
        let run = |split: bool, threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let builder = Simulation::builder(domain, kernel).time(time);
                let mut sim = if split {
                    builder
                        .body(Fluid::new("lower", h, lower.clone(), physics).unwrap())
                        .body(Fluid::new("upper", h, upper.clone(), physics).unwrap())
                } else {
                    let mut all = lower.clone();
                    for (a, b) in [(&mut all.x, &upper.x), (&mut all.u, &upper.u)] {
                        a.extend_from_slice(b);
                    }
                    all.m.extend_from_slice(&upper.m);
                    all.rho.extend_from_slice(&upper.rho);
                    all.p.extend_from_slice(&upper.p);
                    builder.body(Fluid::new("fluid", h, all, physics).unwrap())
                }
                .build()
                .unwrap();
                for _ in 0..20 {
                    sim.step(f64::INFINITY).unwrap();
                }
                let f = sim.fluid();
                let r = sim.fluid_rates();
                let mut bits: Vec<u64> =
                    [&f.rho, &f.p].iter().flat_map(|v| f.by_id(v)).map(|x| x.to_bits()).collect();
                for v in [&f.x, &f.u, &r.du, &r.a_c] {
                    bits.extend(f.by_id(v).iter().flat_map(|x| x.iter().map(|c| c.to_bits())));
                }
                let parts: Vec<(String, std::ops::Range<u32>)> =
                    f.parts.iter().map(|p| (p.name.clone(), p.ids.clone())).collect();
                (bits, parts)
            })
        };
        let (one, parts_one) = run(false, 1);
        assert_eq!(parts_one, [("fluid".to_string(), 0..1024)]);
        for threads in [1, 2] {
            let (two, parts) = run(true, threads);
            assert!(one == two, "{threads} threads: the split fluid differs from the whole");
            assert_eq!(parts, [("lower".to_string(), 0..512), ("upper".to_string(), 512..1024)]);
        }
    }

    /// Bodies are named once; a pair switched off must name two bodies.
    #[test]
    fn bodies_are_named_once_and_pairs_switched_off_by_name() {
        let sim = vortex(RatePositions::End);
        let f = sim.fluid().clone();
        let builder = || Simulation::builder(sim.domain, sim.kernel);
        let twice = builder().body(f.clone()).body(f.clone()).build().err().unwrap();
        assert_eq!(twice, "two bodies are named `fluid`");
        let unknown = builder().body(f.clone()).without("fluid", "lid").build().err().unwrap();
        assert_eq!(unknown, "no body is named `lid` (bodies: fluid)");
        let itself = builder().body(f).without("fluid", "fluid").build().err().unwrap();
        assert!(itself.contains("are one body"), "{itself}");
        assert_eq!(
            Simulation::<2>::builder(sim.domain, sim.kernel).build().err().unwrap(),
            "a simulation needs a fluid or a solid body"
        );
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
            assert_eq!(sim.fluid_rates().a_c_dt, Some(dt), "{pst:?}: scaled for the nominal step");
            let (f, r) = (sim.fluid().clone(), sim.fluid_rates().clone());
            let short = 0.25 * dt;
            sim.step(short).unwrap();
            let (u, du, ac) = (f.by_id(&f.u), f.by_id(&r.du), f.by_id(&r.a_c));
            let after = sim.fluid();
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
            let (mut probe, mut r) = (sim.fluid().clone(), sim.fluid_rates().clone());
            let Fluid { u, u_hat, .. } = &mut probe;
            integrator::kick_transport(u, u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
            let list = &sim.couplings.fluid_fluid.list;
            rates::density_and_pressure_rates(
                &mut FluidPasses::new(),
                &probe,
                list,
                sim.boundaries(),
                &mut r,
            );
            rates::update_density_and_pressure(&mut probe, &r, dt);
            sim.step(f64::INFINITY).unwrap();
            let bits = |f: &Fluid<2>| f.by_id(&f.p).iter().map(|p| p.to_bits()).collect::<Vec<_>>();
            let same = bits(&probe) == bits(sim.fluid());
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
                let (f, r) = (sim.fluid(), sim.fluid_rates());
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
                    let (f, r) = (sim.fluid(), sim.fluid_rates());
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

    /// A fluid and a free elastic block in a periodic box (no walls, no gravity, schemes
    /// whose own forces are pairwise: no CTVF momentum correction, no reference pressure):
    /// the fluid's force on the block and the block's on the fluid cancel, so the total
    /// momentum stays at its start to round-off over a hundred steps, with the block on
    /// three sub-steps a step and on none.
    #[test]
    fn momentum_crosses_the_fluid_structure_interface_without_loss() {
        use crate::solver::scheme::{Corrections, PressureReference, SolidSchemeName, SolidSettings};
        use crate::solver::systems::{BoundaryMaterial, SolidInit, SolidMaterial};
        for substeps in [Substeps::Fixed(3), Substeps::Fixed(1)] {
            let n = 24;
            let dx = 1.0 / n as f64;
            let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
            let (mut fluid, mut block) = (FluidInit::<2>::default(), SolidInit::<2>::default());
            for j in 0..n {
                for i in 0..n {
                    let x = Vector::<2>::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx);
                    if (9..15).contains(&i) && (9..15).contains(&j) {
                        block.x.push(x);
                        block.u.push(Vector::zeros());
                        block.m.push(dx * dx);
                        block.rho.push(1.0);
                        block.fixed.push(false);
                    } else {
                        let wave = 0.1 * (2.0 * std::f64::consts::PI * x[1]).sin();
                        fluid.x.push(x);
                        fluid.u.push(Vector::<2>::new(0.3 + wave, 0.1));
                        fluid.m.push(dx * dx);
                        fluid.rho.push(1.0);
                        fluid.p.push(0.0);
                    }
                }
            }
            let settings = FluidSettings {
                pst: Pst::Sun,
                corrections: Corrections::NONE,
                pressure_reference: PressureReference::None,
                ..FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01)
            };
            let fluid = Fluid::new("water", dx, fluid, SchemeName::Ctvf.fluid_scheme(&settings)).unwrap();
            let solid_settings = SolidSettings {
                pst: Pst::Sun,
                corrections: true,
                alpha: 1.0,
                u_ref: 1.0,
                w_dx: kernel.w(dx, dx),
                gravity: [0.0; 3],
            };
            let material = SolidMaterial::new(300.0, 0.3, 1.0).unwrap();
            let boundary = BoundaryMaterial {
                rho0: 1.0,
                c0: 10.0,
                density: Default::default(),
                pressure: Default::default(),
                viscosity: Default::default(),
            };
            let physics = SolidSchemeName::Ctvf.solid_scheme(&solid_settings).unwrap();
            let block = ElasticSolid::new("block", dx, block, material, physics)
                .unwrap()
                .facing_fluid(boundary)
                .unwrap();
            let time = TimeSettings { solid_substeps: substeps, ..TimeSettings::new(0.25) };
            let mut sim = Simulation::builder(Domain::periodic([0.0; 2], [1.0; 2]), kernel)
                .body(fluid)
                .body(block)
                .time(time)
                .build()
                .unwrap();
            assert_eq!(
                sim.step_sizes().1,
                match substeps {
                    Substeps::Fixed(n) => n,
                    Substeps::Auto => 0,
                }
            );
            let momentum = |sim: &Simulation<2>| {
                let f = sim.fluid();
                let (s, _) = sim.solid("block").unwrap();
                let p: Vector<2> =
                    f.u.iter().zip(&f.m).chain(s.u.iter().zip(&s.m)).map(|(u, m)| u * *m).sum();
                let scale: f64 =
                    f.u.iter().zip(&f.m).chain(s.u.iter().zip(&s.m)).map(|(u, m)| u.norm() * m).sum();
                (p, scale)
            };
            let (p0, scale) = momentum(&sim);
            for _ in 0..100 {
                sim.step(f64::INFINITY).unwrap();
            }
            let (s, _) = sim.solid("block").unwrap();
            let block_p: Vector<2> = s.u.iter().zip(&s.m).map(|(u, m)| u * *m).sum();
            assert!(
                block_p[0] > 0.05 * p0[0] * 36.0 / 540.0,
                "{substeps:?}: the flow pushes the block: {block_p:?}"
            );
            let (p, _) = momentum(&sim);
            assert!(
                (p - p0).norm() < 1e-13 * scale,
                "{substeps:?}: momentum {p0:?} -> {p:?} (scale {scale})"
            );
        }
    }
}
