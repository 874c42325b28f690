//! How a simulation is put together: its bodies (fluids of one physics merged into one body),
//! what is set for pairs of them, and the couplings the interaction match decides for every
//! ordered pair.

use super::{Clock, Simulation, State, TimeSettings};
use crate::solver::integrator::PhaseTimes;
use crate::solver::interactions::{interactions, Coupling, Interaction, PairParams, SolidPair, UniformLoad};
use crate::solver::kernel::Kernel;
use crate::solver::nnps::{CellList, Domain};
use crate::solver::systems::Body;

/// How a simulation is put together ([`Simulation::builder`]).
pub struct Builder<const D: usize> {
    domain: Domain<D>,
    kernel: Kernel,
    bodies: Vec<Body<D>>,
    /// What is set for pairs of bodies (by name; a body with itself for a load).
    pairs: Vec<(String, String, PairParams)>,
    time: TimeSettings,
}

impl<const D: usize> Builder<D> {
    /// A simulation in `domain` with `kernel`, no body yet.
    pub(super) fn new(domain: Domain<D>, kernel: Kernel) -> Self {
        Self { domain, kernel, bodies: Vec::new(), pairs: Vec::new(), time: TimeSettings::new(0.25) }
    }

    /// Adds a body. A fluid body of the same physics and smoothing length as one added
    /// before becomes a part of it ([`Fluid::merge`](crate::solver::systems::Fluid::merge)),
    /// in the order they are added; a fluid of other physics is a body of its own.
    pub fn body(mut self, body: impl Into<Body<D>>) -> Self {
        self.bodies.push(body.into());
        self
    }

    /// Switches the interaction of the bodies named `a` and `b` off, both ways: neither
    /// acts on the other.
    pub fn without(self, a: &str, b: &str) -> Self {
        self.couple(a, b, PairParams { off: true, ..PairParams::default() })
    }

    /// Sets what the bodies named `a` and `b` are given for their pair (both ways), beside
    /// what their kinds decide: e.g. two solids that sum their continuum equations across
    /// ([`SolidPair::Continuum`]).
    pub fn couple(mut self, a: &str, b: &str, params: PairParams) -> Self {
        self.pairs.push((a.into(), b.into(), params));
        self
    }

    /// Puts `load` on the body named `body` (a coupling of the body with itself).
    pub fn load(self, body: &str, load: UniformLoad) -> Self {
        self.couple(body, body, PairParams { load: Some(load), ..PairParams::default() })
    }

    /// The time loop's settings (by default those of [`TimeSettings::new`] at `cfl` 0.25).
    pub fn time(mut self, time: TimeSettings) -> Self {
        self.time = time;
        self
    }

