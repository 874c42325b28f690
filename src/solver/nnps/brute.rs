//! The O(N^2) oracle the cell list is tested against.

use super::Domain;
use crate::solver::math::Vector;

/// For every query point, the sorted indices of the points within `radius` (strictly less),
/// using the minimum image on periodic axes.
pub fn brute_force_neighbours<const D: usize>(
    domain: &Domain<D>,
    radius: f64,
    points: &[Vector<D>],
    queries: &[Vector<D>],
) -> Vec<Vec<usize>> {
    queries
        .iter()
        .map(|q| {
            (0..points.len())
                .filter(|&j| domain.delta(q, &points[j]).norm_squared() < radius * radius)
                .collect()
        })
        .collect()
}
