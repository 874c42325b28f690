//! The bodies of a simulation, one module per kind: each kind owns its struct-of-arrays
//! fields (only those its declared physics needs), its material constants, its smoothing
//! length, its time-step limit, what it does at the opening kick, the drift and the closing
//! kick of a step, and what it does at each stage of a step ([`BodyStages`]). Their rates
//! live outside them ([`Rates`], one set per body, owned by the simulation), so that a pass
//! borrows the bodies immutably and one rate set mutably; so does their passes' work space
//! ([`Work`]).
//!
//! - [`fluid`]: a weakly compressible fluid (CTVF sec. 2-3), integrated;
//! - [`wall`]: wall particles with a prescribed motion, not integrated, presenting
//!   extrapolated values to the fluid through the [`boundary`] model they embed;
//! - [`elastic_solid`]: an elastic solid (CTVF sec. 2-3, eqs. 8, 25, 30-32), integrated; in a
//!   fluid it is also a structure, presenting the boundary model to the fluid (thesis
//!   sec. 4.2.4).
//!
//! Who acts on whom is decided in [`interactions`](crate::solver::interactions), by one
//! exhaustive `match` over pairs of [`BodyKind`]s. A new kind of body is a module here that
//! implements [`BodyStages`], an arm in [`stages_of`] and its arms in that match.

pub mod boundary;
pub mod elastic_solid;
pub mod fluid;
pub mod wall;

pub use boundary::{BoundaryMaterial, BoundaryModel, Presented, WallDensity, WallPressure, WallViscosity};
pub use elastic_solid::{ElasticSolid, MirrorPlane, SolidInit, SolidMaterial, SolidRates, SolidWork};
pub use fluid::{Fluid, FluidInit, FluidPart, FluidRates, FluidWork};
pub use wall::{Wall, WallMotion};

use crate::solver::equations::Point;
use crate::solver::integrator::{PhaseTimes, TimeSettings};
use crate::solver::interactions::Coupling;
use crate::solver::kernel::Kernel;
use crate::solver::nnps::{CellList, Domain};

/// The checks every integrated body's initial values pass, with errors naming the body
/// (`kind` `name`) and the offending field: some particles, a positive finite smoothing
/// length, every per-particle field (`fields`: name and length) as long as the positions
/// (`n`), and positive masses and densities (NaN refused too).
pub(crate) fn check_init(
    (kind, name): (&str, &str),
    n: usize,
    h: f64,
    fields: &[(&str, usize)],
    m: &[f64],
    rho: &[f64],
) -> Result<(), String> {
    if n == 0 {
        return Err(format!("{kind} `{name}`: no particles"));
    }
    if !(h > 0.0 && h.is_finite()) {
        return Err(format!("{kind} `{name}`: smoothing length h = {h} must be positive"));
    }
    for &(field, len) in fields {
        if len != n {
            return Err(format!("{kind} `{name}`: {field} has {len} entries for {n} particles"));
        }
    }
    // `!(v > 0.0)` also rejects NaN.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if let Some(i) = m.iter().position(|&m| !(m > 0.0)) {
        return Err(format!("{kind} `{name}`: particle {i} has non-positive mass {}", m[i]));
    }
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if let Some(i) = rho.iter().position(|&r| !(r > 0.0)) {
        return Err(format!("{kind} `{name}`: particle {i} has non-positive density {}", rho[i]));
    }
    Ok(())
}

use crate::solver::math::Vector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// One body of a simulation. (A simulation holds a handful of bodies: the variants' sizes
/// do not matter.)
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Body<const D: usize> {
    /// A fluid (every fluid body of one physics shares one [`Fluid`], see there).
    Fluid(Fluid<D>),
    /// Wall particles.
    Wall(Wall<D>),
    /// An elastic solid.
    ElasticSolid(ElasticSolid<D>),
}

/// The kinds of body, as the interaction match sees them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// [`Fluid`].
    Fluid,
    /// [`Wall`].
    Wall,
    /// [`ElasticSolid`].
    ElasticSolid,
}

