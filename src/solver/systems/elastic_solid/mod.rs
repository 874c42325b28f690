//! An elastic solid body (CTVF sec. 2-3): positions, momentum velocity u, transport
//! velocity u~ (only when its scheme shifts), density, pressure from the state equation
//! (eq. 8), deviatoric stress sigma' and a `fixed` flag per particle; its material
//! ([`SolidMaterial`]: E, nu, rho0, giving K, c0 and G), its time-step limit (eq. 62) and
//! its kick-drift-kick updates (eqs. 54-60, with eq. 58 for the stress).
//!
//! **Clamps and pistons.** A clamped region is made of particles of the same body flagged
//! `fixed`: they take part in every sum as neighbours and their density, pressure and
//! deviatoric stress evolve by the same rates as the others' (a continuum held at its
//! prescribed velocity), but their accelerations and shifting are zero, so they keep the
//! velocity they were given: zero for a clamp, the piston's for a moving boundary
//! (sec. 4.5). This is the set-up of Gray et al. (2001), which the paper's oscillating
//! plate (sec. 4.4, fig. 17) follows; it needs no extrapolation of the stress onto a
//! separate boundary (eq. 53).
//!
//! **Frictionless platens.** A plane the body slides on without friction is made of fixed
//! particles that mirror the body's particles across it ([`MirrorPlane`], set by
//! [`ElasticSolid::with_mirror`]): after every drift and closing kick each ghost takes its
//! partner's state reflected.
//!
//! **Plasticity.** A material with a yield stress Y0 is elastic-perfectly plastic
//! (sec. 4.7): after every stress update the deviatoric stress is returned radially onto
//! the von Mises surface ([`radial_return`]).

mod mirror;
mod stages;

pub use mirror::{mirror_point, mirror_tensor, mirror_velocity, MirrorPlane};
pub use stages::{SolidStages, SolidWork};

use super::boundary::{BoundaryMaterial, BoundaryModel};
use crate::solver::equations::solid::radial_return;
use crate::solver::integrator;
use crate::solver::math::{Matrix, Vector};
use crate::solver::scheme::SolidScheme;
use serde::{Deserialize, Serialize};

/// The material of an elastic solid: Young's modulus, Poisson's ratio and reference
/// density, from which the bulk modulus, the speed of sound and the shear modulus follow.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolidMaterial {
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio nu.
    pub poisson_ratio: f64,
    /// Reference density rho0 (kg/m^3).
    pub rho0: f64,
    /// Yield stress Y0 (Pa) of an elastic-perfectly-plastic material (sec. 4.7); `None`:
    /// elastic.
    #[serde(default)]
    pub yield_stress: Option<f64>,
}

impl SolidMaterial {
    /// A material, refused (naming the quantity and its value) unless `E > 0`,
    /// `-1 < nu < 0.5` and `rho0 > 0`, all finite.
    pub fn new(youngs_modulus: f64, poisson_ratio: f64, rho0: f64) -> Result<Self, String> {
        if !(youngs_modulus > 0.0 && youngs_modulus.is_finite()) {
            return Err(format!("Young's modulus {youngs_modulus} must be positive"));
        }
        if !(poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(format!(
                "Poisson's ratio {poisson_ratio} must lie in (-1, 0.5): at 0.5 the bulk modulus is infinite, at -1 the shear modulus"
            ));
        }
        if !(rho0 > 0.0 && rho0.is_finite()) {
            return Err(format!("density {rho0} must be positive"));
        }
        Ok(Self { youngs_modulus, poisson_ratio, rho0, yield_stress: None })
    }

    /// The material made elastic-perfectly plastic with yield stress `y0`, refused unless
    /// positive and finite.
    pub fn with_yield_stress(self, y0: f64) -> Result<Self, String> {
        if !(y0 > 0.0 && y0.is_finite()) {
            return Err(format!("yield stress {y0} must be positive"));
        }
        Ok(Self { yield_stress: Some(y0), ..self })
    }

