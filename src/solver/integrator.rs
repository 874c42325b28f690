//! Kick-drift-kick time integration (CTVF eqs. 54-60) and the time-step limits (eq. 61).

use crate::solver::math::Vector;
use rayon::prelude::*;

/// The limits of CTVF eq. (61), each multiplied by `cfl` (0.25 in the paper):
/// acoustic `h / (c + |U|)`, viscous `h^2 / nu`, and body force `sqrt(h / |g|)` (the paper
/// prints `h^2 / g`, which is not a time: SEED-NOTES, eq. 61).
pub fn time_step(cfl: f64, h: f64, c: f64, u_max: f64, nu: Option<f64>, g: f64) -> f64 {
    let mut dt = h / (c + u_max);
    if let Some(nu) = nu.filter(|&n| n > 0.0) {
        dt = dt.min(h * h / nu);
    }
    if g > 0.0 {
        dt = dt.min((h / g).sqrt());
    }
    cfl * dt
}

/// Half kick, eq. (54) and (60): `u += dt/2 du/dt`.
pub fn kick<const D: usize>(u: &mut [Vector<D>], du: &[Vector<D>], dt: f64) {
    let half = 0.5 * dt;
    u.par_iter_mut().zip(du).for_each(|(u, a)| *u += a * half);
}

/// Transport velocity at the half step, eq. (55): `u~ = u + dt/2 (du/dt)_c`.
pub fn transport_velocity<const D: usize>(
    u_hat: &mut [Vector<D>],
    u: &[Vector<D>],
    a_c: &[Vector<D>],
    dt: f64,
) {
    let half = 0.5 * dt;
    u_hat.par_iter_mut().zip(u).zip(a_c).for_each(|((uh, u), ac)| *uh = u + ac * half);
}

/// Drift, eq. (59): `x += dt u~`.
pub fn drift<const D: usize>(x: &mut [Vector<D>], u_hat: &[Vector<D>], dt: f64) {
    x.par_iter_mut().zip(u_hat).for_each(|(x, v)| *x += v * dt);
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
