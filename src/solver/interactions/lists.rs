//! The neighbour lists of interacting bodies, each pair carrying its kernel values,
//! evaluated once a step as the list is built (the passes then evaluate no kernel).

use crate::solver::equations::{regularised_laplacian, Pair};
use crate::solver::kernel::{Kernel, ScaledKernel};
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Listed, NeighbourList};

/// A neighbour list whose pairs carry their [`PairKernel`].
pub type KernelList<const D: usize> = NeighbourList<D, PairKernel>;

/// The kernel values of a listed pair, evaluated for all the pairs of a point in one
/// vectorised loop (the passes then divide nothing for them).
#[derive(Clone, Copy, Debug, Default)]
pub struct PairKernel {
    /// W_ab.
    pub w: f64,
    /// `(1/r) dW/dr`, which turns `x_ab` into `grad_a W_ab`.
    pub grad_factor: f64,
    /// `x_ab . grad W / (r^2 + 0.01 h^2)` ([`regularised_laplacian`]).
    pub lap: f64,
}

impl PairKernel {
    /// The pair at difference `xij` (`r2 = |xij|^2`) for smoothing length `h`.
    #[inline(always)]
    pub fn pair<const D: usize>(&self, xij: Vector<D>, r2: f64, h: f64) -> Pair<D> {
        Pair::with_laplacian(xij, r2, h, self.w, self.grad_factor, self.lap)
    }
}

/// Builds the list of the neighbours of the points `x` (binned by `cells`, smoothing length
/// `h`) among themselves, with the kernel values of each pair.
pub fn build_kernel_list<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    x: &[Vector<D>],
    h: f64,
    k: &Kernel,
) {
    let k = k.scaled(h);
    nl.build(cells, x, |r2, out| kernel_payload(&k, r2, out));
}

/// As [`build_kernel_list`], also summing each point's density over its neighbours,
/// `sum_b m_b W_ab`, into `rho` while its pairs are in cache.
pub fn build_kernel_list_summing_density<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    (x, m, h): (&[Vector<D>], &[f64], f64),
    k: &Kernel,
    rho: &mut Vec<f64>,
) {
    rho.resize(x.len(), 0.0);
    let list = KernelAndDensity::new(m, h, k);
    nl.build_reducing(cells, x, |r2, out| list.payload(r2, out), rho, |p| list.density(p));
}

/// What a list build computes for each pair, its [`PairKernel`] from the pair's squared
/// distance, and for each point as its pairs are listed, its summation density.
pub struct KernelAndDensity<'a> {
    k: ScaledKernel,
    m: &'a [f64],
}

impl<'a> KernelAndDensity<'a> {
    /// For points of masses `m` and smoothing length `h`.
    pub fn new(m: &'a [f64], h: f64, k: &Kernel) -> Self {
        Self { k: k.scaled(h), m }
    }

    /// The payloads of the pairs at squared distances `r2`.
    pub fn payload(&self, r2: &[f64], out: &mut [PairKernel]) {
        kernel_payload(&self.k, r2, out);
    }

    /// `sum_b m_b W_ab` over a point's pairs.
    pub fn density(&self, pairs: Listed<'_, PairKernel>) -> f64 {
        pairs.iter().fold(0.0, |s, (j, kw)| s + self.m[j] * kw.w)
    }
}

/// Builds the list of the neighbours of `queries` (a body of smoothing length `h`) among
/// `sources` (binned by `cells`), with the kernel values of each pair.
pub fn build_kernel_list_cross<const D: usize>(
    nl: &mut KernelList<D>,
    cells: &CellList<D>,
    sources: &[Vector<D>],
    queries: &[Vector<D>],
    h: f64,
    k: &Kernel,
) {
    let k = k.scaled(h);
    nl.build_cross(cells, sources, queries, |r2, out| kernel_payload(&k, r2, out));
}

/// The [`PairKernel`]s of the pairs at squared distances `r2`.
fn kernel_payload(k: &ScaledKernel, r2: &[f64], out: &mut [PairKernel]) {
    let h = k.h;
    k.w_and_grad_factor_map(r2, out, |r2, w, grad_factor| PairKernel {
        w,
        grad_factor,
        lap: regularised_laplacian(grad_factor, r2, h),
    });
}