    /// The material of given bulk modulus `K` and shear modulus `G` (as papers that state a
    /// sound speed and a shear modulus give it, `K = rho0 c0^2`): `E = 9 K G / (3 K + G)`,
    /// `nu = (3 K - 2 G) / (2 (3 K + G))`.
    pub fn from_bulk_and_shear(bulk: f64, shear: f64, rho0: f64) -> Result<Self, String> {
        let e = 9.0 * bulk * shear / (3.0 * bulk + shear);
        let nu = (3.0 * bulk - 2.0 * shear) / (2.0 * (3.0 * bulk + shear));
        Self::new(e, nu, rho0)
    }

    /// Bulk modulus `K = E / (3 (1 - 2 nu)) = rho0 c0^2` (eq. 8 and the text below it).
    pub fn bulk_modulus(&self) -> f64 {
        self.youngs_modulus / (3.0 * (1.0 - 2.0 * self.poisson_ratio))
    }

    /// Speed of sound `c0 = sqrt(E / (3 (1 - 2 nu) rho0))` (the text below eq. 8).
    pub fn c0(&self) -> f64 {
        (self.bulk_modulus() / self.rho0).sqrt()
    }

    /// Shear modulus `G = E / (2 (1 + nu))` (eq. 4).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// The state equation (8): `p = K (rho / rho0 - 1)`.
    #[inline(always)]
    pub fn pressure(&self, rho: f64) -> f64 {
        self.bulk_modulus() * (rho / self.rho0 - 1.0)
    }
}

/// Initial values for a solid body, one entry per particle.
#[derive(Clone, Debug, Default)]
pub struct SolidInit<const D: usize> {
    /// Positions.
    pub x: Vec<Vector<D>>,
    /// Velocities.
    pub u: Vec<Vector<D>>,
    /// Masses.
    pub m: Vec<f64>,
    /// Densities.
    pub rho: Vec<f64>,
    /// Moved at its initial velocity whatever the forces (a clamp at rest, a piston).
    pub fixed: Vec<bool>,
}

/// State of one elastic solid (struct of arrays), in the order its particles were given.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ElasticSolid<const D: usize> {
    /// Body name.
    pub name: String,
    /// Smoothing length.
    pub h: f64,
    /// The material.
    pub material: SolidMaterial,
    /// Its equations.
    pub physics: SolidScheme,
    /// Positions.
    pub x: Vec<Vector<D>>,
    /// Momentum velocity u.
    pub u: Vec<Vector<D>>,
    /// Transport velocity u~ (eq. 33): only when the scheme shifts (Sun or IPST).
    pub u_hat: Option<Vec<Vector<D>>>,
    /// Masses.
    pub m: Vec<f64>,
    /// Densities.
    pub rho: Vec<f64>,
    /// Pressures (eq. 8).
    pub p: Vec<f64>,
    /// Deviatoric stress sigma' (symmetric).
    pub s: Vec<Matrix<D>>,
    /// Moved at the velocity it was given (a clamp, a piston): zero acceleration and
    /// shifting.
    pub fixed: Vec<bool>,
    /// What the particles present to a fluid they meet (a structure in water): dummy
    /// particles of the fluid's density whose pressure is extrapolated from the fluid
    /// (thesis sec. 4.2.4, eq. 4.14); `None` for a solid no fluid sees.
    #[serde(default)]
    pub boundary: Option<BoundaryModel<D>>,
    /// Planes the body slides on without friction, their ghosts mirroring the body.
    #[serde(default)]
    pub mirrors: Vec<MirrorPlane>,
}

