//! An applied load: a uniform acceleration on a range of a body's particles, by their index as
//! the scene gave them (a solid's order, never changed; a fluid's original ids, as it sorts its
//! particles by cell), added into the body's external acceleration at every evaluation of its
//! accelerations. A surface traction t (N/m^2 in 3D, N/m per unit
//! depth in 2D) on a face is `accel = t dx / (rho0 dx^D)` on the row of particles along it.
//! Fixed particles in the range get nothing, as they get no gravity: their motion is
//! prescribed.

use crate::solver::math::Vector;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// A uniform acceleration on the particles of a range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UniformLoad {
    /// Acceleration (m/s^2; the components beyond the dimension are unused).
    pub accel: [f64; 3],
    /// The particles loaded.
    pub particles: Range<usize>,
}

impl UniformLoad {
    /// `accel` on the particles `particles`.
    pub fn new(accel: [f64; 3], particles: Range<usize>) -> Self {
        Self { accel, particles }
    }

    /// Refuses a load that is not finite.
    pub fn check(&self) -> Result<(), String> {
        if self.accel.iter().all(|a| a.is_finite()) {
            Ok(())
        } else {
            Err(format!("a load's acceleration {:?} is not finite", self.accel))
        }
    }

    /// Adds the load into `a_ext` (one entry per particle of the body), except on the
    /// particles `fixed` marks; with `ids`, on the particles whose original id is in the
    /// range (a fluid's).
    pub fn add<const D: usize>(&self, a_ext: &mut [Vector<D>], fixed: Option<&[bool]>, ids: Option<&[u32]>) {
        let a = Vector::<D>::from_fn(|k, _| self.accel[k]);
        if let Some(ids) = ids {
            for (out, &id) in a_ext.iter_mut().zip(ids) {
                if self.particles.contains(&(id as usize)) {
                    *out += a;
                }
            }
            return;
        }
        let end = self.particles.end.min(a_ext.len());
        for i in self.particles.start.min(end)..end {
            if !fixed.is_some_and(|f| f[i]) {
                a_ext[i] += a;
            }
        }
    }
}

/// A load on a body: the coupling of the body with itself that carries it.
#[derive(Clone, Debug)]
pub struct LoadOn {
    /// The body's index.
    pub body: usize,
    /// The load.
    pub load: UniformLoad,
}
