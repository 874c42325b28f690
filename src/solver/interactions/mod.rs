//! Who acts on whom, decided in one place: [`interaction`] is one exhaustive `match` over
//! pairs of [`BodyKind`]s, so that a new kind of body does not compile until every pair
//! with it is decided. Each interaction is a module of its own, holding its neighbour
//! lists and what a particle gathers from a neighbour across it; the passes
//! ([`passes`](crate::solver::passes)) call those per-neighbour functions inside their
//! particle loops, chosen outside them, so the loops stay monomorphic.
//!
//! - [`fluid_fluid`]: a fluid's particles among themselves, CTVF eqs. (25)-(27);
//! - [`fluid_boundary`]: a fluid reading a boundary's extrapolated values as neighbours;
//! - [`boundary_fluid`]: a boundary extrapolating its values from a fluid (eqs. 46-52);
//! - [`solid_solid`]: an elastic solid's particles among themselves, eqs. (25), (30)-(32);
//! - [`structure_fluid`]: an elastic solid in a fluid, extrapolating its pressure from the
//!   fluid (thesis eq. 4.14) and taking the reaction of the fluid's pair force (eq. 4.15);
//!   the fluid reads it as a boundary ([`fluid_boundary`]);
//! - [`lists`]: the neighbour lists with their kernel values, shared by all of them.
//!
//! Reactions stay deterministic without atomics: every pass is a gather, each particle
//! writing only its own row, in a neighbour order fixed by the lists.

pub mod boundary_fluid;
pub mod fluid_boundary;
pub mod fluid_fluid;
pub mod lists;
pub mod solid_solid;
pub mod structure_fluid;

use crate::solver::systems::BodyKind;

/// What one body does with another's particles.
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
    /// A structure (an elastic solid) in a fluid: it extrapolates its pressure from the
    /// fluid (thesis eq. 4.14) and takes the reaction of the fluid's pair force (eq. 4.15)
    /// ([`structure_fluid`]).
    StructureFluid,
}

/// How body kind `dst` is acted on by body kind `src` (`None`: not at all). For two bodies
/// of one kind this is also the interaction of a body with itself.
pub fn interaction(dst: BodyKind, src: BodyKind) -> Option<Interaction> {
    use BodyKind::{ElasticSolid, Fluid, Wall};
    match (dst, src) {
        (Fluid, Fluid) => Some(Interaction::FluidFluid),
        (Fluid, Wall) => Some(Interaction::FluidBoundary),
        (Wall, Fluid) => Some(Interaction::BoundaryFluid),
        // Walls neither move by forces nor present values to each other.
        (Wall, Wall) => None,
        // Within one solid (the simulation pairs a solid only with itself: contact between
        // two solid bodies is not modelled yet, so two solids pass through each other).
        (ElasticSolid, ElasticSolid) => Some(Interaction::SolidSolid),
        // Fluid-structure interaction (thesis sec. 4.2.4): the fluid reads the structure
        // as a boundary, the structure takes the opposite of the fluid's pair force.
        (Fluid, ElasticSolid) => Some(Interaction::FluidBoundary),
        (ElasticSolid, Fluid) => Some(Interaction::StructureFluid),
        // Solid-wall contact is a later stage too (a clamp is made of the solid's own fixed
        // particles, see `systems::elastic_solid`).
        (ElasticSolid, Wall) | (Wall, ElasticSolid) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn who_acts_on_whom() {
        use BodyKind::{Fluid, Wall};
        assert_eq!(interaction(Fluid, Fluid), Some(Interaction::FluidFluid));
        assert_eq!(interaction(Fluid, Wall), Some(Interaction::FluidBoundary));
        assert_eq!(interaction(Wall, Fluid), Some(Interaction::BoundaryFluid));
        assert_eq!(interaction(Wall, Wall), None);
        use BodyKind::ElasticSolid;
        assert_eq!(interaction(ElasticSolid, ElasticSolid), Some(Interaction::SolidSolid));
        assert_eq!((interaction(ElasticSolid, Wall), interaction(Wall, ElasticSolid)), (None, None));
        assert_eq!(interaction(Fluid, ElasticSolid), Some(Interaction::FluidBoundary));
        assert_eq!(interaction(ElasticSolid, Fluid), Some(Interaction::StructureFluid));
    }
}
