//! The boundary model a wall embeds (and, later, any body the fluid sees as a boundary):
//! dummy particles whose pressure and velocities are extrapolated from the fluid every step
//! (Adami, Hu & Adams 2012; CTVF sec. 3.6, eqs. 46-52), and the views of them the fluid's
//! terms read. The extrapolation itself, a loop over the fluid neighbours of each boundary
//! particle, is the boundary-fluid interaction
//! ([`boundary_fluid`](crate::solver::interactions::boundary_fluid)).

use crate::solver::equations::wall::Ghost;
use crate::solver::equations::Point;
use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};

/// The density a boundary particle presents to the fluid (its volume `m / rho` weighs every
/// boundary term).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum WallDensity {
    /// Through the linear state equation from the extrapolated pressure,
    /// `rho = rho0 + p / c0^2` (Adami et al. 2012): for a fluid whose pressure follows its
    /// density the same way.
    #[default]
    StateEquation,
    /// The reference density, as PySPH's EDAC scheme keeps its walls: with EDAC the
    /// pressure evolves by itself and its level says nothing of the density. With the
    /// state equation instead, the mean pressure EDAC accumulates in a closed box (0.17
    /// rho0 c0^2 in the cavity) makes the walls lighter than the fluid, and the fluid
    /// drifts onto them over tens of seconds (`problems/cavity.toml`).
    Reference,
}

named_choices!(WallDensity {
    StateEquation => "state_equation",
    Reference => "reference",
});

/// The pressure a boundary particle presents to the fluid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum WallPressure {
    /// Eq. (52) as it stands (Adami et al. 2012): negative where the fluid's is, so a wall
    /// next to fluid under tension pulls that fluid towards it.
    #[default]
    Extrapolated,
    /// Eq. (52) clamped at zero, as PySPH's `ClampWallPressure` does (an option of the CTVF
    /// authors' code, `--clamp-pressure`; the paper does not mention it): a wall pushes the
    /// fluid away or not at all, never pulls it in.
    NonNegative,
}

impl WallPressure {
    /// The boundary pressure from the extrapolated one, `p_w` of eq. (52).
    #[inline(always)]
    pub fn apply(self, p_w: f64) -> f64 {
        match self {
            Self::Extrapolated => p_w,
            Self::NonNegative => p_w.max(0.0),
        }
    }
}

named_choices!(WallPressure {
    Extrapolated => "extrapolated",
    NonNegative => "non_negative",
});

/// The velocity a boundary particle presents to the fluid's artificial viscosity (eqs.
/// 28-29). The paper uses the no-slip ghost velocity of eq. (50) for "the viscous force" and
/// does not say which its artificial viscosity takes; PySPH's walls and the authors' code
/// present the wall's own velocity there. Against a wall at rest the ghost velocity is the
/// fluid's mirrored, so the no-slip choice roughly doubles the damping of the normal
/// approach and adds friction to an inviscid flow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum WallViscosity {
    /// The no-slip ghost velocity of eq. (50), as the viscous terms.
    #[default]
    NoSlip,
    /// The wall's own velocity u_p (PySPH, the authors' code).
    Wall,
}

named_choices!(WallViscosity {
    NoSlip => "no_slip",
    Wall => "wall",
});

/// What a boundary particle presents once its values are extrapolated: its density, and
/// the views of it the divergence terms, the viscous terms and the artificial viscosity
/// read.
#[derive(Clone, Copy, Debug)]
pub struct Presented<const D: usize> {
    /// Density ([`WallDensity`]).
    pub rho: f64,
    /// With the slip velocities of eqs. (48)-(49).
    pub div: Point<D>,
    /// With the no-slip velocity of eq. (50).
    pub visc: Point<D>,
    /// With the velocity [`WallViscosity`] names.
    pub av: Point<D>,
}

/// The constants of a boundary's density and pressure models.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoundaryMaterial {
    /// Reference density.
    pub rho0: f64,
    /// Speed of sound of the state equation, for [`WallDensity::StateEquation`].
    pub c0: f64,
    /// How the density follows the extrapolated pressure.
    #[serde(default)]
    pub density: WallDensity,
    /// How the pressure follows the extrapolated one.
    #[serde(default)]
    pub pressure: WallPressure,
    /// The velocity the fluid's artificial viscosity sees.
    #[serde(default)]
    pub viscosity: WallViscosity,
}

impl BoundaryMaterial {
    /// The density at extrapolated pressure `p` ([`WallDensity`]).
    #[inline(always)]
    pub fn density_at(&self, p: f64) -> f64 {
        match self.density {
            WallDensity::StateEquation => self.rho0 + p / (self.c0 * self.c0),
            WallDensity::Reference => self.rho0,
        }
    }

    /// What a particle of mass `m` and velocity `u_p` presents once its extrapolated values
    /// `g` are known (with the pressure model applied).
    #[inline(always)]
    pub fn present<const D: usize>(&self, m: f64, u_p: Vector<D>, g: &Ghost<D>) -> Presented<D> {
        let rho = self.density_at(g.p);
        let visc = Point::new(g.u_noslip, g.u_noslip, m, rho, g.p);
        let av = match self.viscosity {
            WallViscosity::NoSlip => visc,
            WallViscosity::Wall => Point::new(u_p, u_p, m, rho, g.p),
        };
        Presented { rho, div: Point::new(g.u_slip, g.u_hat_slip, m, rho, g.p), visc, av }
    }
}

