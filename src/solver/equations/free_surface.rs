//! Free-surface particles and their normals (CTVF sec. 3.4, eqs. 42-43, after Muta et al.
//! 2020), and the shifting kept tangential near the surface (sec. 3.5, eqs. 44-45).

use super::{Pair, Point};
use crate::solver::math::Vector;

/// One neighbour's share of the unnormalised normal of eq. (42): `-V_b grad W`.
#[inline(always)]
pub fn normal<const D: usize>(b: &Point<D>, ab: &Pair<D>) -> Vector<D> {
    ab.dwij * -b.v()
}

/// Eq. (42)'s cut-off: a normal shorter than `1 / (4 h)` is set to zero (the particle has
/// full support); a longer one is normalised.
#[inline(always)]
pub fn cut_normal<const D: usize>(n: Vector<D>, h: f64) -> Vector<D> {
    let len = n.norm();
    if len < 0.25 / h {
        Vector::zeros()
    } else {
        n / len
    }
}

/// One neighbour's share of the smoothed normal of eq. (43): `V_b n*_b W_ab`.
#[inline(always)]
pub fn smoothed_normal<const D: usize>(b: &Point<D>, n_b: &Vector<D>, ab: &Pair<D>) -> Vector<D> {
    n_b * (b.v() * ab.wij)
}

/// The 60-degree test of sec. 3.4: whether neighbour `b` (at `x_ab = x_a - x_b`) lies
/// within 60 degrees of particle `a`'s normal `n_a`, which makes `a` not a surface particle.
#[inline(always)]
pub fn in_normal_cone<const D: usize>(n_a: &Vector<D>, ab: &Pair<D>) -> bool {
    ab.r2 > 0.0 && (-ab.xij).dot(n_a) > 0.5 * ab.r2.sqrt()
}

/// Eqs. (44)-(45): a shift (acceleration or displacement) of a surface particle is zero; of
/// a particle near the surface (with a surface particle among its neighbours, h_b < h in
/// Algorithm 1) it keeps only its part tangential to the surface; elsewhere it is kept.
#[inline(always)]
pub fn adjust_shift<const D: usize>(shift: Vector<D>, surface: bool, near: bool, n: &Vector<D>) -> Vector<D> {
    if surface {
        Vector::zeros()
    } else if near {
        shift - n * shift.dot(n)
    } else {
        shift
    }
}

/// Eq. (44) as the authors' code applies it to solids (`ComputeAuHatETVFSun2019Solid`,
/// `AdjustPositionIPST`): zero on the surface; near it, the normal component removed only
/// when it points out of the body (`shift . n > 0`, the normal pointing outwards), so that
/// a shift into the body is kept whole.
#[inline(always)]
pub fn adjust_shift_outward<const D: usize>(
    shift: Vector<D>,
    surface: bool,
    near: bool,
    n: &Vector<D>,
) -> Vector<D> {
    let out = shift.dot(n);
    if surface {
        Vector::zeros()
    } else if near && out > 0.0 {
        shift - n * out
    } else {
        shift
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_are_tangential_near_the_surface_and_zero_on_it() {
        let n = Vector::<2>::new(0.0, 1.0);
        let s = Vector::<2>::new(0.3, 0.4);
        assert_eq!(adjust_shift(s, true, true, &n), Vector::<2>::zeros());
        assert_eq!(adjust_shift(s, false, true, &n), Vector::<2>::new(0.3, 0.0));
        assert_eq!(adjust_shift(s, false, false, &n), s);
        assert_eq!(adjust_shift_outward(s, true, true, &n), Vector::<2>::zeros());
        assert_eq!(adjust_shift_outward(s, false, true, &n), Vector::<2>::new(0.3, 0.0));
        let inwards = Vector::<2>::new(0.3, -0.4);
        assert_eq!(adjust_shift_outward(inwards, false, true, &n), inwards);
        assert_eq!(adjust_shift(inwards, false, true, &n), Vector::<2>::new(0.3, 0.0));
        assert_eq!(adjust_shift_outward(s, false, false, &n), s);
        assert_eq!(cut_normal(Vector::<2>::new(0.1, 0.0), 1.0), Vector::<2>::zeros());
        assert_eq!(cut_normal(Vector::<2>::new(3.0, 4.0), 1.0), Vector::<2>::new(0.6, 0.8));
    }
}
