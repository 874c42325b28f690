//! Kick-drift-kick time integration (CTVF eqs. 54-60), the time-step limits (eq. 61), the
//! time loop's settings and what it reports (a blow-up, the time spent per phase).

use crate::solver::math::Vector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Where in a step the density and pressure rates of eqs. (56)-(57) are evaluated.
///
/// Sec. 3.7 evaluates them after the half kick, at the step's start positions (`Start`; the
/// authors' code does the same). We evaluate them after the drift, at the new positions
/// (`End`), by default: the paper's order is not uniformly more accurate on the
/// Taylor-Green vortex or the cavity, as problem `taylor_green_rate_positions` shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RatePositions {
    /// Sec. 3.7: at the step's start positions, with the half-step velocities, before the
    /// drift.
    Start,
    /// After the drift, at the new positions, with the half-step velocities.
    #[default]
    End,
}

named_choices!(RatePositions { Start => "start", End => "end" });

/// Why a run stopped early: the physics blew up. A result, not a crash.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    /// What was found.
    pub reason: String,
    /// The step after which it was found.
    pub step: u64,
    /// Simulated time at that step.
    pub time: f64,
}

/// Settings of the time loop.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct TimeSettings {
    /// The factor of eq. (61).
    pub cfl: f64,
    /// A speed above `blowup_factor` times a fluid's speed of sound counts as a blow-up, so
    /// that a run that grows without turning NaN still stops ([`BLOWUP_MACH`] in every
    /// scene).
    pub blowup_factor: f64,
    /// Where the density and pressure rates are evaluated.
    #[serde(default)]
    pub rate_positions: RatePositions,
    /// How many steps a structure in a fluid takes per step of the fluid.
    #[serde(default)]
    pub solid_substeps: Substeps,
}

/// How many steps a structure in a fluid takes per step of the fluid (see
/// [`simulation`](crate::solver::simulation), *Clocks*). A solid no fluid meets steps with
/// the fluid, at the smallest limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Substeps {
    /// As many as the two time-step limits ask: `ceil(fluid's limit / structure's limit)`,
    /// the fluid at its own limit.
    #[default]
    Auto,
    /// This many (at least one): the fluid's step is its own limit or `n` times the
    /// structure's, whichever is shorter. With one, both step together at the smaller
    /// limit: the run without sub-steps.
    Fixed(u32),
}

impl TimeSettings {
    /// The settings of a scene: eq. (61)'s factor; blow-ups at [`BLOWUP_MACH`]; the rates at
    /// the default [`RatePositions`].
    pub fn new(cfl: f64) -> Self {
        Self {
            cfl,
            blowup_factor: BLOWUP_MACH,
            rate_positions: RatePositions::default(),
            solid_substeps: Substeps::default(),
        }
    }
}

/// The Mach number at which a run counts as blown up. Weakly compressible SPH takes c0 at
/// least ten times the largest flow speed (Ma <= 0.1), so a particle at the speed of sound
/// has left the model by ten times its design margin. The quick preset's completed runs peak
/// at Ma = 0.15 (the Taylor-Green vortex and the cavity, c0 = 10 U) and 0.22 (the dam break);
/// a bound of 10 c0 let a Taylor-Green run at `cfl = 5` reach 45 U and report `completed`.
pub const BLOWUP_MACH: f64 = 1.0;

/// Wall-clock seconds spent in each phase of the step, summed over the run (a few clock
/// reads per step; reported by `sphrepro bench`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct PhaseTimes {
    /// Kicks, drift and the blow-up check.
    pub integrate: f64,
    /// Wrapping, binning, reordering and the neighbour lists with their kernel values (and
    /// the fluid's share of a summation density, summed as the list is built).
    pub neighbours: f64,
    /// Summation density: the boundaries' share.
    pub density: f64,
    /// Density and pressure rates and their update (pass A).
    pub pressure: f64,
    /// Accelerations and homogenisation (pass B).
    pub accelerations: f64,
    /// Iterative shifting.
    pub ipst: f64,
}

impl std::ops::AddAssign for PhaseTimes {
    fn add_assign(&mut self, o: Self) {
        self.integrate += o.integrate;
        self.neighbours += o.neighbours;
        self.density += o.density;
        self.pressure += o.pressure;
        self.accelerations += o.accelerations;
        self.ipst += o.ipst;
    }
}

impl PhaseTimes {
    /// Every phase multiplied by `f` (e.g. 1 / total, for shares).
    pub fn scaled(&self, f: f64) -> Self {
        Self {
            integrate: self.integrate * f,
            neighbours: self.neighbours * f,
            density: self.density * f,
            pressure: self.pressure * f,
            accelerations: self.accelerations * f,
            ipst: self.ipst * f,
        }
    }
}

/// Adds the time since `start` to `acc` and returns now.
pub(crate) fn lap(start: std::time::Instant, acc: &mut f64) -> std::time::Instant {
    let now = std::time::Instant::now();
    *acc += (now - start).as_secs_f64();
    now
}

