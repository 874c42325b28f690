//! A fluid body: positions, velocities, mass, density, pressure, and the transport
//! velocity only when the scheme moves particles with one.

use super::permute;
use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};

/// Initial values for a fluid body, one entry per particle.
#[derive(Clone, Debug, Default)]
pub struct FluidInit<const D: usize> {
    /// Positions.
    pub x: Vec<Vector<D>>,
    /// Velocities.
    pub u: Vec<Vector<D>>,
    /// Masses.
    pub m: Vec<f64>,
    /// Densities.
    pub rho: Vec<f64>,
    /// Pressures.
    pub p: Vec<f64>,
}

/// State of one fluid body (struct of arrays). Particles are kept sorted by neighbour-search
/// cell; `id` remembers each particle's original index for output.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fluid<const D: usize> {
    /// Body name, used in output file names.
    pub name: String,
    /// Smoothing length (uniform within a body).
    pub h: f64,
    /// Positions.
    pub x: Vec<Vector<D>>,
    /// Momentum velocity u.
    pub u: Vec<Vector<D>>,
    /// Transport velocity u~ (CTVF eq. 33): present only when the scheme declares transport.
    pub u_hat: Option<Vec<Vector<D>>>,
    /// Masses.
    pub m: Vec<f64>,
    /// Densities.
    pub rho: Vec<f64>,
    /// Pressures.
    pub p: Vec<f64>,
    /// Original particle index.
    pub id: Vec<u32>,
    #[serde(skip)]
    scratch_v: Vec<Vector<D>>,
    #[serde(skip)]
    scratch_s: Vec<f64>,
    #[serde(skip)]
    scratch_id: Vec<u32>,
}

/// Time derivatives of a fluid body, owned by the simulation (not the body) so that a pass
/// borrows the bodies immutably and one rate set mutably.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FluidRates<const D: usize> {
    /// du/dt (CTVF eq. 27).
    pub du: Vec<Vector<D>>,
    /// dp/dt (CTVF eq. 26), when the pressure is evolved.
    pub dp: Vec<f64>,
    /// d rho/dt (CTVF eq. 25), when the density is evolved.
    pub drho: Vec<f64>,
    /// Homogenisation acceleration (du/dt)_c (CTVF eqs. 36, 41), when the scheme shifts.
    pub a_c: Vec<Vector<D>>,
    /// The step that eq. (36) or (41) divided (du/dt)_c by, for a shifting technique
    /// (`None` for a background pressure, a true acceleration). The kick sets
    /// `u~ = u + dt_c/2 (du/dt)_c` with this `dt_c` (eq. 55), so that a step shorter than
    /// the one it was evaluated for (the last before an end time, or one after the speed
    /// grew) moves the particles with the shifting velocity the technique computed, for its
    /// own length.
    #[serde(default)]
    pub a_c_dt: Option<f64>,
}

impl<const D: usize> FluidRates<D> {
    /// Zeroed rates for `n` particles; the optional sets are empty when not declared.
    pub fn new(n: usize, pressure: bool, density: bool, transport: bool) -> Self {
        Self {
            du: vec![Vector::zeros(); n],
            dp: if pressure { vec![0.0; n] } else { Vec::new() },
            drho: if density { vec![0.0; n] } else { Vec::new() },
            a_c: if transport { vec![Vector::zeros(); n] } else { Vec::new() },
            a_c_dt: None,
        }
    }
}

