//! Slabs: a partition of a body's points, in cell order, into runs of whole cell layers
//! (the cells sharing their coordinate along the last axis), for loops that evaluate each
//! pair once and add its share to both points.
//!
//! With the points in cell order, the neighbours `j > i` of a point `i` lie in its own layer
//! or the next one (a cell is at least a search radius wide), or, across a periodic last
//! axis, in the last layer when `i` is in the first. A loop over the pairs `j > i` of a slab
//! adds the shares of the points of its own slab at once and sets the others aside
//! ("spills"), which the slabs that receive them add in a fixed order once that loop is
//! done (IPST's sweeps run the slabs as stages on the threads of the pool). Every sum then
//! runs in an order fixed by the partition, which depends on the geometry alone: the result
//! does not depend on the number of threads, and no two threads write the same point.

use super::CellList;
use std::ops::Range;

/// Slabs of whole cell layers of one body, each with at least a given number of layers
/// (or a single slab of all of them, when there are fewer).
#[derive(Clone, Debug, Default)]
pub struct Slabs {
    /// Slab `s` holds the points `bounds[s]..bounds[s + 1]`.
    bounds: Vec<usize>,
}

impl Slabs {
    /// No slabs.
    pub fn new() -> Self {
        Self::default()
    }

    /// Partitions the points binned by `cells` (in cell order: after
    /// [`CellList::mark_reordered`]) into slabs of whole layers, the layers shared out
    /// evenly: as many slabs as keeps at least `min_layers` layers and, on average,
    /// `min_points` points in each, rounded down to a power of two (at least one slab).
    /// Equal slabs in a power-of-two number halve into equal work for any power-of-two
    /// number of threads, and the fewer the slabs, the fewer the pairs between them.
    pub fn partition<const D: usize>(&mut self, cells: &CellList<D>, min_points: usize, min_layers: usize) {
        debug_assert!(
            cells.order().iter().enumerate().all(|(k, &i)| k == i as usize),
            "slabs need the points in cell order"
        );
        let layers = cells.layers();
        let points = cells.layer_points(0..layers).len();
        let most = (layers / min_layers.max(1)).min(points / min_points.max(1)).max(1);
        let slabs = 1 << most.ilog2();
        self.bounds.clear();
        self.bounds.push(0);
        for s in 1..=slabs {
            self.bounds.push(cells.layer_points(0..s * layers / slabs).end);
        }
    }

    /// Number of slabs.
    pub fn len(&self) -> usize {
        self.bounds.len().saturating_sub(1)
    }

    /// Whether there are no slabs.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points of slab `s`.
    pub fn range(&self, s: usize) -> Range<usize> {
        self.bounds[s]..self.bounds[s + 1]
    }

    /// The slabs whose points may receive spills from other slabs' pairs `j > i` for slab
    /// `t`, in the order they are to be added: the previous slab, then (for the last slab)
    /// the first one, across a periodic last axis.
    pub fn spill_sources(&self, t: usize) -> impl Iterator<Item = usize> {
        let last = self.len().saturating_sub(1);
        let previous = t.checked_sub(1);
        let first = (t == last && t > 1).then_some(0);
        previous.into_iter().chain(first)
    }

    /// The slabs' first points, then the number of points.
    pub fn bounds(&self) -> &[usize] {
        &self.bounds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::math::Vector;
    use crate::solver::nnps::{Domain, NeighbourList};

    /// A perturbed periodic lattice, sorted by cell.
    fn sorted_lattice(n: usize, radius: f64) -> (CellList<2>, Vec<Vector<2>>) {
        let dx = 1.0 / n as f64;
        let mut x: Vec<Vector<2>> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64, (k / n) as f64);
                let jitter = 0.3 * dx * ((k * 7919 % 101) as f64 / 101.0 - 0.5);
                Vector::from([(i + 0.5) * dx + jitter, ((j + 0.5) * dx - jitter).rem_euclid(1.0)])
            })
            .collect();
        let mut cells = CellList::new(Domain::periodic([0.0; 2], [1.0; 2]), radius);
        cells.update(&x);
        x = cells.order().iter().map(|&i| x[i as usize]).collect();
        cells.mark_reordered();
        (cells, x)
    }

    #[test]
    fn slabs_tile_the_points_in_whole_layers_shared_out_evenly() {
        let (cells, x) = sorted_lattice(40, 0.08);
        assert_eq!(cells.layers(), 12, "1 / 0.08 -> 12 cells a row");
        let layer = |i: usize| cells.cell_of(i) / 12;
        // (min points, min layers) -> slabs, rounded down to a power of two: 1600 points /
        // 300 -> 5 -> 4; 12 layers / 6 -> 2; 12 layers / 1 -> 12 -> 8; too many points
        // asked for -> one slab.
        for ((min_points, min_layers), want) in [((300, 1), 4), ((1, 6), 2), ((1, 1), 8), ((10_000, 1), 1)] {
            let mut slabs = Slabs::new();
            slabs.partition(&cells, min_points, min_layers);
            assert_eq!(slabs.len(), want, "min {min_points} points, {min_layers} layers");
            assert_eq!(slabs.range(0).start, 0);
            assert_eq!(slabs.range(slabs.len() - 1).end, x.len());
            for s in 0..slabs.len() {
                let r = slabs.range(s);
                if s + 1 < slabs.len() {
                    assert_eq!(r.end, slabs.range(s + 1).start);
                }
                // Whole layers (a slab starts a layer), as many as the even share:
                // 12 layers into 8 slabs -> 1 or 2 each.
                if r.start > 0 {
                    assert_ne!(layer(r.start), layer(r.start - 1));
                }
                let spanned = layer(r.end - 1) - layer(r.start) + 1;
                assert!(
                    (12 / want..=12_usize.div_ceil(want)).contains(&spanned),
                    "slab {s}: {spanned} layers"
                );
            }
        }
    }

    /// The claim the once-per-pair loops rest on: every neighbour `j > i` of a point is in
    /// its own slab, or in a slab that names the point's slab among its spill sources.
    #[test]
    fn neighbours_after_a_point_lie_in_its_slab_or_one_that_takes_its_spills() {
        for (min_points, min_layers) in [(1, 1), (1, 2), (150, 2), (400, 2), (10_000, 2)] {
            let (cells, x) = sorted_lattice(40, 0.08);
            let mut slabs = Slabs::new();
            slabs.partition(&cells, min_points, min_layers);
            let slab_of = |i: usize| (0..slabs.len()).find(|&s| slabs.range(s).contains(&i)).unwrap();
            let mut nl = NeighbourList::<2, ()>::new();
            nl.build(&cells, &x, |_, _| {});
            for i in 0..x.len() {
                nl.for_each(i, &x, |j, _, _, _| {
                    let (s, t) = (slab_of(i), slab_of(j));
                    if j > i && s != t {
                        assert!(slabs.spill_sources(t).any(|u| u == s), "{i} in slab {s} -> {j} in {t}");
                    }
                });
            }
        }
    }
}
