//! Cell-list binning and queries. See the module docs of `nnps`.

use super::Domain;
use crate::solver::math::Vector;
use rayon::prelude::*;

/// Points of one body binned into cells of edge >= the search radius.
#[derive(Clone, Debug)]
pub struct CellList<const D: usize> {
    domain: Domain<D>,
    radius: f64,
    radius2: f64,
    /// Cells per axis.
    ncells: [usize; D],
    /// Edge length per axis.
    cell_size: [f64; D],
    /// Lower corner of the grid per axis.
    origin: [f64; D],
    /// `cell_start[c]..cell_start[c + 1]` indexes `sorted` for cell `c`.
    cell_start: Vec<u32>,
    /// Point indices in cell order.
    sorted: Vec<u32>,
    /// Scratch: the cell of each point.
    cell_of: Vec<u32>,
}

impl<const D: usize> CellList<D> {
    /// An empty list for queries of `radius` in `domain`. Along a periodic axis the grid
    /// spans the box exactly (cells are widened so that they tile it); along a bounded
    /// axis it spans the box, and points beyond it are clamped into the edge cells.
    ///
    /// Panics if a periodic axis is shorter than two search radii (the minimum image
    /// would then be ambiguous): scenes check this and report it as a parameter error.
    pub fn new(domain: Domain<D>, radius: f64) -> Self {
        let mut list = Self {
            domain,
            radius,
            radius2: radius * radius,
            ncells: [1; D],
            cell_size: [radius; D],
            origin: [0.0; D],
            cell_start: Vec::new(),
            sorted: Vec::new(),
            cell_of: Vec::new(),
        };
        list.reshape(domain, radius);
        list
    }

    /// Makes it a list for queries of `radius` in `domain` (as [`new`](Self::new) does),
    /// keeping its buffers: a list re-made every step (a structure's, around it) allocates
    /// only when it grows. It holds no points until the next [`update`](Self::update).
    pub fn reshape(&mut self, domain: Domain<D>, radius: f64) {
        assert!(radius > 0.0, "search radius must be positive");
        let mut ncells = [1usize; D];
        let mut cell_size = [radius; D];
        let mut origin = [0.0; D];
        for k in 0..D {
            let l = domain.length(k);
            origin[k] = domain.min[k];
            if domain.periodic[k] {
                assert!(
                    l >= 2.0 * radius,
                    "periodic axis {k} of length {l} is shorter than two search radii ({radius})"
                );
                ncells[k] = ((l / radius).floor() as usize).max(1);
                cell_size[k] = l / ncells[k] as f64;
            } else {
                ncells[k] = ((l / radius).ceil() as usize).max(1);
                cell_size[k] = radius;
            }
        }
        let total: usize = ncells.iter().product();
        (self.domain, self.radius, self.radius2) = (domain, radius, radius * radius);
        (self.ncells, self.cell_size, self.origin) = (ncells, cell_size, origin);
        self.cell_start.clear();
        self.cell_start.resize(total + 1, 0);
        self.sorted.clear();
        self.cell_of.clear();
    }

    /// The number of cells a list for queries of `radius` in `domain` would have (as a
    /// float: it may not fit an integer), before it is made.
    pub fn cell_count(domain: &Domain<D>, radius: f64) -> f64 {
        (0..D)
            .map(|k| {
                let cells = domain.length(k) / radius;
                if domain.periodic[k] { cells.floor() } else { cells.ceil() }.max(1.0)
            })
            .product()
    }

    /// The search radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Integer cell coordinate of `x` along `k` (clamped on bounded axes, wrapped on
    /// periodic ones).
    #[inline(always)]
    fn coord(&self, x: f64, k: usize) -> usize {
        let c = ((x - self.origin[k]) / self.cell_size[k]).floor() as i64;
        let n = self.ncells[k] as i64;
        if self.domain.periodic[k] {
            c.rem_euclid(n) as usize
        } else {
            c.clamp(0, n - 1) as usize
        }
    }

    #[inline(always)]
    fn linear(&self, c: &[usize; D]) -> usize {
        let mut idx = 0;
        for k in (0..D).rev() {
            idx = idx * self.ncells[k] + c[k];
        }
        idx
    }