impl<const D: usize> Body<D> {
    /// The body's kind.
    pub fn kind(&self) -> BodyKind {
        match self {
            Body::Fluid(_) => BodyKind::Fluid,
            Body::Wall(_) => BodyKind::Wall,
            Body::ElasticSolid(_) => BodyKind::ElasticSolid,
        }
    }

    /// The names this body answers to: one, or for a fluid the names of its parts.
    pub fn names(&self) -> Vec<&str> {
        match self {
            Body::Fluid(f) => f.parts.iter().map(|p| p.name.as_str()).collect(),
            Body::Wall(w) => vec![w.name.as_str()],
            Body::ElasticSolid(s) => vec![s.name.as_str()],
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        match self {
            Body::Fluid(f) => f.len(),
            Body::Wall(w) => w.len(),
            Body::ElasticSolid(s) => s.len(),
        }
    }

    /// Whether the body has no particles (never true for a constructed body).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The positions of the particles.
    pub fn x(&self) -> &[Vector<D>] {
        match self {
            Body::Fluid(f) => &f.x,
            Body::Wall(w) => &w.x,
            Body::ElasticSolid(s) => &s.x,
        }
    }

    /// The fluid, if this is one.
    pub fn as_fluid(&self) -> Option<&Fluid<D>> {
        match self {
            Body::Fluid(f) => Some(f),
            _ => None,
        }
    }

    /// The fluid, if this is one, mutably.
    pub fn as_fluid_mut(&mut self) -> Option<&mut Fluid<D>> {
        match self {
            Body::Fluid(f) => Some(f),
            _ => None,
        }
    }

    /// The elastic solid, if this is one.
    pub fn as_solid(&self) -> Option<&ElasticSolid<D>> {
        match self {
            Body::ElasticSolid(s) => Some(s),
            _ => None,
        }
    }

    /// The elastic solid, if this is one, mutably.
    pub fn as_solid_mut(&mut self) -> Option<&mut ElasticSolid<D>> {
        match self {
            Body::ElasticSolid(s) => Some(s),
            _ => None,
        }
    }

    /// The wall, if this is one.
    pub fn as_wall(&self) -> Option<&Wall<D>> {
        match self {
            Body::Wall(w) => Some(w),
            _ => None,
        }
    }

    /// The wall, if this is one, mutably.
    pub fn as_wall_mut(&mut self) -> Option<&mut Wall<D>> {
        match self {
            Body::Wall(w) => Some(w),
            _ => None,
        }
    }

    /// Its name: the body's, or for a fluid of several parts the first part's.
    pub fn name(&self) -> &str {
        match self {
            Body::Fluid(f) => &f.parts[0].name,
            Body::Wall(w) => &w.name,
            Body::ElasticSolid(s) => &s.name,
        }
    }

    /// Its smoothing length, for a body whose particles sum over neighbours (not a wall's,
    /// which its neighbours read at theirs).
    pub fn h(&self) -> Option<f64> {
        match self {
            Body::Fluid(f) => Some(f.h),
            Body::ElasticSolid(s) => Some(s.h),
            Body::Wall(_) => None,
        }
    }

    /// Whether its particles move by the forces on them (it has rates).
    pub fn is_integrated(&self) -> bool {
        !matches!(self.zero_rates(), Rates::None)
    }

    /// Sizes the values it presents to a fluid for its particles (after a checkpoint,
    /// which does not hold them).
    pub fn resize_boundary(&mut self) {
        match self {
            Body::Wall(w) => w.boundary.resize(),
            Body::ElasticSolid(s) => {
                if let Some(b) = s.boundary.as_mut() {
                    b.resize();
                }
            }
            Body::Fluid(_) => {}
        }
    }

    /// Keeps the particles `keep` marks (one flag per particle), in their order. Errors for
    /// a body whose particles cannot change.
    pub fn retain(&mut self, keep: &[bool]) -> Result<(), String> {
        match self {
            Body::Fluid(f) => f.retain(keep),
            Body::ElasticSolid(s) => s.retain(keep),
            Body::Wall(w) => Err(format!("wall `{}`: its particles do not change", w.name)),
        }
    }

    /// Appends the particles of `more`, a body of the same kind and physics. Errors for
    /// another kind, another physics, or a body whose particles cannot change.
    pub fn extend(&mut self, more: Body<D>) -> Result<(), String> {
        match (self, more) {
            (Body::Fluid(f), Body::Fluid(more)) => f.extend(more),
            (Body::ElasticSolid(s), Body::ElasticSolid(more)) => s.extend(more),
            (Body::Wall(w), _) => Err(format!("wall `{}`: its particles do not change", w.name)),
            (body, more) => Err(format!(
                "body `{}` is a {:?}: particles of a {:?} cannot join it",
                body.name(),
                body.kind(),
                more.kind()
            )),
        }
    }

    /// What the body does at each stage of a step (see [`BodyStages`]).
    pub fn stages(&self) -> &'static dyn BodyStages<D> {
        stages_of(self.kind())
    }

