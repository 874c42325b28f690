//! A wall body: ghost particles (three layers in the scenes) with a prescribed velocity and
//! a normal, whose pressure and velocities are extrapolated from the fluid every step
//! (Adami et al. 2012). Walls are not integrated and have no neighbour loop of their own
//! beyond that extrapolation.

use crate::solver::equations::wall::Ghost;
use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};

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
    /// Reference density: the wall density follows the extrapolated pressure through the
    /// linear state equation, `rho = rho0 + p / c0^2` (Adami et al. 2012).
    pub rho0: f64,
    /// Speed of sound of that state equation.
    pub c0: f64,
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
        Ok(Self { name: name.into(), x, u_wall, normal, m: vec![mass; n], rho0, c0, ghost })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the wall has no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Density of particle `i` from its extrapolated pressure.
    #[inline(always)]
    pub fn rho(&self, i: usize) -> f64 {
        self.rho0 + self.ghost[i].p / (self.c0 * self.c0)
    }
}
