//! A fluid body: positions, velocities, mass, density, pressure, and the transport
//! velocity only when its scheme moves particles with one; its physics (the scheme, with
//! its material constants), its time-step limit (eq. 61) and its kick-drift-kick updates
//! (eqs. 54-60); what it does at each stage of a step is in [`stages`].

mod stages;

pub use stages::{FluidStages, FluidWork};

use super::permute;
use crate::solver::integrator;
use crate::solver::math::Vector;
use crate::solver::scheme::FluidScheme;
use serde::{Deserialize, Serialize};
use std::ops::Range;

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

/// A named body among the particles of a [`Fluid`]: the particles whose original index is
/// in `ids`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FluidPart {
    /// Body name, used in output file names.
    pub name: String,
    /// The original indices of its particles.
    pub ids: Range<u32>,
}

/// State of one fluid (struct of arrays). Particles are kept sorted by neighbour-search
/// cell; `id` remembers each particle's original index for output.
///
/// Fluid bodies of the same physics are one `Fluid` with several named [`parts`](Self::parts)
/// ([`merge`](Self::merge)): they share one neighbour search and one order of summation, so
/// a fluid split into named bodies computes what it computes whole, bit for bit. (Two
/// fluids held apart would sum a particle's neighbours body by body, in another order, and
/// differ by rounding.)
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fluid<const D: usize> {
    /// The named bodies this fluid holds, in the order of their particles' original indices.
    pub parts: Vec<FluidPart>,
    /// Smoothing length (uniform within a body).
    pub h: f64,
    /// What its equations are (the scheme) and its material constants.
    pub physics: FluidScheme,
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
    /// The external acceleration the couplings added at the last evaluation (a load),
    /// included in `du`; empty for a fluid none acts on.
    #[serde(skip)]
    pub a_ext: Vec<Vector<D>>,
}

impl<const D: usize> FluidRates<D> {
    /// Zeroed rates for the particles of `fluid`, with the sets its physics declares.
    pub fn of(fluid: &Fluid<D>) -> Self {
        let s = &fluid.physics;
        Self::new(
            fluid.len(),
            matches!(s.pressure, crate::solver::scheme::PressureModel::Edac { .. }),
            s.density == crate::solver::scheme::DensityModel::Continuity,
            s.transport.is_some(),
        )
    }

    /// Zeroed rates for `n` particles; the optional sets are empty when not declared.
    pub fn new(n: usize, pressure: bool, density: bool, transport: bool) -> Self {
        Self {
            du: vec![Vector::zeros(); n],
            dp: if pressure { vec![0.0; n] } else { Vec::new() },
            drho: if density { vec![0.0; n] } else { Vec::new() },
            a_c: if transport { vec![Vector::zeros(); n] } else { Vec::new() },
            a_c_dt: None,
            a_ext: Vec::new(),
        }
    }
}