    /// Bins `points` (a counting sort by cell: deterministic and O(N)). Periodic
    /// coordinates must already be wrapped into the box.
    pub fn update(&mut self, points: &[Vector<D>]) {
        let n = points.len();
        self.sorted.resize(n, 0);
        // The cells of the points in parallel (the divisions and roundings are most of the
        // binning), then a serial count: the order depends on nothing but the points.
        let mut cell_of = std::mem::take(&mut self.cell_of);
        cell_of.resize(n, 0);
        cell_of.par_iter_mut().zip(points).with_min_len(crate::solver::LIGHT_LOOP_LEN).for_each(
            |(cell, x)| {
                let mut c = [0usize; D];
                for (k, ck) in c.iter_mut().enumerate() {
                    *ck = self.coord(x[k], k);
                }
                *cell = self.linear(&c) as u32;
            },
        );
        self.cell_of = cell_of;
        self.cell_start.iter_mut().for_each(|c| *c = 0);
        for &cell in &self.cell_of {
            self.cell_start[cell as usize + 1] += 1;
        }
        for c in 0..self.cell_start.len() - 1 {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        // Scatter, using cell_start as a running cursor, then restore it.
        for i in 0..n {
            let cell = self.cell_of[i] as usize;
            self.sorted[self.cell_start[cell] as usize] = i as u32;
            self.cell_start[cell] += 1;
        }
        for c in (1..self.cell_start.len()).rev() {
            self.cell_start[c] = self.cell_start[c - 1];
        }
        self.cell_start[0] = 0;
    }

    /// Point indices in cell order: permuting the point arrays by this order makes cells
    /// contiguous in memory.
    pub fn order(&self) -> &[u32] {
        &self.sorted
    }

    /// Declares that the caller has permuted its arrays by [`order`](Self::order): the
    /// point at slot `k` is now the `k`-th in cell order.
    pub fn mark_reordered(&mut self) {
        for (k, s) in self.sorted.iter_mut().enumerate() {
            *s = k as u32;
        }
        for c in 0..self.cell_start.len() - 1 {
            let range = self.cell_start[c] as usize..self.cell_start[c + 1] as usize;
            self.cell_of[range].iter_mut().for_each(|v| *v = c as u32);
        }
    }

    /// Number of cell layers: the cells sharing their coordinate along the last axis,
    /// which is the slowest in the cell order.
    pub fn layers(&self) -> usize {
        self.ncells[D - 1]
    }

    /// The points binned into layers `layers` (see [`layers`](Self::layers)), as a range of
    /// the current order: valid after [`mark_reordered`](Self::mark_reordered), when the
    /// points are in cell order and a layer's points are contiguous.
    pub fn layer_points(&self, layers: std::ops::Range<usize>) -> std::ops::Range<usize> {
        let per_layer: usize = self.ncells[..D - 1].iter().product();
        self.cell_start[layers.start * per_layer] as usize..self.cell_start[layers.end * per_layer] as usize
    }

    /// The cell point `i` was binned into (by the last [`update`](Self::update), in the
    /// current order after [`mark_reordered`](Self::mark_reordered)).
    #[inline(always)]
    pub fn cell_of(&self, i: usize) -> usize {
        self.cell_of[i] as usize
    }

    /// Calls `f(candidates, wraps)` for each of the 3^D cells around cell `cell` (as
    /// [`for_each_candidate_cell`](Self::for_each_candidate_cell) does for a position).
    #[inline(always)]
    pub fn for_each_cell_around<F: FnMut(&[u32], [i8; D])>(&self, cell: usize, f: F) {
        let mut coords = [0i64; D];
        let mut rest = cell;
        for (k, c) in coords.iter_mut().enumerate() {
            *c = (rest % self.ncells[k]) as i64;
            rest /= self.ncells[k];
        }
        self.visit_cells(coords, f);
    }

    /// Calls `f(j, x_ij, r2)` for every point `j` with `|x_i - x_j| < radius`, where
    /// `x_ij = query - x_j` is the minimum-image difference. `points` must be the slice
    /// passed to the last [`update`](Self::update) (or that slice permuted by
    /// [`order`](Self::order) after [`mark_reordered`](Self::mark_reordered)).
    /// The visiting order is fixed by the binning, never by threads.
    #[inline(always)]
    pub fn for_each_neighbour<F: FnMut(usize, Vector<D>, f64)>(
        &self,
        points: &[Vector<D>],
        query: &Vector<D>,
        mut f: F,
    ) {
        self.visit(points, query, |j, xij, r2, _| f(j, xij, r2));
    }

    /// The image shift of a neighbour found through periodic wrap `wraps` (periods per
    /// axis): the neighbour's image sits at `x_j + shift`.
    pub fn shift(&self, wraps: [i8; D]) -> Vector<D> {
        let mut s = Vector::<D>::zeros();
        for k in 0..D {
            s[k] = wraps[k] as f64 * self.domain.length(k);
        }
        s
    }

    /// As [`for_each_neighbour`](Self::for_each_neighbour), also passing the number of
    /// periods each axis was wrapped by to reach the neighbour's image. `x_ij` is computed
    /// as `(query - shift) - x_j`.
    #[inline(always)]
    pub fn visit<F: FnMut(usize, Vector<D>, f64, [i8; D])>(
        &self,
        points: &[Vector<D>],
        query: &Vector<D>,
        mut f: F,
    ) {
        let r2max = self.radius2;
        self.for_each_candidate_cell(query, |candidates, q, wraps| {
            for &j in candidates {
                let j = j as usize;
                let xij = q - points[j];
                let r2 = xij.norm_squared();
                if r2 < r2max {
                    f(j, xij, r2, wraps);
                }
            }
        });
    }

    /// Calls `f(candidates, q, wraps)` for each of the 3^D cells around `query`: the point
    /// indices binned in the cell, the query moved by the image shift (`query - shift`, so
    /// that `q - x_j` is the pair difference) and the periods wrapped per axis.
    #[inline(always)]
    pub fn for_each_candidate_cell<F: FnMut(&[u32], Vector<D>, [i8; D])>(&self, query: &Vector<D>, mut f: F) {
        let mut coords = [0i64; D];
        for (k, c) in coords.iter_mut().enumerate() {
            *c = ((query[k] - self.origin[k]) / self.cell_size[k]).floor() as i64;
        }
        self.visit_cells(coords, |candidates, w| f(candidates, query - self.shift(w), w));
    }

    /// The 3^D cells around integer cell coordinates `coords` (which may lie outside the
    /// grid), with the periods wrapped to reach each.
    #[inline(always)]
    fn visit_cells<F: FnMut(&[u32], [i8; D])>(&self, coords: [i64; D], mut f: F) {
        // Per axis: the (up to three) neighbour cell coordinates and the periods wrapped
        // to reach them.
        let mut cells = [[0usize; 3]; D];
        let mut wraps = [[0i8; 3]; D];
        let mut counts = [0usize; D];
        for k in 0..D {
            let c = coords[k];
            let n = self.ncells[k] as i64;
            if self.domain.periodic[k] {
                for o in -1..=1i64 {
                    // The query may sit slightly outside the box (positions are wrapped
                    // only at binning time), so wrap by whole periods. With fewer than
                    // three cells the same cell recurs with another shift: each shift is
                    // a different image, which is right.
                    let cc = c + o;
                    cells[k][counts[k]] = cc.rem_euclid(n) as usize;
                    wraps[k][counts[k]] = cc.div_euclid(n) as i8;
                    counts[k] += 1;
                }
            } else {
                // Points beyond a bounded grid were clamped into its edge cells, so a
                // query beyond it scans the edge cell (the distance test does the rest).
                let lo = (c - 1).clamp(0, n - 1);
                let hi = (c + 1).clamp(0, n - 1);
                for cc in lo..=hi {
                    cells[k][counts[k]] = cc as usize;
                    counts[k] += 1;
                }
            }
        }
        // Odometer over the per-axis choices.
        let mut pick = [0usize; D];
        loop {
            let mut c = [0usize; D];
            let mut w = [0i8; D];
            for k in 0..D {
                c[k] = cells[k][pick[k]];
                w[k] = wraps[k][pick[k]];
            }
            let cell = self.linear(&c);
            let (start, end) = (self.cell_start[cell] as usize, self.cell_start[cell + 1] as usize);
            f(&self.sorted[start..end], w);
            let mut k = 0;
            loop {
                if k == D {
                    return;
                }
                pick[k] += 1;
                if pick[k] < counts[k] {
                    break;
                }
                pick[k] = 0;
                k += 1;
            }
        }
    }

    /// Squared search radius.
    pub fn radius2(&self) -> f64 {
        self.radius2
    }
}

#[cfg(test)]
mod tests {
    use super::super::{brute_force_neighbours, Domain};
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn cell_list_neighbours<const D: usize>(
        domain: &Domain<D>,
        radius: f64,
        points: &[Vector<D>],
        queries: &[Vector<D>],
    ) -> Vec<Vec<usize>> {
        let mut cl = CellList::new(*domain, radius);
        cl.update(points);
        queries
            .iter()
            .map(|q| {
                let mut v = Vec::new();
                cl.for_each_neighbour(points, q, |j, xij, r2| {
                    // The reported difference is the minimum image.
                    let d = domain.delta(q, &points[j]);
                    assert!((d - xij).norm() < 1e-12, "xij {xij:?} vs minimum image {d:?}");
                    assert!((r2 - d.norm_squared()).abs() < 1e-12);
                    v.push(j)
                });
                v.sort();
                v
            })
            .collect()
    }

