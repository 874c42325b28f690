//! Who acts on whom, decided in one place: [`interactions`] is one exhaustive `match` over an
//! ordered pair of bodies, `(dst, src)`, that sees both [`BodyKind`]s, whether they are one
//! body, and what the simulation's builder set for the pair ([`PairParams`]), so that a new
//! kind of body does not compile until every pair with it is decided. Each interaction is a
//! module of its own, holding its neighbour lists and what a particle gathers from a
//! neighbour across it; a [`Coupling`] is one of them built for a pair, and the simulation
//! walks its list of couplings stage by stage through the hooks below, naming none of them.
//! The passes ([`passes`](crate::solver::passes)) call the per-neighbour functions inside
//! their particle loops, chosen outside them, so the loops stay monomorphic.
//!
//! - [`fluid_fluid`]: a fluid's particles among themselves, CTVF eqs. (25)-(27);
//! - [`fluid_boundary`]: a fluid reading a boundary's extrapolated values as neighbours;
//! - [`boundary_fluid`]: a boundary extrapolating its values from a fluid (eqs. 46-52);
//! - [`solid_solid`]: an elastic solid's particles among themselves, eqs. (25), (30)-(32);
//! - [`solid_continuum`]: an elastic solid summing its continuum equations over another
//!   solid's particles too, its shifting and surface its own (the CTVF authors' two rings);
//! - [`structure_fluid`]: an elastic solid in a fluid, extrapolating its pressure from the
//!   fluid (thesis eq. 4.14) and taking the reaction of the fluid's pair force (eq. 4.15);
//!   the fluid reads it as a boundary ([`fluid_boundary`]);
//! - [`uniform_load`]: an applied acceleration on some of a body's particles (a distributed
//!   load);
//! - [`lists`]: the neighbour lists with their kernel values, shared by all of them.
//!
//! A coupling's hooks, each called by the simulation for every coupling at its stage:
//! [`relist`](Coupling::relist) (its neighbour lists), [`extrapolate`](Coupling::extrapolate)
//! (a boundary's values from a fluid), [`add_force`](Coupling::add_force) (a force per unit
//! mass into the destination's external acceleration, at the destination's clock) and
//! [`exchange`](Coupling::exchange) (a force computed at the source's slower clock and held
//! over the destination's sub-steps, with its closing correction).
//!
//! Reactions stay deterministic without atomics: every pass is a gather, each particle
//! writing only its own row, in a neighbour order fixed by the lists.

pub mod boundary_fluid;
pub mod fluid_boundary;
pub mod fluid_fluid;
pub mod lists;
pub mod solid_continuum;
pub mod solid_solid;
pub mod structure_fluid;
pub mod uniform_load;

use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::CellList;
use crate::solver::systems::{Body, BodyKind, Rates, Work};
pub use uniform_load::UniformLoad;

/// What one body does with another's particles, or with its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interaction {
    /// A fluid's particles among themselves: density, pressure and momentum (eqs. 25-27),
    /// homogenisation and free-surface detection ([`fluid_fluid`]).
    FluidFluid,
    /// A fluid reads a boundary's particles as neighbours, with their extrapolated pressure
    /// and velocities ([`fluid_boundary`]).
    FluidBoundary,
    /// A boundary extrapolates its pressure and velocities from a fluid (eqs. 46-52,
    /// [`boundary_fluid`]).
    BoundaryFluid,
    /// An elastic solid's particles among themselves: density, stress and momentum
    /// (eqs. 25, 30-32), shifting and free-surface detection ([`solid_solid`]).
    SolidSolid,
    /// An elastic solid sums its density, stress and momentum over another solid's
    /// particles too, as over its own; its shifting and free surface stay its own
    /// ([`solid_continuum`]).
    SolidContinuum,
    /// A structure (an elastic solid) in a fluid: it extrapolates its pressure from the
    /// fluid (thesis eq. 4.14) and takes the reaction of the fluid's pair force (eq. 4.15)
    /// ([`structure_fluid`]).
    StructureFluid,
    /// An applied acceleration on some of a body's particles ([`uniform_load`]).
    Load,
}

/// How two solid bodies meet, as the builder sets it for their pair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SolidPair {
    /// They do not meet: no contact law is modelled, so they pass through each other.
    #[default]
    Apart,
    /// Each sums its continuum equations over the other's particles as over its own (Gray
    /// et al. 2001's colliding rings, with no contact law), while its shifting, IPST and
    /// free-surface detection run over its own particles only.
    Continuum,
}