    /// Builds the simulation: merges the fluids of one physics, decides the couplings of
    /// every ordered pair of bodies, bins and lists the particles (the fluids' sorted by
    /// cell), and evaluates the initial rates. Errors name the body or the setting at fault.
    pub fn build(self) -> Result<Simulation<D>, String> {
        let Self { domain, kernel, bodies: given, pairs, time } = self;
        let bodies = merge_fluids(given)?;
        if !bodies.iter().any(Body::is_integrated) {
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
        // What is set for each unordered pair of bodies.
        let mut set: Vec<((usize, usize), PairParams)> = Vec::new();
        for (a, b, params) in &pairs {
            let (i, j) = (index_of(a)?, index_of(b)?);
            if params.off && i == j {
                return Err(format!("bodies `{a}` and `{b}` are one body: its particles always interact"));
            }
            let key = (i.min(j), i.max(j));
            match set.iter_mut().find(|(k, _)| *k == key) {
                Some((_, p)) => {
                    p.off |= params.off;
                    if params.solids != SolidPair::default() {
                        p.solids = params.solids;
                    }
                    if params.load.is_some() {
                        p.load.clone_from(&params.load);
                    }
                }
                None => set.push((key, params.clone())),
            }
        }
        let default = PairParams::default();
        let params_of = |i: usize, j: usize| {
            set.iter().find(|(k, _)| *k == (i.min(j), i.max(j))).map_or(&default, |(_, p)| p)
        };
        // One exhaustive decision per ordered pair of bodies.
        let mut couplings = Vec::new();
        for (i, dst) in bodies.iter().enumerate() {
            for (j, src) in bodies.iter().enumerate() {
                let pair = params_of(i, j);
                let decided = interactions(dst.kind(), src.kind(), i == j, pair)
                    .map_err(|e| format!("bodies `{}` and `{}`: {e}", dst.name(), src.name()))?;
                couplings.extend(decided.into_iter().map(|x| Coupling::new(x, i, j, pair)));
            }
        }
        check_couplings(&bodies, &couplings)?;
        // A body acted on by a force held from a slower clock steps on its own.
        let mut clocks = vec![Clock::Main; bodies.len()];
        for c in couplings.iter().filter(|c| c.holds_force()) {
            clocks[c.bodies().0] = Clock::Own;
        }
        for c in couplings.iter().filter(|c| c.interaction() == Interaction::SolidContinuum) {
            let (dst, src) = c.bodies();
            if clocks[dst] != clocks[src] {
                return Err(format!(
                    "solids `{}` and `{}` sum their equations across but step on different clocks (one is a structure in a fluid)",
                    bodies[dst].name(),
                    bodies[src].name()
                ));
            }
        }
        let mut bodies = bodies;
        for (k, body) in bodies.iter_mut().enumerate() {
            if let Body::Fluid(f) = body {
                let walled = couplings
                    .iter()
                    .any(|c| c.interaction() == Interaction::FluidBoundary && c.bodies().0 == k);
                f.physics.resolve_reference(walled);
            }
        }
        // The search radius: the widest kernel of a body that sums over neighbours.
        let radius = bodies.iter().filter_map(Body::h).map(|h| kernel.support() * h).fold(0.0, f64::max);
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
        let rates = bodies.iter().map(Body::zero_rates).collect();
        // Every body binned with the widest search radius (its neighbours query them all).
        let bins = bodies
            .iter()
            .map(|b| {
                let mut cells = CellList::new(domain, radius);
                cells.update(b.x());
                cells
            })
            .collect();
        // The sub-steps' binning, made over the box around a body when it steps.
        let local_bins =
            bodies.iter().map(|b| CellList::new(super::box_around(&b.x()[..1], radius), radius)).collect();
        let work = (0..bodies.len())
            .map(|k| {
                let incoming: Vec<usize> =
                    (0..couplings.len()).filter(|&c| couplings[c].bodies().0 == k).collect();
                bodies[k].stages().work(&bodies[k], &couplings, &incoming)
            })
            .collect();
        let mut check_order: Vec<usize> = (0..bodies.len()).collect();
        check_order.sort_by_key(|&k| bodies[k].stages().sets_flow_speed());
        let state = State { bodies, rates, time: 0.0, steps: 0, u_max: 0.0, ipst_iterations: 0 };
        let mut sim = Simulation {
            domain,
            kernel,
            time_settings: time,
            state,
            couplings,
            work,
            bins,
            local_bins,
            clocks,
            check_order,
            times: PhaseTimes::default(),
        };
        sim.start();
        Ok(sim)
    }
}

/// The bodies with every fluid body merged into the first one of the same physics and
/// smoothing length before it, if any.
fn merge_fluids<const D: usize>(given: Vec<Body<D>>) -> Result<Vec<Body<D>>, String> {
    let mut bodies: Vec<Body<D>> = Vec::with_capacity(given.len());
    for body in given {
        let Body::Fluid(more) = body else {
            bodies.push(body);
            continue;
        };
        let same = bodies
            .iter_mut()
            .filter_map(Body::as_fluid_mut)
            .find(|f| f.physics.same_physics(&more.physics) && f.h == more.h);
        match same {
            Some(f) => f.merge(more)?,
            None => bodies.push(Body::Fluid(more)),
        }
    }
    Ok(bodies)
}

/// What the interaction match cannot see, pair by pair: a solid a fluid meets must present
/// a boundary to it; a boundary extrapolates from one fluid only; two solids that sum
/// across their pair share a smoothing length.
fn check_couplings<const D: usize>(bodies: &[Body<D>], couplings: &[Coupling<D>]) -> Result<(), String> {
    for c in couplings {
        let (dst, src) = c.bodies();
        match c.interaction() {
            Interaction::FluidBoundary if bodies[src].as_boundary().is_none() => {
                return Err(format!(
                    "solid `{}` meets the fluid but presents nothing to it: give it the fluid's boundary model (`ElasticSolid::facing_fluid`), or keep them apart (`without`)",
                    bodies[src].name()
                ))
            }
            Interaction::BoundaryFluid | Interaction::StructureFluid => {
                let fluids = couplings.iter().filter(|o| o.interaction() == c.interaction() && o.bodies().0 == dst).count();
                if fluids > 1 {
                    return Err(format!(
                        "body `{}` meets {fluids} fluids: a boundary extrapolates from one; keep it apart from the others (`without`)",
                        bodies[dst].name()
                    ));
                }
            }
            Interaction::SolidContinuum if bodies[dst].h() != bodies[src].h() => {
                return Err(format!(
                    "solids `{}` and `{}` sum their equations across but differ in smoothing length",
                    bodies[dst].name(),
                    bodies[src].name()
                ))
            }
            _ => {}
        }
    }
    Ok(())
}