    fn random_points<const D: usize>(rng: &mut ChaCha8Rng, n: usize, d: &Domain<D>) -> Vec<Vector<D>> {
        (0..n)
            .map(|_| {
                let mut x = Vector::<D>::zeros();
                for k in 0..D {
                    x[k] = d.min[k] + rng.gen::<f64>() * d.length(k);
                }
                x
            })
            .collect()
    }

    /// Neighbour sets must agree except for pairs whose distance equals the radius to within
    /// rounding (the minimum image and the cell shift round differently there).
    fn check<const D: usize>(domain: Domain<D>, radius: f64, points: Vec<Vector<D>>) {
        let brute = brute_force_neighbours(&domain, radius, &points, &points);
        let cells = cell_list_neighbours(&domain, radius, &points, &points);
        let clear = |i: usize, v: &[usize]| -> Vec<usize> {
            v.iter()
                .copied()
                .filter(|&j| (domain.delta(&points[i], &points[j]).norm() - radius).abs() > 1e-12 * radius)
                .collect()
        };
        for i in 0..points.len() {
            assert_eq!(
                clear(i, &brute[i]),
                clear(i, &cells[i]),
                "point {i}, radius {radius}, domain {domain:?}"
            );
        }
        assert!(brute.iter().map(|v| v.len()).sum::<usize>() > points.len(), "test has pairs");
    }