/// Time derivatives of a solid body, owned by the simulation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolidRates<const D: usize> {
    /// du/dt (eq. 30); zero for fixed particles.
    pub du: Vec<Vector<D>>,
    /// d rho/dt (eq. 25).
    pub drho: Vec<f64>,
    /// d sigma'/dt (eq. 32).
    pub ds: Vec<Matrix<D>>,
    /// Homogenisation acceleration (du/dt)_c (eq. 36), when the scheme shifts.
    pub a_c: Vec<Vector<D>>,
    /// The step eq. (36) divided (du/dt)_c by (see
    /// [`FluidRates::a_c_dt`](super::FluidRates::a_c_dt)).
    pub a_c_dt: Option<f64>,
    /// The external acceleration computed at a slower clock than the body's and held over
    /// its sub-steps: the fluid's force on a structure per unit mass, F_FSI / m of eq. (4.6)
    /// (the opposite of eq. 4.15); empty for a solid no fluid acts on (see
    /// [`simulation`](crate::solver::simulation), *Clocks*).
    #[serde(default, alias = "a_fsi")]
    pub a_held: Vec<Vector<D>>,
    /// The external acceleration at the last evaluation, included in `du`: the held one plus
    /// what the couplings at the body's own clock added (a load); empty for a solid that
    /// none acts on.
    #[serde(skip)]
    pub a_ext: Vec<Vector<D>>,
}

impl<const D: usize> SolidRates<D> {
    /// Zeroed rates for the particles of `solid` (the shifting only if it shifts).
    pub fn of(solid: &ElasticSolid<D>) -> Self {
        let n = solid.len();
        Self {
            du: vec![Vector::zeros(); n],
            drho: vec![0.0; n],
            ds: vec![Matrix::zeros(); n],
            a_c: if solid.physics.transports() { vec![Vector::zeros(); n] } else { Vec::new() },
            a_c_dt: None,
            a_held: if solid.boundary.is_some() { vec![Vector::zeros(); n] } else { Vec::new() },
            a_ext: Vec::new(),
        }
    }
}

impl<const D: usize> ElasticSolid<D> {
    /// A solid body from initial values, stress free, its pressure from the state equation.
    /// Errors name the body and the offending field.
    pub fn new(
        name: &str,
        h: f64,
        init: SolidInit<D>,
        material: SolidMaterial,
        physics: SolidScheme,
    ) -> Result<Self, String> {
        let n = init.x.len();
        super::check_init(
            ("solid", name),
            n,
            h,
            &[("u", init.u.len()), ("m", init.m.len()), ("rho", init.rho.len()), ("fixed", init.fixed.len())],
            &init.m,
            &init.rho,
        )?;
        let u = init.u;
        let u_hat = physics.transports().then(|| u.clone());
        let p = init.rho.iter().map(|&r| material.pressure(r)).collect();
        Ok(Self {
            name: name.into(),
            h,
            material,
            physics,
            x: init.x,
            u,
            u_hat,
            m: init.m,
            rho: init.rho,
            p,
            s: vec![Matrix::zeros(); n],
            fixed: init.fixed,
            boundary: None,
            mirrors: Vec::new(),
        })
    }

    /// The body with a frictionless plane whose ghosts (fixed particles) mirror their
    /// partners (free ones); the ghosts take their partners' state at once. Errors name the
    /// body and the offending pair.
    pub fn with_mirror(mut self, plane: MirrorPlane) -> Result<Self, String> {
        plane.check(self.len(), &self.fixed).map_err(|e| format!("solid `{}`: {e}", self.name))?;
        self.mirrors.push(plane);
        self.apply_mirrors();
        Ok(self)
    }

    /// Every ghost of every mirror plane takes its partner's position, velocities, density,
    /// pressure and deviatoric stress, reflected across the plane.
    fn apply_mirrors(&mut self) {
        for plane in &self.mirrors {
            let (axis, at, v) = (plane.axis, plane.position, plane.velocity);
            for &(g, p) in &plane.pairs {
                let (g, p) = (g as usize, p as usize);
                self.x[g] = mirror_point(self.x[p], axis, at);
                self.u[g] = mirror_velocity(self.u[p], axis, v);
                if let Some(uh) = self.u_hat.as_mut() {
                    uh[g] = self.u[g];
                }
                self.rho[g] = self.rho[p];
                self.p[g] = self.p[p];
                self.s[g] = mirror_tensor(&self.s[p], axis);
            }
        }
    }

