//! A wall body: ghost particles (three layers in the scenes) with a prescribed velocity and
//! a normal, whose pressure and velocities are extrapolated from the fluid every step
//! (Adami et al. 2012). Walls are not integrated and have no neighbour loop of their own
//! beyond that extrapolation.

use crate::solver::equations::wall::Ghost;
use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};

/// The density a wall particle presents to the fluid (its volume `m / rho` weighs every
/// wall term).
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
    /// drifts onto them over tens of seconds (measured: `problems/cavity.toml`).
    Reference,
}

named_choices!(WallDensity {
    StateEquation => "state_equation",
    Reference => "reference",
});

/// The pressure a wall particle presents to the fluid.
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
    /// The wall pressure from the extrapolated one, `p_w` of eq. (52).
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

/// State of one wall body (struct of arrays).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Wall<const D: usize> {
    /// Body name, used in output file names.
    pub name: String,
    /// Positions (fixed).
    pub x: Vec<Vector<D>>,
    /// Prescribed velocity u_p (a moving lid slides tangentially, its particles stay put).
    pub u_wall: Vec<Vector<D>>,
    /// Unit normal into the fluid.
    pub normal: Vec<Vector<D>>,
    /// Masses (rho0 dx^D).
    pub m: Vec<f64>,
    /// Reference density.
    pub rho0: f64,
    /// Speed of sound of the state equation, for [`WallDensity::StateEquation`].
    pub c0: f64,
    /// How the wall's density follows its extrapolated pressure (a scene sets it from its
    /// `wall_density` parameter).
    #[serde(default)]
    pub density: WallDensity,
    /// How the wall's pressure follows the extrapolated one (`wall_pressure` parameter).
    #[serde(default)]
    pub pressure: WallPressure,
    /// Extrapolated values, eqs. (46)-(52): recomputed from the fluid before every use,
    /// so not part of a checkpoint.
    #[serde(skip)]
    pub ghost: Vec<Ghost<D>>,
}

impl<const D: usize> Wall<D> {
    /// A wall from positions, velocities and normals; errors name the body and field.
    pub fn new(
        name: &str,
        x: Vec<Vector<D>>,
        u_wall: Vec<Vector<D>>,
        normal: Vec<Vector<D>>,
        mass: f64,
        rho0: f64,
        c0: f64,
    ) -> Result<Self, String> {
        let n = x.len();
        if u_wall.len() != n || normal.len() != n {
            return Err(format!(
                "wall `{name}`: {n} positions, {} velocities, {} normals",
                u_wall.len(),
                normal.len()
            ));
        }
        if !(mass > 0.0 && rho0 > 0.0 && c0 > 0.0) {
            return Err(format!("wall `{name}`: mass {mass}, rho0 {rho0} and c0 {c0} must be positive"));
        }
        if let Some(i) = normal.iter().position(|v| (v.norm() - 1.0).abs() > 1e-9) {
            return Err(format!("wall `{name}`: normal of particle {i} is not a unit vector"));
        }
        let ghost = u_wall.iter().map(|&u| Ghost { p: 0.0, u_slip: u, u_hat_slip: u, u_noslip: u }).collect();
        Ok(Self {
            name: name.into(),
            x,
            u_wall,
            normal,
            m: vec![mass; n],
            rho0,
            c0,
            density: WallDensity::default(),
            pressure: WallPressure::default(),
            ghost,
        })
    }

    /// The wall with its density and pressure models set.
    pub fn with_models(self, density: WallDensity, pressure: WallPressure) -> Self {
        Self { density, pressure, ..self }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the wall has no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Density of particle `i` (see [`WallDensity`]).
    #[inline(always)]
    pub fn rho(&self, i: usize) -> f64 {
        match self.density {
            WallDensity::StateEquation => self.rho0 + self.ghost[i].p / (self.c0 * self.c0),
            WallDensity::Reference => self.rho0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_density_follows_the_pressure_or_stays_at_the_reference() {
        let x = vec![Vector::<2>::zeros()];
        let n = vec![Vector::<2>::new(0.0, 1.0)];
        let mut w = Wall::new("w", x.clone(), x, n, 1e-3, 1000.0, 20.0).unwrap();
        w.ghost[0].p = 800.0;
        assert_eq!(w.rho(0), 1002.0, "rho0 + p / c0^2 by default");
        let w = w.with_models(WallDensity::Reference, WallPressure::Extrapolated);
        assert_eq!(w.rho(0), 1000.0);
        for name in WallDensity::NAMES {
            assert!(WallDensity::from_name(name).is_some());
        }
        assert_eq!(WallDensity::from_name("heavy"), None);
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