impl<const D: usize> Fluid<D> {
    /// A fluid body from initial values, with the fields its `physics` declares (the
    /// transport velocity only with a transport velocity). Errors name the body and the
    /// offending field.
    pub fn new(name: &str, h: f64, init: FluidInit<D>, physics: FluidScheme) -> Result<Self, String> {
        let n = init.x.len();
        super::check_init(
            ("fluid", name),
            n,
            h,
            &[("u", init.u.len()), ("m", init.m.len()), ("rho", init.rho.len()), ("p", init.p.len())],
            &init.m,
            &init.rho,
        )?;
        if n > u32::MAX as usize {
            return Err(format!("fluid `{name}`: {n} particles are more than a body indexes"));
        }
        let u_hat = physics.transport.is_some().then(|| init.u.clone());
        Ok(Self {
            parts: vec![FluidPart { name: name.into(), ids: 0..n as u32 }],
            h,
            physics,
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

    /// Adds the particles of `other`, a fluid body of the same physics and smoothing length,
    /// as a part of this one: its particles come after this one's, in their order, with
    /// their original indices offset by this one's count (both as built, their ids those of
    /// their order): [`extend`](Self::extend) on a body as built.
    pub fn merge(&mut self, other: Fluid<D>) -> Result<(), String> {
        self.extend(other)
    }

    /// The name of the part particle `id` (an original index) belongs to.
    pub fn part_of(&self, id: u32) -> &str {
        let part = self.parts.iter().find(|p| p.ids.contains(&id));
        part.map_or("fluid", |p| p.name.as_str())
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// The largest time step of eq. (61) at factor `cfl`, with `u_max` the largest particle
    /// speed (the acoustic limit takes the larger of it and the reference speed).
    pub fn dt_limit(&self, cfl: f64, u_max: f64) -> f64 {
        let s = &self.physics;
        let g = s.gravity.iter().map(|v| v * v).sum::<f64>().sqrt();
        integrator::time_step(cfl, self.h, s.c0, s.u_ref.max(u_max), s.viscosity, g)
    }

    /// The opening half kick (eq. 54) and the transport velocity (eq. 55).
    pub fn kick_open(&mut self, r: &FluidRates<D>, dt: f64) {
        integrator::kick_transport(&mut self.u, self.u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
    }

    /// The drift of eq. (59), with the transport velocity if there is one.
    pub fn drift(&mut self, dt: f64) {
        integrator::drift(&mut self.x, self.u_hat.as_deref().unwrap_or(&self.u), dt);
    }

    /// The closing half kick (eq. 60).
    pub fn kick_close(&mut self, r: &FluidRates<D>, dt: f64) {
        integrator::kick(&mut self.u, &r.du, dt);
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

    /// Values in the order of the particles' original ids (for output that must not depend
    /// on the internal ordering).
    pub fn by_id<T: Copy + Default>(&self, v: &[T]) -> Vec<T> {
        let n = v.len();
        if self.id.iter().all(|&i| (i as usize) < n) {
            // Ids 0..n, as built: each its own slot.
            let mut out = vec![T::default(); n];
            for (k, &i) in self.id.iter().enumerate() {
                out[i as usize] = v[k];
            }
            return out;
        }
        // Particles removed or added: in increasing id.
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_unstable_by_key(|&k| self.id[k]);
        order.into_iter().map(|k| v[k]).collect()
    }

    /// Keeps the particles `keep` marks, in their order, with their ids.
    pub fn retain(&mut self, keep: &[bool]) -> Result<(), String> {
        use super::retain_by;
        retain_by(&mut self.x, keep);
        retain_by(&mut self.u, keep);
        if let Some(uh) = self.u_hat.as_mut() {
            retain_by(uh, keep);
        }
        retain_by(&mut self.m, keep);
        retain_by(&mut self.rho, keep);
        retain_by(&mut self.p, keep);
        retain_by(&mut self.id, keep);
        Ok(())
    }

    /// Appends the particles of `more`, a fluid body of the same physics and smoothing
    /// length (as built), with ids after this one's largest; its parts keep their names.
    pub fn extend(&mut self, more: Fluid<D>) -> Result<(), String> {
        let next = self.id.iter().max().map_or(0, |&i| i + 1);
        let (a, b) = (&self.parts[0].name, &more.parts[0].name);
        if !more.physics.same_physics(&self.physics) || more.h != self.h {
            return Err(format!("fluid `{b}` differs from fluid `{a}` in its physics or smoothing length"));
        }
        if next as usize + more.len() > u32::MAX as usize {
            return Err(format!("fluids `{a}` and `{b}`: more particles than a body indexes"));
        }
        self.parts.extend(
            more.parts
                .into_iter()
                .map(|p| FluidPart { name: p.name, ids: p.ids.start + next..p.ids.end + next }),
        );
        self.x.extend(more.x);
        self.u.extend(more.u);
        if let (Some(mine), Some(theirs)) = (self.u_hat.as_mut(), more.u_hat) {
            mine.extend(theirs);
        }
        self.m.extend(more.m);
        self.rho.extend(more.rho);
        self.p.extend(more.p);
        self.id.extend(more.id.into_iter().map(|i| i + next));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::scheme::{FluidSettings, Pst, SchemeName};

    /// CTVF physics, with a transport velocity (Sun's shifting) or without (no shifting).
    pub(crate) fn physics(transport: bool) -> FluidScheme {
        let pst = if transport { Pst::Sun } else { Pst::None };
        let s = FluidSettings { pst, ..FluidSettings::internal_flow(1.0, 10.0, 1.0, 0.1, 1.0, 0.01) };
        SchemeName::Ctvf.fluid_scheme(&s)
    }

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
            Fluid::new("water", 0.1, i, physics(false)).unwrap_err(),
            "fluid `water`: particle 1 has non-positive mass 0"
        );
        let mut i = init(3);
        i.p.pop();
        assert_eq!(
            Fluid::new("water", 0.1, i, physics(false)).unwrap_err(),
            "fluid `water`: p has 2 entries for 3 particles"
        );
        assert!(Fluid::new("water", -1.0, init(3), physics(false)).unwrap_err().contains("h = -1"));
    }

    #[test]
    fn transport_velocity_is_allocated_only_when_declared() {
        assert!(Fluid::new("f", 0.1, init(4), physics(false)).unwrap().u_hat.is_none());
        assert_eq!(Fluid::new("f", 0.1, init(4), physics(true)).unwrap().u_hat.unwrap().len(), 4);
    }

    #[test]
    fn reorder_moves_every_field_and_keeps_ids() {
        let mut f = Fluid::new("f", 0.1, init(4), physics(true)).unwrap();
        f.p = vec![10.0, 11.0, 12.0, 13.0];
        f.reorder(&[2, 0, 3, 1]);
        assert_eq!(f.p, vec![12.0, 10.0, 13.0, 11.0]);
        assert_eq!(f.id, vec![2, 0, 3, 1]);
        assert_eq!(f.x[0][0], 2.0);
        assert_eq!(f.by_id(&f.p), vec![10.0, 11.0, 12.0, 13.0]);
    }

    /// A merged fluid holds both bodies' particles in order, each part naming its own, and
    /// refuses a fluid of other physics.
    #[test]
    fn merged_fluids_keep_their_parts() {
        let mut f = Fluid::new("lower", 0.1, init(3), physics(true)).unwrap();
        let mut upper = Fluid::new("upper", 0.1, init(2), physics(true)).unwrap();
        upper.p = vec![7.0, 8.0];
        f.merge(upper).unwrap();
        assert_eq!(f.len(), 5);
        assert_eq!(f.id, vec![0, 1, 2, 3, 4]);
        assert_eq!(f.p[3..], [7.0, 8.0]);
        assert_eq!(f.u_hat.as_ref().unwrap().len(), 5);
        assert_eq!((f.part_of(2), f.part_of(3)), ("lower", "upper"));
        assert_eq!(f.parts[1].ids, 3..5);
        let other = Fluid::new("oil", 0.1, init(2), physics(false)).unwrap();
        assert!(f.merge(other).unwrap_err().contains("fluid `oil` differs from fluid `lower`"));
    }
}
