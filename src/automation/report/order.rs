//! Observed order of convergence from an error sequence.

/// Observed order between consecutive resolutions, `log(e_i/e_{i+1}) / log(h_i/h_{i+1})`.
///
/// Returns one entry per consecutive pair (length `min(h.len(), err.len()) - 1`, or empty).
/// An entry is `None` when either error is non-positive or non-finite, or the two
/// resolutions are equal, non-positive or non-finite.
pub fn observed_order(h: &[f64], err: &[f64]) -> Vec<Option<f64>> {
    let n = h.len().min(err.len());
    let ok = |v: f64| v.is_finite() && v > 0.0;
    (1..n)
        .map(|i| {
            let (h0, h1, e0, e1) = (h[i - 1], h[i], err[i - 1], err[i]);
            (ok(h0) && ok(h1) && ok(e0) && ok(e1) && h0 != h1).then(|| (e0 / e1).ln() / (h0 / h1).ln())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_order_errors_give_two() {
        let h = [0.1, 0.05, 0.025, 0.0125];
        let e: Vec<f64> = h.iter().map(|h| 3.7 * h * h).collect();
        let p = observed_order(&h, &e);
        assert_eq!(p.len(), 3);
        for q in p {
            assert!((q.unwrap() - 2.0).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_errors_give_none() {
        let h = [0.1, 0.05, 0.025, 0.0125];
        let e = [1e-2, 0.0, 2.5e-3, f64::NAN];
        assert_eq!(observed_order(&h, &e), vec![None, None, None]);
        let e = [1e-2, 2.5e-3, -1.0, 1e-4];
        let p = observed_order(&h, &e);
        assert!((p[0].unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(&p[1..], &[None, None]);
        assert!(observed_order(&[0.1], &[1.0]).is_empty());
        assert_eq!(observed_order(&[0.1, 0.1], &[1.0, 0.5]), vec![None]);
    }
}
