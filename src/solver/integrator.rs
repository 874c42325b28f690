//! Kick-drift-kick time integration (CTVF eqs. 54-60) and the time-step limits (eq. 61).

use crate::solver::math::Vector;
use rayon::prelude::*;

/// The limits of CTVF eq. (61), each multiplied by `cfl` (0.25 in the paper):
/// acoustic `h / (c + |U|)`, viscous `h^2 / nu`, and body force `sqrt(h / |g|)` (the paper
/// prints `h^2 / g`, which is not a time: SEED-NOTES, eq. 61).
pub fn time_step(cfl: f64, h: f64, c: f64, u_max: f64, nu: Option<f64>, g: f64) -> f64 {
    binding_limit(cfl, h, c, u_max, nu, g).1
}

/// The limit of eq. (61) that sets the time step (`"acoustic"`, `"viscous"` or
/// `"body force"`), and the time step, as [`time_step`].
pub fn binding_limit(cfl: f64, h: f64, c: f64, u_max: f64, nu: Option<f64>, g: f64) -> (&'static str, f64) {
    let mut limit = ("acoustic", h / (c + u_max));
    if let Some(nu) = nu.filter(|&n| n > 0.0) {
        if h * h / nu < limit.1 {
            limit = ("viscous", h * h / nu);
        }
    }
    if g > 0.0 && (h / g).sqrt() < limit.1 {
        limit = ("body force", (h / g).sqrt());
    }
    (limit.0, cfl * limit.1)
}

use crate::solver::LIGHT_LOOP_LEN;

/// Half kick, eq. (54) and (60): `u += dt/2 du/dt`.
#[inline(always)]
fn half_kick<const D: usize>(u: &mut Vector<D>, du: &Vector<D>, dt: f64) {
    *u += du * (0.5 * dt);
}

/// The first half of a step, in one sweep over the particles: the half kick (eq. 54), the
/// transport velocity `u~ = u + dt/2 (du/dt)_c` (eq. 55) if the body has one, and the drift
/// `x += dt u~` (eq. 59).
pub fn kick_drift<const D: usize>(
    x: &mut [Vector<D>],
    u: &mut [Vector<D>],
    u_hat: Option<&mut [Vector<D>]>,
    du: &[Vector<D>],
    a_c: &[Vector<D>],
    dt: f64,
) {
    // Zipped iterators stop at the shortest slice: every one must cover the body.
    assert!(u.len() == x.len() && du.len() == x.len(), "one velocity and rate per particle");
    match u_hat {
        Some(u_hat) => {
            assert!(u_hat.len() == x.len() && a_c.len() == x.len(), "u~ and (du/dt)_c per particle");
            x.par_iter_mut().zip(u).zip(u_hat).zip(du).zip(a_c).with_min_len(LIGHT_LOOP_LEN).for_each(
                |((((x, u), uh), du), ac)| {
                    half_kick(u, du, dt);
                    *uh = *u + ac * (0.5 * dt);
                    *x += *uh * dt;
                },
            )
        }
        None => x.par_iter_mut().zip(u).zip(du).with_min_len(LIGHT_LOOP_LEN).for_each(|((x, u), du)| {
            half_kick(u, du, dt);
            *x += *u * dt;
        }),
    }
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
