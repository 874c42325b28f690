//! Mirror planes: a frictionless contact with a flat rigid surface (a platen, a symmetry
//! plane) made of fixed particles of the body that copy, mirrored across the plane, the
//! body particles they face (the free-slip counterpart of Adami, Hu & Adams 2012 for a solid,
//! as the authors' `AdamiBoundaryConditionExtrapolateFreeSlip` extrapolates the stress onto
//! a boundary). A ghost at the mirror image of its partner, with the partner's density,
//! pressure and deviatoric stress reflected and the normal component of its velocity
//! reflected about the plane's, makes the normal velocity continuous with the plane's (no
//! penetration) and the shear stress on the plane zero (no friction): the sums of eqs.
//! (25), (30)-(32) near the plane then see the body continued by its own reflection.

use crate::solver::math::{Matrix, Vector};
use serde::{Deserialize, Serialize};

/// A plane `x[axis] = position` moving along its normal at `velocity`, and the ghost
/// particles mirroring their partners across it: `(ghost, partner)` indices into the body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MirrorPlane {
    /// The coordinate axis the plane is normal to.
    pub axis: usize,
    /// Where the plane is along `axis` (m).
    pub position: f64,
    /// Its speed along `axis` (m/s).
    pub velocity: f64,
    /// `(ghost, partner)`: each ghost copies its partner's state, mirrored.
    pub pairs: Vec<(u32, u32)>,
}

/// The reflection of a point across the plane `x[axis] = position`.
#[inline]
pub fn mirror_point<const D: usize>(x: Vector<D>, axis: usize, position: f64) -> Vector<D> {
    let mut m = x;
    m[axis] = 2.0 * position - x[axis];
    m
}

/// The velocity a ghost shows for its partner's `u` across a plane moving at `velocity`
/// along `axis`: the normal component reflected about the plane's, the tangential kept.
#[inline]
pub fn mirror_velocity<const D: usize>(u: Vector<D>, axis: usize, velocity: f64) -> Vector<D> {
    let mut m = u;
    m[axis] = 2.0 * velocity - u[axis];
    m
}

/// A symmetric tensor reflected across a plane normal to `axis`: `R s R` with `R` the
/// identity but -1 on `axis`, which flips the shear components that couple `axis` with
/// another direction and keeps the rest.
#[inline]
pub fn mirror_tensor<const D: usize>(s: &Matrix<D>, axis: usize) -> Matrix<D> {
    Matrix::<D>::from_fn(|i, j| if (i == axis) != (j == axis) { -s[(i, j)] } else { s[(i, j)] })
}

impl MirrorPlane {
    /// Moves the plane over `dt`.
    pub fn advance(&mut self, dt: f64) {
        self.position += self.velocity * dt;
    }

    /// Refused when an index is out of `0..n` or a ghost is its own partner or mirrors
    /// another ghost.
    pub fn check(&self, n: usize, fixed: &[bool]) -> Result<(), String> {
        for &(g, p) in &self.pairs {
            let (g, p) = (g as usize, p as usize);
            if g >= n || p >= n {
                return Err(format!("mirror plane: pair ({g}, {p}) outside the body's {n} particles"));
            }
            if g == p || fixed[p] {
                return Err(format!(
                    "mirror plane: ghost {g} mirrors particle {p}, not a free particle of the body"
                ));
            }
            if !fixed[g] {
                return Err(format!("mirror plane: ghost {g} must be a fixed particle"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reflection twice is the identity; the reflected shear flips, the normal stresses
    /// stay; the mirrored velocity of a particle moving with the plane is the plane's.
    #[test]
    fn reflections_are_involutions_with_the_expected_signs() {
        let s = Matrix::<2>::new(1.0, 2.0, 2.0, 3.0);
        let m = mirror_tensor(&s, 1);
        assert_eq!(m, Matrix::<2>::new(1.0, -2.0, -2.0, 3.0));
        assert_eq!(mirror_tensor(&m, 1), s);
        let x = Vector::<2>::new(0.3, 0.1);
        assert_eq!(mirror_point(x, 1, 0.0), Vector::<2>::new(0.3, -0.1));
        assert!((mirror_point(mirror_point(x, 1, 0.25), 1, 0.25) - x).norm() < 1e-15);
        let u = Vector::<2>::new(0.5, -0.2);
        assert_eq!(mirror_velocity(u, 1, -0.2), u, "a particle moving with the plane");
        assert_eq!(mirror_velocity(u, 1, 0.0), Vector::<2>::new(0.5, 0.2));
    }
}