    /// Zeroed rates for its particles (none for a body that is not integrated).
    pub fn zero_rates(&self) -> Rates<D> {
        match self {
            Body::Fluid(f) => Rates::Fluid(FluidRates::of(f)),
            Body::ElasticSolid(s) => Rates::Solid(SolidRates::of(s)),
            Body::Wall(_) => Rates::None,
        }
    }

    /// The body as a boundary a fluid reads: its positions and what they present (a
    /// wall's or a structure's extrapolated values); `None` for a body that is not one.
    pub fn as_boundary(&self) -> Option<(&[Vector<D>], &BoundaryModel<D>)> {
        match self {
            Body::Wall(w) => Some((&w.x, &w.boundary)),
            Body::ElasticSolid(s) => s.boundary.as_ref().map(|b| (&s.x[..], b)),
            Body::Fluid(_) => None,
        }
    }

    /// Whether the body's particles move (and so must be binned again after the drift).
    pub fn moves(&self) -> bool {
        match self {
            Body::Fluid(_) | Body::ElasticSolid(_) => true,
            Body::Wall(w) => w.moves(),
        }
    }

    /// The largest time step the body allows at `cfl` (eq. 61), given the fluid's largest
    /// particle speed `u_max` (a solid takes its own, eq. 62); `None` for a body that sets
    /// no limit (a wall's motion is prescribed).
    pub fn dt_limit(&self, cfl: f64, u_max: f64) -> Option<f64> {
        match self {
            Body::Fluid(f) => Some(f.dt_limit(cfl, u_max)),
            Body::ElasticSolid(s) => Some(s.dt_limit(cfl)),
            Body::Wall(_) => None,
        }
    }

    /// The opening half kick of a step over `dt` (eqs. 54-55 for a fluid).
    pub fn kick_open(&mut self, rates: &Rates<D>, dt: f64) {
        match (self, rates) {
            (Body::Fluid(f), Rates::Fluid(r)) => f.kick_open(r, dt),
            (Body::ElasticSolid(s), Rates::Solid(r)) => s.kick_open(r, dt),
            (Body::Wall(w), _) => w.half_kick(dt),
            (Body::Fluid(_), _) => unreachable!("a fluid's rates are fluid rates"),
            (Body::ElasticSolid(_), _) => unreachable!("a solid's rates are solid rates"),
        }
    }

    /// The drift over `dt` (eq. 59 for a fluid).
    pub fn drift(&mut self, dt: f64) {
        match self {
            Body::Fluid(f) => f.drift(dt),
            Body::Wall(w) => w.drift(dt),
            Body::ElasticSolid(s) => s.drift(dt),
        }
    }

