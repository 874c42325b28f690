//! Smoothing kernels W(r, h) with their 1D, 2D and 3D normalisations.
//!
//! Every kernel is written as `W = sigma_D / h^D * w(q)` with `q = r / h`, so the support
//! radius is `support() * h`. The kernel is a small `Copy` enum rather than a trait object:
//! the match is loop-invariant and the branch predictor removes its cost in the pair loops
//! (measured in `sphrepro bench`).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The kernels the solver offers, by the names `--set kernel=...` accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// Cubic B-spline (Monaghan & Lattanzio 1985), support 2h.
    CubicSpline,
    /// Quintic spline (Morris et al. 1997), support 3h: the CTVF paper's choice.
    QuinticSpline,
    /// Wendland C2 (Wendland 1995, the "WendlandQuintic" of PySPH), support 2h.
    WendlandC2,
    /// Gaussian exp(-q^2), truncated at q = 3 (normalisation error below 1e-3).
    Gaussian,
}

impl KernelKind {
    /// The name `from_name` accepts.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

// In the order of the enum: `name` indexes `NAMES` by variant.
named_choices!(KernelKind {
    CubicSpline => "cubic_spline",
    QuinticSpline => "quintic_spline",
    WendlandC2 => "wendland_c2",
    Gaussian => "gaussian",
});

/// A kernel bound to a dimension: `sigma` is the normalisation for that `D`.
#[derive(Clone, Copy, Debug)]
pub struct Kernel {
    kind: KernelKind,
    sigma: f64,
    dim: i32,
}

impl Kernel {
    /// The kernel `kind` normalised in `dim` dimensions (1, 2 or 3).
    pub fn new(kind: KernelKind, dim: usize) -> Self {
        assert!((1..=3).contains(&dim), "kernels are defined for 1, 2 and 3 dimensions");
        let sigma = match (kind, dim) {
            (KernelKind::CubicSpline, 1) => 2.0 / 3.0,
            (KernelKind::CubicSpline, 2) => 10.0 / (7.0 * PI),
            (KernelKind::CubicSpline, _) => 1.0 / PI,
            (KernelKind::QuinticSpline, 1) => 1.0 / 120.0,
            (KernelKind::QuinticSpline, 2) => 7.0 / (478.0 * PI),
            (KernelKind::QuinticSpline, _) => 1.0 / (120.0 * PI),
            (KernelKind::WendlandC2, 1) => 5.0 / 8.0,
            (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI),
            (KernelKind::WendlandC2, _) => 21.0 / (16.0 * PI),
            (KernelKind::Gaussian, d) => 1.0 / PI.powf(d as f64 / 2.0),
        };
        Self { kind, sigma, dim: dim as i32 }
    }

    /// Which kernel this is.
    pub fn kind(&self) -> KernelKind {
        self.kind
    }

    /// Support radius in units of h: W = 0 for r >= support() * h.
    pub fn support(&self) -> f64 {
        match self.kind {
            KernelKind::CubicSpline | KernelKind::WendlandC2 => 2.0,
            KernelKind::QuinticSpline | KernelKind::Gaussian => 3.0,
        }
    }

    /// `w(q)` and `dw/dq` of the unnormalised kernel. Written without branches on `q`
    /// (clamped polynomial pieces): neighbours sit at all distances, so a branch per piece
    /// would be mispredicted in the pair loops.
    #[inline(always)]
    fn shape(&self, q: f64) -> (f64, f64) {
        match self.kind {
            KernelKind::CubicSpline => cubic_spline(q),
            KernelKind::QuinticSpline => quintic_spline(q),
            KernelKind::WendlandC2 => wendland_c2(q),
            KernelKind::Gaussian => gaussian(q),
        }
    }

    /// `1 / h^D`.
    #[inline(always)]
    fn inv_hd(&self, h: f64) -> f64 {
        1.0 / h.powi(self.dim)
    }

