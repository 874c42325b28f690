//! Fixed-radius neighbour search with cell lists, periodic or bounded per axis, in any
//! dimension. This module knows points, a radius and a box; nothing about SPH (it could be
//! its own crate, as PointNeighbors.jl is for TrixiParticles.jl).
//!
//! A [`CellList`] bins the points of one body into cells at least one search radius wide
//! (a counting sort, so the order is deterministic) and answers queries from any position
//! by scanning the 3^D surrounding cells. Periodic images are handled per neighbour cell by
//! a shift vector, so no point is ever copied. Callers that reorder their particle arrays in
//! the cell order returned by [`CellList::order`] (and then call
//! [`CellList::mark_reordered`]) get neighbours that are contiguous in memory.

mod brute;
mod cell_list;
mod filter;
mod gather;
mod neighbour_list;
mod slabs;

pub use brute::brute_force_neighbours;
pub use cell_list::CellList;
/// The implementations of the list build's distance test (same bits; the fastest is used).
pub use filter::Path as DistanceTest;
pub use gather::Gather;
pub use neighbour_list::{ChunkWriter, HalfPairs, Listed, NeighbourList, PairSlices, CHUNK};
pub use slabs::Slabs;

use crate::solver::math::Vector;

/// The box particles live in: per axis either periodic (positions wrap into `[min, max)`)
/// or bounded (a particle outside `[min, max]` has left the domain).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain<const D: usize> {
    /// Lower corner.
    pub min: [f64; D],
    /// Upper corner.
    pub max: [f64; D],
    /// Which axes are periodic.
    pub periodic: [bool; D],
}

impl<const D: usize> Domain<D> {
    /// A box periodic along every axis.
    pub fn periodic(min: [f64; D], max: [f64; D]) -> Self {
        Self { min, max, periodic: [true; D] }
    }

    /// A bounded box (no periodic axis).
    pub fn bounded(min: [f64; D], max: [f64; D]) -> Self {
        Self { min, max, periodic: [false; D] }
    }

    /// Edge length along `k`.
    pub fn length(&self, k: usize) -> f64 {
        self.max[k] - self.min[k]
    }

    /// The first periodic axis shorter than two search radii `radius`, if any: a
    /// particle's periodic images would be within reach of each other along it (and
    /// [`CellList::new`] panics on it).
    pub fn short_periodic_axis(&self, radius: f64) -> Option<usize> {
        (0..D).find(|&k| self.periodic[k] && self.length(k) < 2.0 * radius)
    }

    /// Refuses a domain with a [`short_periodic_axis`](Self::short_periodic_axis).
    pub fn check_periodic(&self, radius: f64) -> Result<(), String> {
        match self.short_periodic_axis(radius) {
            Some(k) => Err(format!(
                "periodic box length {} along axis {k} is shorter than two kernel radii ({radius}): increase nx or lower hdx",
                self.length(k)
            )),
            None => Ok(()),
        }
    }

    /// Wraps periodic coordinates into `[min, max)`; bounded axes are left alone.
    #[inline]
    pub fn wrap(&self, x: &mut Vector<D>) {
        for k in 0..D {
            if self.periodic[k] {
                let l = self.length(k);
                let mut v = x[k];
                if v < self.min[k] || v >= self.max[k] {
                    v = self.min[k] + (v - self.min[k]).rem_euclid(l);
                    // rem_euclid can round up to exactly l.
                    if v >= self.max[k] {
                        v = self.min[k];
                    }
                }
                x[k] = v;
            }
        }
    }

    /// The minimum-image difference `a - b`.
    #[inline]
    pub fn delta(&self, a: &Vector<D>, b: &Vector<D>) -> Vector<D> {
        let mut d = a - b;
        for k in 0..D {
            if self.periodic[k] {
                let l = self.length(k);
                d[k] -= l * (d[k] / l).round();
            }
        }
        d
    }

    /// Whether `x` is inside the box along every bounded axis.
    #[inline]
    pub fn contains(&self, x: &Vector<D>) -> bool {
        (0..D).all(|k| self.periodic[k] || (x[k] >= self.min[k] && x[k] <= self.max[k]))
    }
}