    /// The closing half kick of a step over `dt` (eq. 60 for a fluid).
    pub fn kick_close(&mut self, rates: &Rates<D>, dt: f64) {
        match (self, rates) {
            (Body::Fluid(f), Rates::Fluid(r)) => f.kick_close(r, dt),
            (Body::ElasticSolid(s), Rates::Solid(r)) => s.kick_close(r, dt),
            (Body::Wall(w), _) => w.half_kick(dt),
            (Body::Fluid(_), _) => unreachable!("a fluid's rates are fluid rates"),
            (Body::ElasticSolid(_), _) => unreachable!("a solid's rates are solid rates"),
        }
    }
}

/// The time derivatives of one body, owned by the simulation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Rates<const D: usize> {
    /// A fluid's.
    Fluid(FluidRates<D>),
    /// An elastic solid's.
    Solid(SolidRates<D>),
    /// None: the body is not integrated (its motion, if any, is prescribed).
    None,
}

impl<const D: usize> Rates<D> {
    /// A solid's rates, if these are.
    pub fn as_solid(&self) -> Option<&SolidRates<D>> {
        match self {
            Rates::Solid(r) => Some(r),
            _ => None,
        }
    }

    /// A solid's rates, if these are, mutably.
    pub fn as_solid_mut(&mut self) -> Option<&mut SolidRates<D>> {
        match self {
            Rates::Solid(r) => Some(r),
            _ => None,
        }
    }

    /// Keeps the rates of the particles `keep` marks.
    pub fn retain(&mut self, keep: &[bool]) {
        match self {
            Rates::Fluid(r) => {
                retain_by(&mut r.du, keep);
                retain_by(&mut r.dp, keep);
                retain_by(&mut r.drho, keep);
                retain_by(&mut r.a_c, keep);
                retain_by(&mut r.a_ext, keep);
            }
            Rates::Solid(r) => {
                retain_by(&mut r.du, keep);
                retain_by(&mut r.drho, keep);
                retain_by(&mut r.ds, keep);
                retain_by(&mut r.a_c, keep);
                retain_by(&mut r.a_held, keep);
                retain_by(&mut r.a_ext, keep);
            }
            Rates::None => {}
        }
    }

    /// Appends `more` (of the same kind: the rates of particles added).
    pub fn extend(&mut self, more: Rates<D>) {
        match (self, more) {
            (Rates::Fluid(r), Rates::Fluid(m)) => {
                r.du.extend(m.du);
                r.dp.extend(m.dp);
                r.drho.extend(m.drho);
                r.a_c.extend(m.a_c);
            }
            (Rates::Solid(r), Rates::Solid(m)) => {
                r.du.extend(m.du);
                r.drho.extend(m.drho);
                r.ds.extend(m.ds);
                r.a_c.extend(m.a_c);
                r.a_held.extend(m.a_held);
            }
            _ => {}
        }
    }

    /// The external acceleration the couplings add into, if the body has one (see
    /// [`BodyStages::reset_external`]).
    pub fn external_mut(&mut self) -> Option<&mut [Vector<D>]> {
        match self {
            Rates::Solid(r) if !r.a_ext.is_empty() => Some(&mut r.a_ext),
            Rates::Fluid(r) if !r.a_ext.is_empty() => Some(&mut r.a_ext),
            _ => None,
        }
    }

    /// A fluid's rates, if these are.
    pub fn as_fluid(&self) -> Option<&FluidRates<D>> {
        match self {
            Rates::Fluid(r) => Some(r),
            Rates::Solid(_) | Rates::None => None,
        }
    }

    /// A fluid's rates, if these are, mutably.
    pub fn as_fluid_mut(&mut self) -> Option<&mut FluidRates<D>> {
        match self {
            Rates::Fluid(r) => Some(r),
            Rates::Solid(_) | Rates::None => None,
        }
    }
}

