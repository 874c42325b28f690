//! Measurements against published data: Shepard interpolation at a point, and the RMS
//! deviation of a sampled curve from published points.

use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::systems::Fluid;

/// Shepard interpolation of `value` (per fluid particle) at `q`: `sum v W / sum W`, by
/// brute force over the particles (for a handful of probe points at the end of a run).
pub fn shepard(f: &Fluid<2>, kernel: &Kernel, q: Vector<2>, value: impl Fn(usize) -> f64) -> Option<f64> {
    let k = kernel.scaled(f.h);
    let r2max = (kernel.support() * f.h).powi(2);
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..f.len() {
        let r2 = (q - f.x[j]).norm_squared();
        if r2 < r2max {
            let w = k.w(r2.sqrt());
            num += value(j) * w;
            den += w;
        }
    }
    (den > 0.0).then(|| num / den)
}

/// The RMS deviation of a sampled curve `ours` (time, value; in time order) from the points
/// `reference` within its time range: ours interpolated linearly at each reference time
/// (the first sample's value before it); reference points after our last sample are
/// skipped. `None` when no reference point falls in range.
pub fn rms_deviation(ours: &[(f64, f64)], reference: &[(f64, f64)]) -> Option<f64> {
    let (mut sum2, mut n) = (0.0, 0);
    for &(ts, z) in reference {
        let Some(i) = ours.iter().position(|&(t, _)| t >= ts) else { continue };
        let value = if i == 0 {
            ours[0].1
        } else {
            let ((t0, z0), (t1, z1)) = (ours[i - 1], ours[i]);
            z0 + (z1 - z0) * (ts - t0) / (t1 - t0).max(1e-300)
        };
        sum2 += (value - z).powi(2);
        n += 1;
    }
    (n > 0).then(|| (sum2 / n as f64).sqrt())
}