/// What the builder set for a pair of bodies (or a body with itself), beside their kinds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairParams {
    /// The pair does not interact at all (`Builder::without`).
    pub off: bool,
    /// How two solids meet.
    pub solids: SolidPair,
    /// An applied load on a body (with itself only).
    pub load: Option<UniformLoad>,
}

/// The interactions by which body `dst` (of kind `dst`) is acted on by body `src`, `same`
/// when they are one body, with what the builder set for the pair: none, one or several
/// (a solid with itself under a load: its own sums and the load). Errors for a pair the
/// solver cannot model, naming what to do instead.
pub fn interactions(
    dst: BodyKind,
    src: BodyKind,
    same: bool,
    pair: &PairParams,
) -> Result<Vec<Interaction>, String> {
    use BodyKind::{ElasticSolid, Fluid, Wall};
    use Interaction as I;
    if pair.off {
        return Ok(Vec::new());
    }
    let mut out = match (dst, src, same) {
        (Fluid, Fluid, true) => vec![I::FluidFluid],
        // Fluids of one physics are merged into one body by the builder; fluids of different
        // physics would need a multiphase model.
        (Fluid, Fluid, false) => {
            return Err("two fluid bodies of different physics meet: a multiphase interaction is not modelled; keep them apart (`without`)".into())
        }
        (Fluid, Wall, _) => vec![I::FluidBoundary],
        (Wall, Fluid, _) => vec![I::BoundaryFluid],
        // Walls neither move by forces nor present values to each other.
        (Wall, Wall, _) => Vec::new(),
        (ElasticSolid, ElasticSolid, true) => vec![I::SolidSolid],
        (ElasticSolid, ElasticSolid, false) => match pair.solids {
            SolidPair::Apart => Vec::new(),
            SolidPair::Continuum => vec![I::SolidContinuum],
        },
        // Fluid-structure interaction (thesis sec. 4.2.4): the fluid reads the structure
        // as a boundary, the structure takes the opposite of the fluid's pair force.
        (Fluid, ElasticSolid, _) => vec![I::FluidBoundary],
        (ElasticSolid, Fluid, _) => vec![I::StructureFluid],
        // Solid-wall contact is not modelled (a clamp is made of the solid's own fixed
        // particles, see `systems::elastic_solid`).
        (ElasticSolid, Wall, _) | (Wall, ElasticSolid, _) => Vec::new(),
    };
    if let Some(load) = &pair.load {
        match (dst, same) {
            (ElasticSolid | Fluid, true) => {
                load.check()?;
                out.push(I::Load);
            }
            (Wall, true) => {
                return Err("a load acts on a body that moves by its forces, not on a wall".into())
            }
            (_, false) => return Err("a load acts on one body: give it for the body with itself".into()),
        }
    }
    if pair.solids != SolidPair::Apart && !(dst == ElasticSolid && src == ElasticSolid && !same) {
        return Err("a solid pair setting is for two different solid bodies".into());
    }
    Ok(out)
}

/// One interaction built for an ordered pair of bodies: its lists and what it keeps.
#[derive(Debug)]
pub enum Coupling<const D: usize> {
    /// [`Interaction::FluidFluid`].
    FluidFluid(fluid_fluid::FluidFluid<D>),
    /// [`Interaction::FluidBoundary`].
    FluidBoundary(fluid_boundary::FluidBoundary<D>),
    /// [`Interaction::BoundaryFluid`].
    BoundaryFluid(boundary_fluid::BoundaryFluid<D>),
    /// [`Interaction::SolidSolid`].
    SolidSolid(solid_solid::SolidSolid<D>),
    /// [`Interaction::SolidContinuum`].
    SolidContinuum(solid_continuum::SolidContinuum<D>),
    /// [`Interaction::StructureFluid`].
    StructureFluid(structure_fluid::StructureFluid<D>),
    /// [`Interaction::Load`].
    Load(uniform_load::LoadOn),
}

impl<const D: usize> Coupling<D> {
    /// `interaction` built for body `dst` acted on by body `src`, with the pair's settings.
    pub fn new(interaction: Interaction, dst: usize, src: usize, pair: &PairParams) -> Self {
        match interaction {
            Interaction::FluidFluid => Coupling::FluidFluid(fluid_fluid::FluidFluid::new(dst)),
            Interaction::FluidBoundary => {
                Coupling::FluidBoundary(fluid_boundary::FluidBoundary::new(dst, src))
            }
            Interaction::BoundaryFluid => {
                Coupling::BoundaryFluid(boundary_fluid::BoundaryFluid::new(dst, src))
            }
            Interaction::SolidSolid => Coupling::SolidSolid(solid_solid::SolidSolid::new(dst)),
            Interaction::SolidContinuum => {
                Coupling::SolidContinuum(solid_continuum::SolidContinuum::new(dst, src))
            }
            Interaction::StructureFluid => {
                Coupling::StructureFluid(structure_fluid::StructureFluid::new(dst, src))
            }
            Interaction::Load => Coupling::Load(uniform_load::LoadOn {
                body: dst,
                load: pair.load.clone().expect("a load's pair has one"),
            }),
        }
    }