/// What a kind of body does at each stage of a step, called by the simulation for every
/// body at that stage (see [`simulation`](crate::solver::simulation)): each reads and writes
/// through the [`World`] (the bodies, their rates and work, the couplings, the binning), and
/// does nothing where its kind has nothing to do. `i` is the body's index.
pub trait BodyStages<const D: usize>: Sync {
    /// Its work space for the passes, given its incoming couplings (their indices among
    /// `couplings`): which of them its passes read.
    fn work(&self, body: &Body<D>, couplings: &[Coupling<D>], incoming: &[usize]) -> Work<D> {
        let _ = (body, couplings, incoming);
        Work::None
    }

    /// Wraps its positions into the box and bins them in `w.bins[i]` (sorting a body that
    /// its passes read in cell order), if it moves.
    fn rebin(&self, w: &mut World<D>, i: usize) {
        let _ = (w, i);
    }

    /// The quantities measured once on the initial configuration (IPST's reference chi).
    fn reference(&self, w: &mut World<D>, i: usize) {
        let _ = (w, i);
    }

    /// Its external acceleration reset to the part held over its sub-steps, before the
    /// couplings at its clock add theirs ([`Coupling::add_force`]).
    fn reset_external(&self, w: &mut World<D>, i: usize) {
        let _ = (w, i);
    }

    /// Gathers the views of its particles that other bodies' passes read.
    fn gather(&self, w: &mut World<D>, i: usize) {
        let _ = (w, i);
    }

    /// The rates taken at the step's start positions with the half-step velocities (sec.
    /// 3.7), before the drift: a solid's density and stress rates, a fluid's density and
    /// pressure rates if asked there.
    fn start_rates(&self, w: &mut World<D>, i: usize, dt: f64) {
        let _ = (w, i, dt);
    }

    /// The update over `dt` by the rates of [`start_rates`](Self::start_rates).
    fn start_update(&self, w: &mut World<D>, i: usize, dt: f64) {
        let _ = (w, i, dt);
    }

    /// The summation density.
    fn density(&self, w: &mut World<D>, i: usize) {
        let _ = (w, i);
    }

    /// The density and pressure rates after the drift and their update over `dt` (at the
    /// `start` of a run, the pressure from the initial density).
    fn pressure(&self, w: &mut World<D>, i: usize, dt: f64, start: bool) {
        let _ = (w, i, dt, start);
    }

    /// The free surface, detected; returns whether it set pressures (so that the
    /// boundaries extrapolate again).
    fn surface(&self, w: &mut World<D>, i: usize) -> bool {
        let _ = (w, i);
        false
    }

    /// The accelerations for the closing kick (a step `dt` scales the shifting), with the
    /// external acceleration the couplings have added.
    fn accelerations(&self, w: &mut World<D>, i: usize, dt: f64) {
        let _ = (w, i, dt);
    }

    /// The iterative shifting for a step `dt`, step number `next_step`; returns its moves.
    fn homogenise(&self, w: &mut World<D>, i: usize, dt: f64, next_step: u64) -> usize {
        let _ = (w, i, dt, next_step);
        0
    }

    /// For a body alone in its simulation: the listing and every pass of a step as one
    /// fused schedule of its own, if it has one and takes it this step (returns whether it
    /// did; the stages above are then skipped).
    fn fused(&self, w: &mut World<D>, i: usize, dt: f64, dt_nominal: f64) -> bool {
        let _ = (w, i, dt, dt_nominal);
        false
    }

    /// After a step that took `seconds` of wall time (a tuner of the body's schedule times
    /// it).
    fn timed(&self, work: &mut Work<D>, seconds: f64) {
        let _ = (work, seconds);
    }

    /// Whether the body's largest speed sets the time step (a fluid's, eq. 61): it is
    /// checked after the others.
    fn sets_flow_speed(&self) -> bool {
        false
    }

    /// Blow-up detection after a step: non-finite fields, a particle outside a bounded
    /// domain, a speed beyond `blowup` times the body's speed of sound. Returns the body's
    /// largest flow speed if its speed sets the next time step (a fluid's), or why it blew
    /// up.
    fn check(&self, body: &Body<D>, domain: &Domain<D>, blowup: f64) -> Result<Option<f64>, String> {
        let _ = (body, domain, blowup);
        Ok(None)
    }
}