    #[test]
    fn random_points_periodic_and_bounded_2d() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for &radius in &[0.05, 0.13, 0.3, 0.45] {
            for periodic in [[true, true], [false, false], [true, false]] {
                let d = Domain { min: [0.0, -0.5], max: [1.0, 0.7], periodic };
                let pts = random_points(&mut rng, 400, &d);
                check(d, radius, pts);
            }
        }
    }

    #[test]
    fn random_points_periodic_and_bounded_3d() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for &radius in &[0.1, 0.26, 0.49] {
            for periodic in [[true; 3], [false; 3], [true, false, true]] {
                let d = Domain { min: [0.0; 3], max: [1.0, 1.0, 1.0], periodic };
                let pts = random_points(&mut rng, 300, &d);
                check(d, radius, pts);
            }
        }
    }

    #[test]
    fn lattice_with_points_on_cell_and_box_edges() {
        // A lattice whose spacing divides the box: many points sit exactly on cell faces,
        // at the box edge and at exactly the search radius from each other.
        let n = 20;
        let dx = 1.0 / n as f64;
        let mut pts: Vec<Vector<2>> = Vec::new();
        for i in 0..n {
            for j in 0..n {
                pts.push(Vector::<2>::new(i as f64 * dx, j as f64 * dx));
            }
        }
        // Points a hair inside the upper edge.
        pts.push(Vector::<2>::new(1.0 - 1e-15, 0.5));
        pts.push(Vector::<2>::new(0.5, 1.0 - f64::EPSILON));
        for radius in [3.0 * dx, 2.0 * dx, 0.1 + 1e-12, 0.3] {
            check(Domain::periodic([0.0, 0.0], [1.0, 1.0]), radius, pts.clone());
            check(Domain::bounded([0.0, 0.0], [1.0, 1.0]), radius, pts.clone());
        }
    }

    #[test]
    fn queries_from_another_body_and_outside_a_bounded_grid() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let d = Domain::bounded([0.0, 0.0], [1.0, 1.0]);
        let pts = random_points(&mut rng, 300, &d);
        let wide = Domain::bounded([-0.4, -0.4], [1.4, 1.4]);
        let queries = random_points(&mut rng, 200, &wide);
        for radius in [0.07, 0.2] {
            let brute = brute_force_neighbours(&d, radius, &pts, &queries);
            let cells = cell_list_neighbours(&d, radius, &pts, &queries);
            assert_eq!(brute, cells);
        }
    }

    #[test]
    fn reordering_keeps_neighbour_sets() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let d = Domain::periodic([0.0, 0.0], [1.0, 1.0]);
        let pts = random_points(&mut rng, 500, &d);
        let mut cl = CellList::new(d, 0.1);
        cl.update(&pts);
        let sorted: Vec<Vector<2>> = cl.order().iter().map(|&i| pts[i as usize]).collect();
        cl.mark_reordered();
        let brute = brute_force_neighbours(&d, 0.1, &sorted, &sorted);
        for (i, q) in sorted.iter().enumerate() {
            let mut v = Vec::new();
            cl.for_each_neighbour(&sorted, q, |j, _, _| v.push(j));
            v.sort();
            assert_eq!(v, brute[i]);
        }
    }
}