    /// The interaction it is.
    pub fn interaction(&self) -> Interaction {
        match self {
            Coupling::FluidFluid(_) => Interaction::FluidFluid,
            Coupling::FluidBoundary(_) => Interaction::FluidBoundary,
            Coupling::BoundaryFluid(_) => Interaction::BoundaryFluid,
            Coupling::SolidSolid(_) => Interaction::SolidSolid,
            Coupling::SolidContinuum(_) => Interaction::SolidContinuum,
            Coupling::StructureFluid(_) => Interaction::StructureFluid,
            Coupling::Load(_) => Interaction::Load,
        }
    }

    /// The body acted on and the body acting: `(dst, src)`.
    pub fn bodies(&self) -> (usize, usize) {
        match self {
            Coupling::FluidFluid(c) => (c.body, c.body),
            Coupling::FluidBoundary(c) => (c.fluid, c.boundary),
            Coupling::BoundaryFluid(c) => (c.boundary, c.fluid),
            Coupling::SolidSolid(c) => (c.body, c.body),
            Coupling::SolidContinuum(c) => (c.dst, c.src),
            Coupling::StructureFluid(c) => (c.structure, c.fluid),
            Coupling::Load(c) => (c.body, c.body),
        }
    }

    /// Whether its force on the destination is computed at the source's clock and held over
    /// the destination's sub-steps ([`exchange`](Self::exchange)): a destination with such a
    /// coupling steps on its own clock.
    pub fn holds_force(&self) -> bool {
        matches!(self, Coupling::StructureFluid(_))
    }

    /// The fluid boundary it is, if it is one.
    pub fn as_fluid_boundary(&self) -> Option<&fluid_boundary::FluidBoundary<D>> {
        match self {
            Coupling::FluidBoundary(c) => Some(c),
            _ => None,
        }
    }

    /// Rebuilds its neighbour lists from the current binning of the bodies (`bins`, one per
    /// body, each binned with the search radius of the simulation).
    pub fn relist(&mut self, bodies: &[Body<D>], bins: &[CellList<D>], kernel: &Kernel) {
        let fluid_of = |k: usize| bodies[k].as_fluid().expect("a fluid by the interaction match");
        let solid_of = |k: usize| bodies[k].as_solid().expect("a solid by the interaction match");
        match self {
            Coupling::FluidFluid(c) => c.relist(&bins[c.body], fluid_of(c.body), kernel),
            Coupling::FluidBoundary(c) => {
                let fluid = fluid_of(c.fluid);
                c.relist(&bins[c.boundary], bodies[c.boundary].x(), &fluid.x, fluid.h, kernel)
            }
            Coupling::BoundaryFluid(c) => {
                c.relist(&bins[c.fluid], fluid_of(c.fluid), bodies[c.boundary].x(), kernel)
            }
            Coupling::SolidSolid(c) => c.relist(&bins[c.body], solid_of(c.body), kernel),
            Coupling::SolidContinuum(c) => c.relist(&bins[c.src], solid_of(c.src), solid_of(c.dst), kernel),
            Coupling::StructureFluid(c) => {
                c.relist(&bins[c.fluid], fluid_of(c.fluid), bodies[c.structure].x(), kernel)
            }
            Coupling::Load(_) => {}
        }
    }

    /// Sets the values a boundary presents from its fluid (eqs. 46-52 for a wall, eq. 4.14
    /// for a structure, with its last accelerations from `rates`); nothing for the others.
    pub fn extrapolate(&self, bodies: &mut [Body<D>], rates: &[Rates<D>]) {
        match self {
            Coupling::BoundaryFluid(c) => {
                let [boundary, fluid] =
                    bodies.get_disjoint_mut([c.boundary, c.fluid]).expect("a boundary and a fluid");
                let fluid = fluid.as_fluid().expect("a fluid by the interaction match");
                let wall = boundary.as_wall_mut().expect("a wall by the interaction match");
                c.extrapolate(wall, fluid, fluid.physics.gravity_vector());
            }
            Coupling::StructureFluid(c) => {
                let [structure, fluid] =
                    bodies.get_disjoint_mut([c.structure, c.fluid]).expect("a structure and a fluid");
                let fluid = fluid.as_fluid().expect("a fluid by the interaction match");
                // Eq. (4.14) takes the structure's acceleration: its last du/dt.
                let a = &rates[c.structure].as_solid().expect("a structure's rates").du;
                let solid = structure.as_solid_mut().expect("a solid by the interaction match");
                c.extrapolate(solid, fluid, a, fluid.physics.gravity_vector());
            }
            _ => {}
        }
    }