    /// The solid as a structure a fluid meets (thesis sec. 4.2.4): its particles present
    /// themselves to the fluid as boundary particles of `material` (the fluid's reference
    /// density and sound speed, and the wall models of the scene), each of mass
    /// `rho0_fluid V` for its volume `V = m / rho`, as the thesis's code sets them, so that
    /// the fluid sees a boundary of its own density.
    pub fn facing_fluid(mut self, material: BoundaryMaterial) -> Result<Self, String> {
        let mut model = BoundaryModel::new(self.len(), 1.0, material.rho0, material.c0)
            .map_err(|e| format!("solid `{}`: {e}", self.name))?;
        model.material = material;
        model.m = self.m.iter().zip(&self.rho).map(|(m, rho)| material.rho0 * m / rho).collect();
        model.resize();
        self.boundary = Some(model);
        Ok(self)
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Keeps the particles `keep` marks, in their order. Errors for a structure a fluid
    /// reads (its boundary values are sized once).
    pub fn retain(&mut self, keep: &[bool]) -> Result<(), String> {
        use super::retain_by;
        if self.boundary.is_some() || !self.mirrors.is_empty() {
            return Err(format!(
                "solid `{}`: a structure a fluid reads, or a body with mirror planes, keeps its particles",
                self.name
            ));
        }
        retain_by(&mut self.x, keep);
        retain_by(&mut self.u, keep);
        if let Some(uh) = self.u_hat.as_mut() {
            retain_by(uh, keep);
        }
        retain_by(&mut self.m, keep);
        retain_by(&mut self.rho, keep);
        retain_by(&mut self.p, keep);
        retain_by(&mut self.s, keep);
        retain_by(&mut self.fixed, keep);
        Ok(())
    }

    /// Appends the particles of `more`, a solid of the same material, scheme and smoothing
    /// length (as built). Errors as [`retain`](Self::retain), and for another material.
    pub fn extend(&mut self, more: ElasticSolid<D>) -> Result<(), String> {
        if self.boundary.is_some() || !self.mirrors.is_empty() {
            return Err(format!(
                "solid `{}`: a structure a fluid reads, or a body with mirror planes, keeps its particles",
                self.name
            ));
        }
        if more.material != self.material || more.h != self.h || more.physics.name != self.physics.name {
            return Err(format!(
                "solid `{}` differs from solid `{}` in its material, scheme or smoothing length",
                more.name, self.name
            ));
        }
        self.x.extend(more.x);
        self.u.extend(more.u);
        if let (Some(mine), Some(theirs)) = (self.u_hat.as_mut(), more.u_hat) {
            mine.extend(theirs);
        }
        self.m.extend(more.m);
        self.rho.extend(more.rho);
        self.p.extend(more.p);
        self.s.extend(more.s);
        self.fixed.extend(more.fixed);
        Ok(())
    }

    /// Whether the body has no particles (never true for a constructed body).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The transport velocity if declared, else the momentum velocity.
    pub fn u_hat(&self) -> &[Vector<D>] {
        self.u_hat.as_deref().unwrap_or(&self.u)
    }

    /// Largest particle speed |u|.
    pub fn max_speed(&self) -> f64 {
        self.u.iter().map(|u| u.norm_squared()).fold(0.0, f64::max).sqrt()
    }

    /// The time-step limit of eq. (62), `cfl h / (c0 + |u|_max)` (the paper's factor is
    /// 0.25), with the body's own largest speed.
    pub fn dt_limit(&self, cfl: f64) -> f64 {
        cfl * self.h / (self.material.c0() + self.max_speed())
    }

    /// The opening half kick (eq. 54) and the transport velocity (eq. 55). Fixed
    /// particles have zero rates, so they stay at rest.
    pub fn kick_open(&mut self, r: &SolidRates<D>, dt: f64) {
        integrator::kick_transport(&mut self.u, self.u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
    }

    /// The update of density, pressure and deviatoric stress over `dt` (eqs. 56, 8, 58)
    /// by rates evaluated at the start of the step with the half-step velocities (sec. 3.7),
    /// the stress returned onto the yield surface if the material is plastic (sec. 4.7).
    pub fn update_state(&mut self, r: &SolidRates<D>, dt: f64) {
        let material = self.material;
        for ((rho, p), drho) in self.rho.iter_mut().zip(&mut self.p).zip(&r.drho) {
            *rho += dt * drho;
            *p = material.pressure(*rho);
        }
        for (s, ds) in self.s.iter_mut().zip(&r.ds) {
            *s += ds * dt;
            if let Some(y0) = material.yield_stress {
                *s = radial_return(s, y0);
            }
        }
    }

    /// The drift of eq. (59), with the transport velocity if there is one; mirror planes
    /// move with it and their ghosts follow their partners.
    pub fn drift(&mut self, dt: f64) {
        integrator::drift(&mut self.x, self.u_hat.as_deref().unwrap_or(&self.u), dt);
        if !self.mirrors.is_empty() {
            self.mirrors.iter_mut().for_each(|m| m.advance(dt));
            self.apply_mirrors();
        }
    }

    /// The closing half kick (eq. 60); the ghosts of mirror planes follow their partners.
    pub fn kick_close(&mut self, r: &SolidRates<D>, dt: f64) {
        integrator::kick(&mut self.u, &r.du, dt);
        if !self.mirrors.is_empty() {
            self.apply_mirrors();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::scheme::{Pst, SolidSchemeName, SolidSettings};

    fn physics() -> SolidScheme {
        SolidSchemeName::Ctvf.solid_scheme(&SolidSettings::for_tests(Pst::Sun, 1.0)).unwrap()
    }

    /// The oscillating plate's material (CTVF sec. 4.4): c0 = sqrt(E / (3 (1 - 2 nu) rho0)).
    #[test]
    fn material_constants() {
        let m = SolidMaterial::new(2.0e6, 0.3975, 1000.0).unwrap();
        let k = 2.0e6 / (3.0 * (1.0 - 0.795));
        assert!((m.bulk_modulus() - k).abs() < 1e-9 * k);
        assert!((m.c0() - (k / 1000.0).sqrt()).abs() < 1e-12);
        assert!((m.c0() - 57.03).abs() < 0.01, "{}", m.c0());
        assert!((m.shear_modulus() - 2.0e6 / 2.795).abs() < 1e-6);
        assert_eq!(m.pressure(1000.0), 0.0);
        assert!(m.pressure(1001.0) > 0.0, "compression raises the pressure");
        assert!(SolidMaterial::new(1.0, 0.5, 1.0).unwrap_err().contains("Poisson's ratio 0.5"));
        assert!(SolidMaterial::new(0.0, 0.3, 1.0).unwrap_err().contains("Young's modulus 0"));
        assert!(SolidMaterial::new(1.0, 0.3, -1.0).unwrap_err().contains("density -1"));
    }

    #[test]
    fn fixed_particles_keep_their_velocity_and_fields_follow_the_scheme() {
        let init = SolidInit {
            x: vec![Vector::<2>::zeros(), Vector::<2>::new(1.0, 0.0)],
            u: vec![Vector::<2>::new(1.0, 0.0); 2],
            m: vec![1.0; 2],
            rho: vec![1000.0; 2],
            fixed: vec![true, false],
        };
        let s =
            ElasticSolid::new("plate", 0.1, init, SolidMaterial::new(1.0, 0.3, 1000.0).unwrap(), physics())
                .unwrap();
        assert_eq!(s.u, vec![Vector::<2>::new(1.0, 0.0); 2]);
        assert_eq!(s.u_hat.as_ref().unwrap().len(), 2);
        let bad = SolidInit { fixed: vec![false], ..SolidInit::<2>::default() };
        assert!(ElasticSolid::new("plate", 0.1, bad, s.material, physics())
            .unwrap_err()
            .contains("no particles"));
    }
}