    /// This kernel at a fixed smoothing length, with `sigma / h^D` and `1/h` precomputed
    /// for the pair loops.
    pub fn scaled(&self, h: f64) -> ScaledKernel {
        ScaledKernel { kernel: *self, h, inv_h: 1.0 / h, fac: self.sigma * self.inv_hd(h) }
    }

    /// W(r, h).
    #[inline(always)]
    pub fn w(&self, r: f64, h: f64) -> f64 {
        self.sigma * self.inv_hd(h) * self.shape(r / h).0
    }

    /// W(r, h) and dW/dr(r, h) together, sharing the powers.
    #[inline(always)]
    pub fn w_dwdr(&self, r: f64, h: f64) -> (f64, f64) {
        let hinv = 1.0 / h;
        let (w, dw) = self.shape(r * hinv);
        let f = self.sigma * self.inv_hd(h);
        (f * w, f * dw * hinv)
    }

    /// (1/r) dW/dr, the factor that turns `x_ab` into `grad_a W_ab`; 0 at r = 0 where the
    /// gradient vanishes by symmetry.
    #[inline(always)]
    pub fn w_and_grad_factor(&self, r: f64, h: f64) -> (f64, f64) {
        let (w, dwdr) = self.w_dwdr(r, h);
        if r > 1e-12 * h {
            (w, dwdr / r)
        } else {
            (w, 0.0)
        }
    }
}

/// Cubic spline `w(q)`, `dw/dq`.
#[inline(always)]
fn cubic_spline(q: f64) -> (f64, f64) {
    let t2 = (2.0 - q).max(0.0);
    let t1 = (1.0 - q).max(0.0);
    (0.25 * t2 * t2 * t2 - t1 * t1 * t1, -0.75 * t2 * t2 + 3.0 * t1 * t1)
}

/// Quintic spline `w(q)`, `dw/dq`.
#[inline(always)]
fn quintic_spline(q: f64) -> (f64, f64) {
    let t3 = (3.0 - q).max(0.0);
    let t2 = (2.0 - q).max(0.0);
    let t1 = (1.0 - q).max(0.0);
    let (t3_4, t2_4, t1_4) = (t3 * t3 * t3 * t3, t2 * t2 * t2 * t2, t1 * t1 * t1 * t1);
    (t3_4 * t3 - 6.0 * t2_4 * t2 + 15.0 * t1_4 * t1, -5.0 * t3_4 + 30.0 * t2_4 - 75.0 * t1_4)
}

/// Wendland C2 `w(q)`, `dw/dq`.
#[inline(always)]
fn wendland_c2(q: f64) -> (f64, f64) {
    let t = (1.0 - 0.5 * q).max(0.0);
    let t3 = t * t * t;
    (t3 * t * (2.0 * q + 1.0), -5.0 * q * t3)
}

/// Truncated Gaussian `w(q)`, `dw/dq`.
#[inline(always)]
fn gaussian(q: f64) -> (f64, f64) {
    let e = if q < 3.0 { (-q * q).exp() } else { 0.0 };
    (e, -2.0 * q * e)
}

/// Evaluates `$body` with `$shape` bound to the shape function of kernel kind `$kind`: the
/// match is taken once, outside the loop `$body` holds, which then vectorises.
macro_rules! with_shape {
    ($kind:expr, $shape:ident => $body:expr) => {
        match $kind {
            KernelKind::CubicSpline => {
                let $shape = cubic_spline;
                $body
            }
            KernelKind::QuinticSpline => {
                let $shape = quintic_spline;
                $body
            }
            KernelKind::WendlandC2 => {
                let $shape = wendland_c2;
                $body
            }
            KernelKind::Gaussian => {
                let $shape = gaussian;
                $body
            }
        }
    };
}

/// A [`Kernel`] at one smoothing length (bodies have a uniform h).
#[derive(Clone, Copy, Debug)]
pub struct ScaledKernel {
    kernel: Kernel,
    /// Smoothing length.
    pub h: f64,
    inv_h: f64,
    fac: f64,
}

impl ScaledKernel {
    /// W(r).
    #[inline(always)]
    pub fn w(&self, r: f64) -> f64 {
        self.fac * self.kernel.shape(r * self.inv_h).0
    }