    /// Adds its force per unit mass on the destination's particles into `a_ext`, the
    /// destination's external acceleration at its own clock; nothing for a coupling without
    /// one.
    pub fn add_force(&self, bodies: &[Body<D>], a_ext: &mut [Vector<D>]) {
        if let Coupling::Load(c) = self {
            let fixed = bodies[c.body].as_solid().map(|s| &s.fixed[..]);
            let ids = bodies[c.body].as_fluid().map(|f| &f.id[..]);
            c.load.add(a_ext, fixed, ids);
        }
    }

    /// A force held over the destination's sub-steps ([`holds_force`](Self::holds_force)):
    /// computed anew from the source's evaluation just made and stored in the destination's
    /// held acceleration. Within a step (`kick` = its length), the destination also takes a
    /// half kick of `kick / 2` times the change from the force it held, so that its impulse
    /// over the step is the mean of the old and new forces, what the source's two half
    /// kicks took (see [`simulation`](crate::solver::simulation)); at the start (`None`), the
    /// force only.
    pub fn exchange(
        &mut self,
        bodies: &mut [Body<D>],
        rates: &mut [Rates<D>],
        work: &[Work<D>],
        kick: Option<f64>,
    ) {
        if let Coupling::StructureFluid(c) = self {
            let (structure, fluid) = (c.structure, c.fluid);
            let points = work[fluid].fluid_points().expect("a fluid's work");
            let fluid = bodies[fluid].as_fluid().expect("a fluid by the interaction match");
            let solid = bodies[structure].as_solid().expect("a solid by the interaction match");
            let new = c.reaction(solid, (points, fluid.h), &fluid.x, &fluid.physics);
            let r = rates[structure].as_solid_mut().expect("a structure's rates");
            if let Some(dt) = kick {
                let solid = bodies[structure].as_solid_mut().expect("a solid by the interaction match");
                for ((u, du), (new, held)) in solid.u.iter_mut().zip(&mut r.du).zip(new.iter().zip(&r.a_held))
                {
                    let change = new - held;
                    *u += change * (0.5 * dt);
                    *du += change;
                }
            }
            r.a_held.clear();
            r.a_held.extend_from_slice(new);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair() -> PairParams {
        PairParams::default()
    }

    #[test]
    fn who_acts_on_whom() {
        use BodyKind::{ElasticSolid, Fluid, Wall};
        use Interaction as I;
        let of = |d, s, same| interactions(d, s, same, &pair()).unwrap();
        assert_eq!(of(Fluid, Fluid, true), [I::FluidFluid]);
        assert!(interactions(Fluid, Fluid, false, &pair()).unwrap_err().contains("keep them apart"));
        assert_eq!(of(Fluid, Wall, false), [I::FluidBoundary]);
        assert_eq!(of(Wall, Fluid, false), [I::BoundaryFluid]);
        assert!(of(Wall, Wall, false).is_empty());
        assert_eq!(of(ElasticSolid, ElasticSolid, true), [I::SolidSolid]);
        assert!(of(ElasticSolid, ElasticSolid, false).is_empty());
        assert!(of(ElasticSolid, Wall, false).is_empty() && of(Wall, ElasticSolid, false).is_empty());
        assert_eq!(of(Fluid, ElasticSolid, false), [I::FluidBoundary]);
        assert_eq!(of(ElasticSolid, Fluid, false), [I::StructureFluid]);
        // The pair's settings: two solids summing across, a load on a solid, a pair off.
        let continuum = PairParams { solids: SolidPair::Continuum, ..pair() };
        assert_eq!(interactions(ElasticSolid, ElasticSolid, false, &continuum).unwrap(), [I::SolidContinuum]);
        assert!(interactions(ElasticSolid, ElasticSolid, true, &continuum).is_err());
        let load = PairParams { load: Some(UniformLoad::new([0.0, -1.0, 0.0], 0..3)), ..pair() };
        assert_eq!(interactions(ElasticSolid, ElasticSolid, true, &load).unwrap(), [I::SolidSolid, I::Load]);
        assert_eq!(interactions(Fluid, Fluid, true, &load).unwrap(), [I::FluidFluid, I::Load]);
        assert!(interactions(Wall, Wall, true, &load).is_err());
        let off = PairParams { off: true, ..pair() };
        assert!(interactions(Fluid, Wall, false, &off).unwrap().is_empty());
    }
}
