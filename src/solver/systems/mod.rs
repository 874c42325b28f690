//! The bodies of a simulation, one module per kind: each kind owns its struct-of-arrays
//! fields (only those its declared physics needs), its material constants, its smoothing
//! length, its time-step limit, and what it does at the opening kick, the drift and the
//! closing kick of a step. Their rates live outside them ([`Rates`], one set per body, owned
//! by the simulation), so that a pass borrows the bodies immutably and one rate set
//! mutably.
//!
//! - [`fluid`]: a weakly compressible fluid (CTVF sec. 2-3), integrated;
//! - [`wall`]: wall particles with a prescribed motion, not integrated, presenting
//!   extrapolated values to the fluid through the [`boundary`] model they embed;
//! - [`elastic_solid`]: an elastic solid (CTVF sec. 2-3, eqs. 8, 25, 30-32), integrated; in a
//!   fluid it is also a structure, presenting the boundary model to the fluid (thesis
//!   sec. 4.2.4).
//!
//! Who acts on whom is decided in [`interactions`](crate::solver::interactions), by one
//! exhaustive `match` over the [`BodyKind`]s.

pub mod boundary;
pub mod elastic_solid;
pub mod fluid;
pub mod wall;

pub use boundary::{BoundaryMaterial, BoundaryModel, Presented, WallDensity, WallPressure, WallViscosity};
pub use elastic_solid::{ElasticSolid, SolidInit, SolidMaterial, SolidRates};
pub use fluid::{Fluid, FluidInit, FluidPart, FluidRates};
pub use wall::{Wall, WallMotion};

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

    /// The wall, if this is one.
    pub fn as_wall(&self) -> Option<&Wall<D>> {
        match self {
            Body::Wall(w) => Some(w),
            _ => None,
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