    /// W(r) and (1/r) dW/dr (0 at r = 0), the factor that turns `x_ab` into `grad_a W_ab`.
    #[inline(always)]
    pub fn w_and_grad_factor(&self, r: f64) -> (f64, f64) {
        self.w_and_grad_factor_with(r, |q| self.kernel.shape(q))
    }

    #[inline(always)]
    fn w_and_grad_factor_with(&self, r: f64, shape: impl Fn(f64) -> (f64, f64)) -> (f64, f64) {
        let (w, dw) = shape(r * self.inv_h);
        let g = if r > 1e-12 * self.h { self.fac * dw * self.inv_h / r } else { 0.0 };
        (self.fac * w, g)
    }

    /// [`w_and_grad_factor`](Self::w_and_grad_factor) at `sqrt(r2[k])` into `out[k]`: the
    /// neighbour lists evaluate all their pairs at once, in a loop the compiler vectorises
    /// (the kernel's match is outside it; the values equal the one-pair call bit for bit).
    pub fn w_and_grad_factor_batch(&self, r2: &[f64], out: &mut [(f64, f64)]) {
        self.w_and_grad_factor_map(r2, out, |_, w, f| (w, f));
    }

    /// `out[k] = f(r2[k], W, (1/r) dW/dr)` at `sqrt(r2[k])`, in one loop the compiler
    /// vectorises, for payloads that hold more of a pair than the kernel's two values.
    #[inline(always)]
    pub fn w_and_grad_factor_map<Y>(&self, r2: &[f64], out: &mut [Y], f: impl Fn(f64, f64, f64) -> Y) {
        with_shape!(self.kernel.kind, shape => {
            for (o, &r2) in out.iter_mut().zip(r2) {
                let (w, g) = self.w_and_grad_factor_with(r2.sqrt(), shape);
                *o = f(r2, w, g);
            }
        })
    }

    /// [`w`](Self::w) at `sqrt(r2[k])` into `out[k]`, as
    /// [`w_and_grad_factor_batch`](Self::w_and_grad_factor_batch).
    pub fn w_batch(&self, r2: &[f64], out: &mut [f64]) {
        with_shape!(self.kernel.kind, shape => {
            for (o, &r2) in out.iter_mut().zip(r2) {
                *o = self.fac * shape(r2.sqrt() * self.inv_h).0;
            }
        })
    }