/// The limits of CTVF eq. (61), each multiplied by `cfl` (0.25 in the paper):
/// acoustic `h / (c + |U|)`, viscous `h^2 / nu`, and body force `sqrt(h / |g|)` (the paper
/// prints `h^2 / g`, which is not a time: SEED-NOTES, eq. 61).
pub fn time_step(cfl: f64, h: f64, c: f64, u_max: f64, nu: Option<f64>, g: f64) -> f64 {
    binding_limit(cfl, h, c, u_max, nu, g).1
}

/// The three limits of eq. (61).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeStepLimit {
    /// `h / (c + |U|)`.
    Acoustic,
    /// `h^2 / nu`.
    Viscous,
    /// `sqrt(h / |g|)`.
    BodyForce,
}

impl TimeStepLimit {
    /// The limit's name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Acoustic => "acoustic",
            Self::Viscous => "viscous",
            Self::BodyForce => "body force",
        }
    }
}

/// The limit of eq. (61) that sets the time step, and the time step, as [`time_step`].
pub fn binding_limit(cfl: f64, h: f64, c: f64, u_max: f64, nu: Option<f64>, g: f64) -> (TimeStepLimit, f64) {
    let mut limit = (TimeStepLimit::Acoustic, h / (c + u_max));
    if let Some(nu) = nu.filter(|&n| n > 0.0) {
        let viscous = h * h / nu;
        if viscous < limit.1 {
            limit = (TimeStepLimit::Viscous, viscous);
        }
    }
    if g > 0.0 {
        let body = (h / g).sqrt();
        if body < limit.1 {
            limit = (TimeStepLimit::BodyForce, body);
        }
    }
    (limit.0, cfl * limit.1)
}

use crate::solver::LIGHT_LOOP_LEN;

/// Half kick, eq. (54) and (60): `u += dt/2 du/dt`.
#[inline(always)]
fn half_kick<const D: usize>(u: &mut Vector<D>, du: &Vector<D>, dt: f64) {
    *u += du * (0.5 * dt);
}

/// The half kick (eq. 54) and, if the body has one, the transport velocity
/// `u~ = u + dt_c/2 (du/dt)_c` (eq. 55), `dt_c` the step a shifting technique scaled
/// (du/dt)_c for (`a_c_dt`; `dt` itself for a background pressure).
pub fn kick_transport<const D: usize>(
    u: &mut [Vector<D>],
    u_hat: Option<&mut [Vector<D>]>,
    du: &[Vector<D>],
    a_c: &[Vector<D>],
    a_c_dt: Option<f64>,
    dt: f64,
) {
    let half_dt_c = 0.5 * a_c_dt.unwrap_or(dt);
    // Zipped iterators stop at the shortest slice: every one must cover the body.
    assert!(du.len() == u.len(), "one rate per particle");
    match u_hat {
        Some(u_hat) => {
            assert!(u_hat.len() == u.len() && a_c.len() == u.len(), "u~ and (du/dt)_c per particle");
            u.par_iter_mut().zip(u_hat).zip(du).zip(a_c).with_min_len(LIGHT_LOOP_LEN).for_each(
                |(((u, uh), du), ac)| {
                    half_kick(u, du, dt);
                    *uh = *u + ac * half_dt_c;
                },
            )
        }
        None => kick(u, du, dt),
    }
}

/// The drift of eq. (59), `x += dt u~` (or `dt u` for a body without transport velocity).
pub fn drift<const D: usize>(x: &mut [Vector<D>], velocity: &[Vector<D>], dt: f64) {
    assert!(velocity.len() == x.len(), "one velocity per particle");
    x.par_iter_mut().zip(velocity).with_min_len(LIGHT_LOOP_LEN).for_each(|(x, v)| *x += v * dt);
}

/// The closing half kick of a step, eq. (60).
pub fn kick<const D: usize>(u: &mut [Vector<D>], du: &[Vector<D>], dt: f64) {
    u.par_iter_mut().zip(du).with_min_len(LIGHT_LOOP_LEN).for_each(|(u, a)| half_kick(u, a, dt));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_step_takes_the_smallest_limit() {
        // Acoustic: 0.25 * 0.02 / 11.
        assert_eq!(time_step(0.25, 0.02, 10.0, 1.0, Some(0.01), 0.0), 0.25 * 0.02 / 11.0);
        // Viscous: h^2/nu = 4e-4/1 smaller than 0.02/11.
        assert_eq!(time_step(0.25, 0.02, 10.0, 1.0, Some(1.0), 0.0), 0.25 * 0.02 * 0.02);
        // Body force: sqrt(h/g).
        let dt = time_step(0.25, 0.02, 0.1, 0.0, None, 9.81);
        assert!((dt - 0.25 * (0.02f64 / 9.81).sqrt()).abs() < 1e-12 * dt);
    }
}
