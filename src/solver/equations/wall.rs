//! Solid-wall boundary conditions by ghost particles (Adami, Hu & Adams 2012; CTVF sec. 3.6,
//! eqs. 46-52): wall particles carry values extrapolated from the fluid, a pressure that
//! balances the fluid's, and velocities mirrored about the wall's own.

use crate::solver::math::Vector;

/// Kernel-weighted sums a wall particle gathers from its fluid neighbours.
#[derive(Clone, Copy, Debug)]
pub struct WallSums<const D: usize> {
    /// sum_f W_wf.
    pub w: f64,
    /// sum_f p_f W_wf.
    pub p: f64,
    /// sum_f rho_f r_wf W_wf, with r_wf = x_w - x_f.
    pub rho_r: Vector<D>,
    /// sum_f u_f W_wf.
    pub u: Vector<D>,
    /// sum_f u~_f W_wf.
    pub u_hat: Vector<D>,
}

impl<const D: usize> Default for WallSums<D> {
    fn default() -> Self {
        Self { w: 0.0, p: 0.0, rho_r: Vector::zeros(), u: Vector::zeros(), u_hat: Vector::zeros() }
    }
}

impl<const D: usize> WallSums<D> {
    /// Adds one fluid neighbour `f` at `x_wf = x_w - x_f` with kernel value `w`.
    #[inline(always)]
    pub fn add(&mut self, w: f64, x_wf: Vector<D>, p: f64, rho: f64, u: Vector<D>, u_hat: Vector<D>) {
        self.w += w;
        self.p += p * w;
        self.rho_r += x_wf * (rho * w);
        self.u += u * w;
        self.u_hat += u_hat * w;
    }

    /// The extrapolated pressure of eq. (52) (eq. 4.14 of the thesis for a structure) for a
    /// particle at acceleration `a_w` under gravity `g`, and the kernel-weighted mean fluid
    /// velocity and transport velocity around it: zero for a particle with no fluid
    /// neighbour.
    #[inline(always)]
    pub fn extrapolated(&self, a_w: Vector<D>, g: Vector<D>) -> (f64, Vector<D>, Vector<D>) {
        if self.w > 1e-300 {
            let inv = 1.0 / self.w;
            // p_w = (sum p_f W + (g - a_w) . sum rho_f r_wf W) / sum W
            ((self.p + (g - a_w).dot(&self.rho_r)) * inv, self.u * inv, self.u_hat * inv)
        } else {
            (0.0, Vector::zeros(), Vector::zeros())
        }
    }
}

/// The values a wall particle presents to the fluid.
#[derive(Clone, Copy, Debug)]
pub struct Ghost<const D: usize> {
    /// Pressure, eq. (52).
    pub p: f64,
    /// Velocity for the divergence terms (no penetration, free slip), eq. (48).
    pub u_slip: Vector<D>,
    /// Transport velocity for the divergence terms, eq. (49).
    pub u_hat_slip: Vector<D>,
    /// Velocity for the viscous terms (no slip), eq. (50).
    pub u_noslip: Vector<D>,
}

/// Eqs. (46)-(52) for one wall particle with prescribed velocity `u_p`, acceleration
/// `a_w` and unit normal `n` (into the fluid), from its fluid sums; `g` is gravity.
/// A wall particle with no fluid neighbour gets zero pressure and the mirror of zero.
///
/// In eqs. (48)-(49) only the wall's normal velocity matters (the tangential part of the
/// mirrored velocity is the fluid's): it is `u_p . n` for a wall that moves in space, and
/// zero for a wall whose particles stay put while its surface slides (`sliding`, a lid).
/// With the lid's velocity there, the lid's corner particles, whose normals are diagonal,
/// would recede from the fluid and suck the corner particle through the wall.
#[inline(always)]
pub fn ghost<const D: usize>(
    s: &WallSums<D>,
    u_p: Vector<D>,
    sliding: bool,
    a_w: Vector<D>,
    n: Vector<D>,
    g: Vector<D>,
) -> Ghost<D> {
    let (p, u_f, u_hat_f) = s.extrapolated(a_w, g);
    let u_n = if sliding { 0.0 } else { u_p.dot(&n) };
    Ghost {
        p,
        // eq. (48): the normal component mirrored about the wall's, the tangential kept
        u_slip: n * (2.0 * (u_n - u_f.dot(&n))) + u_f,
        // eq. (49)
        u_hat_slip: n * (2.0 * (u_n - u_hat_f.dot(&n))) + u_hat_f,
        // eq. (50): the whole velocity mirrored about the wall's
        u_noslip: u_p * 2.0 - u_f,
    }
}

/// What a particle of a deforming structure presents to the fluid (Adami et al. 2012 with
/// the structure's own motion; thesis sec. 4.2.4): the pressure of eq. (4.14) at the
/// particle's acceleration `a_s`, its own velocity `u_s` and transport velocity `u_hat_s`
/// to the divergence terms (a structure has no fixed normal to mirror about, so the fluid's
/// continuity sees the structure's motion itself, as the thesis's code does), and the
/// no-slip mirror `2 u_s - u_f` of eq. (50) to the viscous terms.
#[inline(always)]
pub fn structure_ghost<const D: usize>(
    s: &WallSums<D>,
    u_s: Vector<D>,
    u_hat_s: Vector<D>,
    a_s: Vector<D>,
    g: Vector<D>,
) -> Ghost<D> {
    let (p, u_f, _) = s.extrapolated(a_s, g);
    Ghost { p, u_slip: u_s, u_hat_slip: u_hat_s, u_noslip: u_s * 2.0 - u_f }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hydrostatic_wall_pressure_and_mirrored_velocities() {
        // One fluid particle 0.1 above a wall particle, at p = 5, rho = 1000, g = -9.81 y.
        let mut s = WallSums::<2>::default();
        let u = Vector::<2>::new(0.3, -0.2);
        s.add(2.0, Vector::<2>::new(0.0, -0.1), 5.0, 1000.0, u, u);
        let n = Vector::<2>::new(0.0, 1.0);
        let g = ghost(&s, Vector::zeros(), false, Vector::zeros(), n, Vector::<2>::new(0.0, -9.81));
        assert!((g.p - (5.0 + 1000.0 * 9.81 * 0.1)).abs() < 1e-9, "p_w = p_f + rho g d: {}", g.p);
        // Free slip: tangential kept, normal reversed (the fluid cannot go through).
        assert!((g.u_slip - Vector::<2>::new(0.3, 0.2)).norm() < 1e-12);
        // No slip: the mean of fluid and ghost velocity is the wall's (zero).
        assert!((g.u_noslip + u).norm() < 1e-12);
        // A moving lid: the no-slip ghost makes the mean equal to the lid speed.
        let lid = ghost(&s, Vector::<2>::new(1.0, 0.0), true, Vector::zeros(), -n, Vector::zeros());
        assert!(((lid.u_noslip + u) * 0.5 - Vector::<2>::new(1.0, 0.0)).norm() < 1e-12);
        // A sliding lid has no normal velocity, even at a corner with a diagonal normal.
        let diag = Vector::<2>::new(-1.0, -1.0).normalize();
        let corner = ghost(&s, Vector::<2>::new(1.0, 0.0), true, Vector::zeros(), diag, Vector::zeros());
        assert!(((corner.u_slip + u).dot(&diag)).abs() < 1e-12, "no penetration through the corner");
    }
}
