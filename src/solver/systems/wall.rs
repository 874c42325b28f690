//! A wall body: layers of dummy particles (three in the scenes) with a normal and a
//! prescribed motion, presenting pressures and velocities extrapolated from the fluid
//! through the [`BoundaryModel`] they embed (Adami et al. 2012). A wall is not integrated:
//! it sets no time-step limit, and its kicks and drift follow its prescribed motion.

use super::boundary::BoundaryModel;
use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};

/// How a wall moves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum WallMotion<const D: usize> {
    /// The particles stay put; the wall's surface slides with a velocity per particle
    /// (a lid; zero for a fixed wall). Eqs. (48)-(49) then see no normal wall velocity.
    Sliding {
        /// The surface velocity u_p of each particle.
        u: Vec<Vector<D>>,
    },
    /// The whole wall translates with a uniform velocity that changes at a constant
    /// acceleration (a piston, a tank shaken or accelerated): the acceleration enters the
    /// extrapolated pressure of eq. (52).
    Translating {
        /// The current velocity.
        velocity: Vector<D>,
        /// The constant acceleration a_w.
        acceleration: Vector<D>,
    },
}

/// State of one wall body (struct of arrays).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Wall<const D: usize> {
    /// Body name, used in output file names.
    pub name: String,
    /// Positions.
    pub x: Vec<Vector<D>>,
    /// Unit normal into the fluid.
    pub normal: Vec<Vector<D>>,
    /// The prescribed motion.
    pub motion: WallMotion<D>,
    /// The dummy particles' masses, density model and extrapolated values.
    pub boundary: BoundaryModel<D>,
}

impl<const D: usize> Wall<D> {
    /// A wall from positions, surface velocities (see [`WallMotion::Sliding`]) and normals,
    /// with particles of mass `mass` and the density model's `rho0` and `c0`; errors name the
    /// body and field.
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
        if let Some(i) = normal.iter().position(|v| (v.norm() - 1.0).abs() > 1e-9) {
            return Err(format!("wall `{name}`: normal of particle {i} is not a unit vector"));
        }
        let boundary = BoundaryModel::new(n, mass, rho0, c0).map_err(|e| format!("wall `{name}`: {e}"))?;
        Ok(Self { name: name.into(), x, normal, motion: WallMotion::Sliding { u: u_wall }, boundary })
    }

    /// The wall with its density, pressure and artificial-viscosity models set.
    pub fn with_models(
        mut self,
        density: super::WallDensity,
        pressure: super::WallPressure,
        viscosity: super::WallViscosity,
    ) -> Self {
        let m = &mut self.boundary.material;
        (m.density, m.pressure, m.viscosity) = (density, pressure, viscosity);
        self
    }

    /// The wall translating with initial velocity `velocity` and constant `acceleration`
    /// instead of sliding.
    pub fn translating(mut self, velocity: Vector<D>, acceleration: Vector<D>) -> Self {
        self.motion = WallMotion::Translating { velocity, acceleration };
        self
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the wall has no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Whether the particles move (a translating wall's do; a sliding wall's stay put).
    pub fn moves(&self) -> bool {
        matches!(self.motion, WallMotion::Translating { .. })
    }

    /// The velocity of particle `i`: its surface's for a sliding wall, the wall's for a
    /// translating one.
    #[inline(always)]
    pub fn velocity(&self, i: usize) -> Vector<D> {
        match &self.motion {
            WallMotion::Sliding { u } => u[i],
            WallMotion::Translating { velocity, .. } => *velocity,
        }
    }

    /// Half a kick of the prescribed motion over `dt`: the velocity changes by `a dt / 2`
    /// (exact for a constant acceleration, in the kick-drift-kick of eqs. 54-60).
    pub fn half_kick(&mut self, dt: f64) {
        if let WallMotion::Translating { velocity, acceleration } = &mut self.motion {
            *velocity += *acceleration * (0.5 * dt);
        }
    }

    /// The drift over `dt` with the velocity of the half step.
    pub fn drift(&mut self, dt: f64) {
        if let WallMotion::Translating { velocity, .. } = self.motion {
            let dx = velocity * dt;
            self.x.iter_mut().for_each(|x| *x += dx);
        }
    }
}

/// The stages of a [`Wall`]: it moves as prescribed, and is binned again when it does.
pub struct WallStages;

impl<const D: usize> super::BodyStages<D> for WallStages {
    fn rebin(&self, w: &mut super::World<D>, i: usize) {
        let wall = w.bodies[i].as_wall().expect("a wall");
        if wall.moves() {
            w.bins[i].update(&wall.x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kick, drift and kick move a translating wall as `x + v t + a t^2 / 2` (exactly, up
    /// to rounding, for a constant acceleration) and leave a sliding one in place.
    #[test]
    fn a_translating_wall_follows_its_acceleration() {
        let one = |x: f64, y: f64| vec![Vector::<2>::new(x, y)];
        let up = Vector::<2>::new(0.0, 1.0);
        let wall = Wall::new("w", one(0.0, 0.0), one(0.0, 0.0), vec![up], 1e-3, 1000.0, 20.0).unwrap();
        let mut moving = wall.clone().translating(Vector::<2>::new(0.5, 0.0), Vector::<2>::new(0.0, 2.0));
        let mut still = wall;
        let dt = 0.01;
        for _ in 0..100 {
            for w in [&mut moving, &mut still] {
                w.half_kick(dt);
                w.drift(dt);
                w.half_kick(dt);
            }
        }
        let t = 1.0;
        assert!((moving.x[0] - Vector::<2>::new(0.5 * t, t * t)).norm() < 1e-12, "{:?}", moving.x[0]);
        assert!((moving.velocity(0) - Vector::<2>::new(0.5, 2.0 * t)).norm() < 1e-12);
        assert_eq!(still.x[0], Vector::<2>::zeros());
        assert!(moving.moves() && !still.moves());
    }

    #[test]
    fn invalid_walls_name_body_and_field() {
        let x = vec![Vector::<2>::zeros()];
        let bent = vec![Vector::<2>::new(1.0, 1.0)];
        assert!(Wall::new("w", x.clone(), x.clone(), bent, 1.0, 1.0, 1.0)
            .unwrap_err()
            .contains("not a unit"));
        let up = vec![Vector::<2>::new(0.0, 1.0)];
        assert!(Wall::new("w", x.clone(), x, up, -1.0, 1.0, 1.0)
            .unwrap_err()
            .starts_with("wall `w`: mass -1"));
    }
}