/// What the body kind `kind` does at each stage of a step.
pub fn stages_of<const D: usize>(kind: BodyKind) -> &'static dyn BodyStages<D> {
    match kind {
        BodyKind::Fluid => &fluid::FluidStages,
        BodyKind::Wall => &wall::WallStages,
        BodyKind::ElasticSolid => &elastic_solid::SolidStages,
    }
}

/// The work space of one body's passes (not part of the state: rebuilt when needed).
#[derive(Debug, Default)]
pub enum Work<const D: usize> {
    /// A fluid's.
    Fluid(Box<FluidWork<D>>),
    /// An elastic solid's.
    Solid(Box<SolidWork<D>>),
    /// None.
    #[default]
    None,
}

impl<const D: usize> Work<D> {
    /// A fluid's work, if this is one.
    pub fn as_fluid(&self) -> Option<&FluidWork<D>> {
        match self {
            Work::Fluid(w) => Some(w),
            _ => None,
        }
    }

    /// A fluid's work, if this is one, mutably.
    pub fn as_fluid_mut(&mut self) -> Option<&mut FluidWork<D>> {
        match self {
            Work::Fluid(w) => Some(w),
            _ => None,
        }
    }

    /// A solid's work, if this is one.
    pub fn as_solid(&self) -> Option<&SolidWork<D>> {
        match self {
            Work::Solid(w) => Some(w),
            _ => None,
        }
    }

    /// A solid's work, if this is one, mutably.
    pub fn as_solid_mut(&mut self) -> Option<&mut SolidWork<D>> {
        match self {
            Work::Solid(w) => Some(w),
            _ => None,
        }
    }

    /// The views of a fluid's particles as its last pass B gathered them (a structure's
    /// reaction reads them).
    pub fn fluid_points(&self) -> Option<&[Point<D>]> {
        self.as_fluid().map(|w| &w.passes.points[..])
    }
}

/// Everything the stages of a step read and write, borrowed from the simulation: the
/// bodies, their rates and work, the couplings, the binning (one cell list per body), the
/// kernel, the box, the time loop's settings and the time spent per phase.
pub struct World<'a, const D: usize> {
    /// The bodies.
    pub bodies: &'a mut [Body<D>],
    /// Their rates.
    pub rates: &'a mut [Rates<D>],
    /// Their passes' work space.
    pub work: &'a mut [Work<D>],
    /// The couplings.
    pub couplings: &'a mut [Coupling<D>],
    /// Each body's binning.
    pub bins: &'a mut [CellList<D>],
    /// The kernel.
    pub kernel: &'a Kernel,
    /// The box.
    pub domain: Domain<D>,
    /// The time loop's settings.
    pub settings: &'a TimeSettings,
    /// The time per phase, summed over the run.
    pub times: &'a mut PhaseTimes,
}

/// Keeps the entries of `v` that `keep` marks (`v` empty: a field the body does not have).
pub(crate) fn retain_by<T>(v: &mut Vec<T>, keep: &[bool]) {
    if !v.is_empty() {
        let mut k = keep.iter();
        v.retain(|_| *k.next().expect("a flag per particle"));
    }
}

/// Permutes `v` by `order` (`v_new[k] = v_old[order[k]]`) through a reusable scratch
/// buffer, so reordering allocates nothing once the buffers have grown. A gather, split
/// across the threads: run serially, a step's reordering held the second core idle.
pub(crate) fn permute<T: Copy + Send + Sync>(v: &mut Vec<T>, order: &[u32], scratch: &mut Vec<T>) {
    let Some(&first) = v.first() else { return };
    scratch.resize(order.len(), first);
    let from = &v[..];
    scratch
        .par_iter_mut()
        .zip(order)
        .with_min_len(crate::solver::LIGHT_LOOP_LEN)
        .for_each(|(s, &i)| *s = from[i as usize]);
    std::mem::swap(v, scratch);
}