/// Dummy particles that present extrapolated values to a fluid: their masses, the
/// constants of their models, and, recomputed by every extrapolation, what they present.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BoundaryModel<const D: usize> {
    /// Masses (rho0 dx^D).
    pub m: Vec<f64>,
    /// The density and pressure models.
    pub material: BoundaryMaterial,
    /// Extrapolated values, eqs. (46)-(52): recomputed from the fluid before every use,
    /// so not part of a checkpoint.
    #[serde(skip)]
    pub ghost: Vec<Ghost<D>>,
    /// Densities from the extrapolated pressure ([`WallDensity`]).
    #[serde(skip)]
    pub rho: Vec<f64>,
    /// The particles as the fluid's divergence terms see them: the slip velocities of
    /// eqs. (48)-(49).
    #[serde(skip)]
    pub div: Vec<Point<D>>,
    /// The particles as the fluid's viscous terms see them: the no-slip velocity of eq. (50).
    #[serde(skip)]
    pub visc: Vec<Point<D>>,
    /// The particles as the fluid's artificial viscosity sees them ([`WallViscosity`]).
    #[serde(skip)]
    pub av: Vec<Point<D>>,
}

impl<const D: usize> BoundaryModel<D> {
    /// `n` particles of mass `mass`, density model constants `rho0` and `c0`, at rest and at
    /// zero pressure until the first extrapolation; errors say which constant is wrong.
    pub fn new(n: usize, mass: f64, rho0: f64, c0: f64) -> Result<Self, String> {
        if !(mass > 0.0 && rho0 > 0.0 && c0 > 0.0) {
            return Err(format!("mass {mass}, rho0 {rho0} and c0 {c0} must be positive"));
        }
        let material = BoundaryMaterial {
            rho0,
            c0,
            density: WallDensity::default(),
            pressure: WallPressure::default(),
            viscosity: WallViscosity::default(),
        };
        let mut model = Self {
            m: vec![mass; n],
            material,
            ghost: Vec::new(),
            rho: Vec::new(),
            div: Vec::new(),
            visc: Vec::new(),
            av: Vec::new(),
        };
        model.resize();
        Ok(model)
    }

    /// Room for every particle's extrapolated values (at rest and at zero pressure until
    /// extrapolated): after a checkpoint is read, which holds none.
    pub fn resize(&mut self) {
        let n = self.m.len();
        let rest =
            Ghost { p: 0.0, u_slip: Vector::zeros(), u_hat_slip: Vector::zeros(), u_noslip: Vector::zeros() };
        let at_rest = self.material.present(self.m.first().copied().unwrap_or(1.0), Vector::zeros(), &rest);
        self.ghost.resize(n, rest);
        self.rho.resize(n, at_rest.rho);
        self.div.resize(n, at_rest.div);
        self.visc.resize(n, at_rest.visc);
        self.av.resize(n, at_rest.av);
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.m.len()
    }

    /// Whether the model has no particles.
    pub fn is_empty(&self) -> bool {
        self.m.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_density_follows_the_pressure_or_stays_at_the_reference() {
        let mut b = BoundaryModel::<2>::new(1, 1e-3, 1000.0, 20.0).unwrap().material;
        assert_eq!(b.density_at(800.0), 1002.0, "rho0 + p / c0^2 by default");
        b.density = WallDensity::Reference;
        assert_eq!(b.density_at(800.0), 1000.0);
        for name in WallDensity::NAMES {
            assert!(WallDensity::from_name(name).is_some());
        }
        assert_eq!(WallDensity::from_name("heavy"), None);
        assert!(BoundaryModel::<2>::new(1, 0.0, 1000.0, 20.0).unwrap_err().contains("mass 0"));
    }

    /// The artificial viscosity sees the no-slip ghost velocity or the wall's own; the other
    /// views do not change with the choice.
    #[test]
    fn the_artificial_viscosity_sees_the_velocity_chosen() {
        let g = Ghost {
            p: 5.0,
            u_slip: Vector::<2>::new(1.0, 0.0),
            u_hat_slip: Vector::<2>::new(1.0, 0.1),
            u_noslip: Vector::<2>::new(-1.0, 0.5),
        };
        let mut material = BoundaryModel::<2>::new(1, 1e-3, 1000.0, 20.0).unwrap().material;
        let u_p = Vector::<2>::new(0.3, 0.0);
        let no_slip = material.present(1e-3, u_p, &g);
        assert_eq!(no_slip.av.u, g.u_noslip);
        material.viscosity = WallViscosity::Wall;
        let wall = material.present(1e-3, u_p, &g);
        assert_eq!((wall.av.u, wall.av.du), (u_p, Vector::zeros()));
        assert_eq!((wall.div.u, wall.visc.u, wall.rho), (no_slip.div.u, no_slip.visc.u, no_slip.rho));
    }

    #[test]
    fn a_non_negative_wall_pressure_never_pulls() {
        assert_eq!(WallPressure::Extrapolated.apply(-3.0), -3.0);
        assert_eq!(WallPressure::NonNegative.apply(-3.0), 0.0);
        assert_eq!(WallPressure::NonNegative.apply(2.5), 2.5);
        for name in WallPressure::NAMES {
            assert!(WallPressure::from_name(name).is_some());
        }
        assert_eq!(WallPressure::from_name("clamped"), None);
    }
}
