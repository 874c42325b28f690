//! A numerical-fracture detector for a solid body (the tensile instability tears an SPH
//! solid apart into clusters, CTVF sec. 4.4, fig. 18b): two particles are connected when
//! they are closer than `link` times the initial spacing `dx`; the body's clusters are the
//! connected components of that graph (union-find), and its largest gap is the largest
//! distance from a particle to its nearest neighbour, in units of `dx`. An intact lattice
//! is one cluster with a largest gap near 1.
//!
//! Pairs are found by a sweep along the first axis (particles sorted by `x_0`, each compared
//! with those ahead of it within the search reach): `O(n k)` for `k` particles within reach,
//! cheap enough at the output cadence.

use crate::solver::math::Vector;

/// The farthest the nearest neighbour is looked for, in units of `dx`: a larger gap is
/// reported as this value (a particle alone this far from every other is torn off anyway).
pub const GAP_CAP: f64 = 10.0;

/// What [`detect`] finds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fracture {
    /// Number of connected clusters (1: intact).
    pub clusters: usize,
    /// Largest nearest-neighbour distance over the particles, in units of `dx` (capped at
    /// [`GAP_CAP`]).
    pub max_gap: f64,
}

/// The worst of [`detect`] over a run: the largest cluster count and the largest gap seen,
/// for the `clusters_max` and `max_gap` metrics of the solid scenes, and the time the body
/// was first seen in more clusters than intact (`fracture_time`), where the scene follows
/// it ([`observe_at`](Self::observe_at)). A run that blows up after it fractured keeps all
/// three: they are running records, valid before the end.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Worst {
    /// The largest number of clusters seen.
    pub clusters_max: usize,
    /// The largest nearest-neighbour distance seen, in units of `dx`.
    pub max_gap: f64,
    /// The first time the body was seen in more clusters than intact.
    #[serde(default)]
    pub fractured_at: Option<f64>,
}

impl Worst {
    /// [`detect`] at `x` now, folded into the worst so far; returns what it found.
    pub fn observe<const D: usize>(&mut self, x: &[Vector<D>], dx: f64, link: f64) -> Fracture {
        let f = detect(x, dx, link);
        self.clusters_max = self.clusters_max.max(f.clusters);
        self.max_gap = self.max_gap.max(f.max_gap);
        f
    }

    /// [`observe`](Self::observe) at time `t`, recording the first time the particles fall
    /// into more than `intact` clusters (1 for one body; 2 for two bodies apart).
    pub fn observe_at<const D: usize>(
        &mut self,
        t: f64,
        x: &[Vector<D>],
        (dx, link): (f64, f64),
        intact: usize,
    ) -> Fracture {
        let f = self.observe(x, dx, link);
        if f.clusters > intact && self.fractured_at.is_none() {
            self.fractured_at = Some(t);
        }
        f
    }

    /// The worst so far together with [`detect`] at `x` (the end of a run, whatever the
    /// sampling), without changing the record.
    pub fn with<const D: usize>(&self, x: &[Vector<D>], dx: f64, link: f64) -> Worst {
        let mut w = *self;
        w.observe(x, dx, link);
        w
    }

    /// The `clusters_max` and `max_gap` metrics, and `fracture_time` where the body has
    /// fractured.
    pub fn metrics(&self) -> Vec<(String, f64)> {
        let mut m = vec![("clusters_max".into(), self.clusters_max as f64), ("max_gap".into(), self.max_gap)];
        if let Some(t) = self.fractured_at {
            m.push(("fracture_time".into(), t));
        }
        m
    }
}

/// The clusters and largest gap of the particles at `x` (initial spacing `dx`), two
/// particles being connected when closer than `link * dx`.
pub fn detect<const D: usize>(x: &[Vector<D>], dx: f64, link: f64) -> Fracture {
    let n = x.len();
    if n == 0 {
        return Fracture { clusters: 0, max_gap: 0.0 };
    }
    let reach = GAP_CAP.max(link) * dx;
    let (reach2, link2) = (reach * reach, (link * dx) * (link * dx));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| x[a][0].total_cmp(&x[b][0]));
    let mut parent: Vec<usize> = (0..n).collect();
    let mut nearest2 = vec![reach2; n];
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if x[j][0] - x[i][0] >= reach {
                break;
            }
            let r2 = (x[i] - x[j]).norm_squared();
            nearest2[i] = nearest2[i].min(r2);
            nearest2[j] = nearest2[j].min(r2);
            if r2 < link2 {
                union(&mut parent, i, j);
            }
        }
    }
    let clusters = (0..n).filter(|&i| find(&mut parent, i) == i).count();
    let max_gap = nearest2.iter().copied().fold(0.0, f64::max).sqrt() / dx;
    Fracture { clusters, max_gap }
}

/// The root of `i`'s set, halving the path on the way.
fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of `a` and `b` (the smaller root under the larger, so that the result
/// does not depend on the order of the pairs).
fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        parent[hi] = lo;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(nx: usize, ny: usize, dx: f64, offset: [f64; 2]) -> Vec<Vector<2>> {
        (0..nx * ny)
            .map(|k| Vector::<2>::new(offset[0] + (k % nx) as f64 * dx, offset[1] + (k / nx) as f64 * dx))
            .collect()
    }

    /// One lattice is one cluster with gap 1; two lattices 3 dx apart are two, gap 1 (every
    /// particle has a neighbour at dx); a particle 4 dx from the rest makes a third
    /// cluster and a gap of 4.
    #[test]
    fn clusters_and_gaps_of_lattices() {
        let dx = 0.1;
        let one = lattice(10, 4, dx, [0.0, 0.0]);
        let f = detect(&one, dx, 1.5);
        assert_eq!(f.clusters, 1);
        assert!((f.max_gap - 1.0).abs() < 1e-9, "{f:?}");
        let mut two = one.clone();
        two.extend(lattice(5, 4, dx, [1.2, 0.0])); // 0.9 .. 1.2: a gap of 3 dx
        let f = detect(&two, dx, 1.5);
        assert_eq!(f.clusters, 2);
        assert!((f.max_gap - 1.0).abs() < 1e-9, "{f:?}");
        two.push(Vector::<2>::new(0.4, 0.7)); // 4 dx above the top row (y = 0.3)
        let f = detect(&two, dx, 1.5);
        assert_eq!(f.clusters, 3);
        assert!((f.max_gap - 4.0).abs() < 1e-9, "{f:?}");
        let far = vec![Vector::<2>::zeros(), Vector::<2>::new(100.0, 0.0)];
        assert_eq!(detect(&far, dx, 1.5), Fracture { clusters: 2, max_gap: GAP_CAP });
    }
}