impl<const D: usize> Fluid<D> {
    /// A fluid body from initial values. `transport` allocates the transport velocity.
    /// Errors name the body and the offending field.
    pub fn new(name: &str, h: f64, init: FluidInit<D>, transport: bool) -> Result<Self, String> {
        let n = init.x.len();
        if n == 0 {
            return Err(format!("fluid `{name}`: no particles"));
        }
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!("fluid `{name}`: smoothing length h = {h} must be positive"));
        }
        for (field, len) in
            [("u", init.u.len()), ("m", init.m.len()), ("rho", init.rho.len()), ("p", init.p.len())]
        {
            if len != n {
                return Err(format!("fluid `{name}`: {field} has {len} entries for {n} particles"));
            }
        }
        // `!(v > 0.0)` also rejects NaN.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if let Some(i) = init.m.iter().position(|&m| !(m > 0.0)) {
            return Err(format!("fluid `{name}`: particle {i} has non-positive mass {}", init.m[i]));
        }
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if let Some(i) = init.rho.iter().position(|&r| !(r > 0.0)) {
            return Err(format!("fluid `{name}`: particle {i} has non-positive density {}", init.rho[i]));
        }
        let u_hat = transport.then(|| init.u.clone());
        Ok(Self {
            name: name.into(),
            h,
            x: init.x,
            u: init.u,
            u_hat,
            m: init.m,
            rho: init.rho,
            p: init.p,
            id: (0..n as u32).collect(),
            scratch_v: Vec::new(),
            scratch_s: Vec::new(),
            scratch_id: Vec::new(),
        })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the body has no particles (never true for a constructed body).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The transport velocity if declared, else the momentum velocity (u~ = u without
    /// shifting, so every term may read `u_hat()`).
    pub fn u_hat(&self) -> &[Vector<D>] {
        self.u_hat.as_deref().unwrap_or(&self.u)
    }

    /// Reorders every per-particle field by `order` (see `CellList::order`).
    pub fn reorder(&mut self, order: &[u32]) {
        permute(&mut self.x, order, &mut self.scratch_v);
        permute(&mut self.u, order, &mut self.scratch_v);
        if let Some(uh) = self.u_hat.as_mut() {
            permute(uh, order, &mut self.scratch_v);
        }
        permute(&mut self.m, order, &mut self.scratch_s);
        permute(&mut self.rho, order, &mut self.scratch_s);
        permute(&mut self.p, order, &mut self.scratch_s);
        permute(&mut self.id, order, &mut self.scratch_id);
    }

    /// Values indexed by original particle id (for output that must not depend on the
    /// internal ordering).
    pub fn by_id<T: Copy + Default>(&self, v: &[T]) -> Vec<T> {
        let mut out = vec![T::default(); v.len()];
        for (k, &i) in self.id.iter().enumerate() {
            out[i as usize] = v[k];
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn init(n: usize) -> FluidInit<2> {
        FluidInit {
            x: (0..n).map(|i| Vector::<2>::new(i as f64, 0.0)).collect(),
            u: vec![Vector::zeros(); n],
            m: vec![1.0; n],
            rho: vec![1.0; n],
            p: vec![0.0; n],
        }
    }

    #[test]
    fn invalid_declarations_name_body_and_field() {
        let mut i = init(3);
        i.m[1] = 0.0;
        assert_eq!(
            Fluid::new("water", 0.1, i, false).unwrap_err(),
            "fluid `water`: particle 1 has non-positive mass 0"
        );
        let mut i = init(3);
        i.p.pop();
        assert_eq!(
            Fluid::new("water", 0.1, i, false).unwrap_err(),
            "fluid `water`: p has 2 entries for 3 particles"
        );
        assert!(Fluid::new("water", -1.0, init(3), false).unwrap_err().contains("h = -1"));
    }

    #[test]
    fn transport_velocity_is_allocated_only_when_declared() {
        assert!(Fluid::new("f", 0.1, init(4), false).unwrap().u_hat.is_none());
        assert_eq!(Fluid::new("f", 0.1, init(4), true).unwrap().u_hat.unwrap().len(), 4);
    }

    #[test]
    fn reorder_moves_every_field_and_keeps_ids() {
        let mut f = Fluid::new("f", 0.1, init(4), true).unwrap();
        f.p = vec![10.0, 11.0, 12.0, 13.0];
        f.reorder(&[2, 0, 3, 1]);
        assert_eq!(f.p, vec![12.0, 10.0, 13.0, 11.0]);
        assert_eq!(f.id, vec![2, 0, 3, 1]);
        assert_eq!(f.x[0][0], 2.0);
        assert_eq!(f.by_id(&f.p), vec![10.0, 11.0, 12.0, 13.0]);
    }
}