    /// `out[k] = f(r, W(r))` at the distance `r = distance(&items[k])` of each item: one
    /// loop the compiler vectorises for callers that need a value of each pair (the
    /// kernel's match is outside it).
    #[inline(always)]
    pub fn map_batch<X, A>(
        &self,
        items: &[X],
        out: &mut [A],
        distance: impl Fn(&X) -> f64,
        f: impl Fn(f64, f64) -> A,
    ) {
        with_shape!(self.kernel.kind, shape => {
            for (a, x) in out.iter_mut().zip(items) {
                let r = distance(x);
                *a = f(r, self.fac * shape(r * self.inv_h).0);
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [KernelKind; 4] =
        [KernelKind::CubicSpline, KernelKind::QuinticSpline, KernelKind::WendlandC2, KernelKind::Gaussian];

    /// Sum of W over a lattice of spacing dx around the origin, times the cell volume.
    fn lattice_integral(k: &Kernel, dim: usize, h: f64, dx: f64) -> f64 {
        let n = (k.support() * h / dx).ceil() as i64 + 1;
        let mut s = 0.0;
        let range = -n..=n;
        let zr = if dim == 3 { range.clone() } else { 0..=0 };
        let yr = range.clone();
        for i in range.clone() {
            for j in yr.clone() {
                for l in zr.clone() {
                    // An offset lattice so that r = 0 is not the only sample near the peak.
                    let x = (i as f64 + 0.25) * dx;
                    let y = (j as f64 + 0.25) * dx;
                    let z = (l as f64 + 0.25) * dx;
                    let r = if dim == 2 { (x * x + y * y).sqrt() } else { (x * x + y * y + z * z).sqrt() };
                    s += k.w(r, h);
                }
            }
        }
        s * dx.powi(dim as i32)
    }

    #[test]
    fn kernels_integrate_to_one_over_a_lattice() {
        for kind in ALL {
            for dim in 2..=3 {
                let k = Kernel::new(kind, dim);
                let h = 1.0;
                let integral = lattice_integral(&k, dim, h, h / 8.0);
                let tol = if kind == KernelKind::Gaussian { 2e-3 } else { 1e-3 };
                assert!((integral - 1.0).abs() < tol, "{kind:?} in {dim}D integrates to {integral}");
            }
        }
    }

    #[test]
    fn gradient_matches_finite_difference() {
        for kind in ALL {
            for dim in 2..=3 {
                let k = Kernel::new(kind, dim);
                let h = 0.7;
                let mut r = 0.01;
                while r < k.support() * h - 0.01 {
                    let eps = 1e-6;
                    let fd = (k.w(r + eps, h) - k.w(r - eps, h)) / (2.0 * eps);
                    let (_, dw) = k.w_dwdr(r, h);
                    let scale = k.w(0.0, h) / h;
                    assert!((fd - dw).abs() < 1e-6 * scale, "{kind:?} {dim}D r={r}: fd {fd} analytic {dw}");
                    r += 0.013;
                }
            }
        }
    }

    #[test]
    fn zero_beyond_support() {
        for kind in ALL {
            for dim in 2..=3 {
                let k = Kernel::new(kind, dim);
                let h = 1.3;
                let rs = k.support() * h;
                for r in [rs, rs * 1.0000001, rs + 0.5, 10.0 * rs] {
                    assert_eq!(k.w(r, h), 0.0, "{kind:?} W({r})");
                    assert_eq!(k.w_dwdr(r, h).1, 0.0, "{kind:?} dW({r})");
                }
                assert!(k.w(0.99 * rs, h) >= 0.0);
            }
        }
    }

    #[test]
    fn scaled_kernel_equals_kernel() {
        for kind in ALL {
            let k = Kernel::new(kind, 2);
            let s = k.scaled(0.37);
            for r in [0.0, 0.1, 0.4, 0.9, 1.2] {
                assert!((s.w(r) - k.w(r, 0.37)).abs() <= 1e-14 * k.w(0.0, 0.37));
                let (a, b) = (s.w_and_grad_factor(r), k.w_and_grad_factor(r, 0.37));
                assert!(
                    (a.0 - b.0).abs() <= 1e-14 * k.w(0.0, 0.37)
                        && (a.1 - b.1).abs() <= 1e-12 * b.1.abs().max(1.0)
                );
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for kind in ALL {
            assert_eq!(KernelKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(KernelKind::from_name("warp9"), None);
    }

    #[test]
    fn batch_evaluation_equals_one_pair_evaluation_bit_for_bit() {
        for kind in ALL {
            let k = Kernel::new(kind, 2).scaled(0.0333);
            let r2: Vec<f64> = (0..1000).map(|i| (i as f64 * 1.1e-4).powi(2)).collect();
            let mut both = vec![(0.0, 0.0); r2.len()];
            let mut w = vec![0.0; r2.len()];
            let mut mapped = vec![(0.0, 0.0); r2.len()];
            k.w_and_grad_factor_batch(&r2, &mut both);
            k.w_batch(&r2, &mut w);
            k.map_batch(&r2, &mut mapped, |r2| r2.sqrt(), |r, w| (r, w));
            for (i, &r2) in r2.iter().enumerate() {
                assert_eq!(both[i], k.w_and_grad_factor(r2.sqrt()), "{kind:?} at r2 = {r2}");
                assert_eq!(w[i], k.w(r2.sqrt()));
                assert_eq!(mapped[i], (r2.sqrt(), w[i]));
            }
        }
    }
}
