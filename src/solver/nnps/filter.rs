//! The distance test of the neighbour-list build: which of a point's candidates lie within
//! the search radius. It is the innermost loop of the build (about 80 candidates per point
//! in 2D for 28 neighbours), so it has an AVX-512 path (eight candidates per instruction,
//! the accepted ones packed with a register compress) next to the portable one, chosen at
//! run time. Both compute `r2 = sum_d ((x_i - shift) - x_j)_d^2` with the same operations in
//! the same order, so they accept the same candidates and return the same r2, bit for bit
//! (tested), and the r2 equals the one `NeighbourList::for_each` recomputes.

use crate::solver::math::Vector;

/// Candidates per vector: callers leave this much room past the last candidate in the
/// output slices, which the vector path may write (and the caller then truncates).
pub const LANES: usize = 8;

/// The candidates of a point: packed entries, and their positions and image shifts stored
/// axis after axis (`x[d * m + k]` for candidate `k` of `m`).
pub struct Candidates<'a> {
    pub entries: &'a [u32],
    pub x: &'a [f64],
    pub shift: &'a [f64],
}

/// Whether this CPU runs the vector path.
pub fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Where the accepted candidates go, from the front: their entries and their r2. Both must
/// hold the number of candidates plus [`LANES`].
pub struct Accepted<'a> {
    pub entries: &'a mut [u32],
    pub r2: &'a mut [f64],
}

/// Writes the candidates within `sqrt(r2max)` of `xi` to `out` and returns how many.
/// `simd` must come from [`simd_available`].
pub fn within<const D: usize>(
    simd: bool,
    xi: &Vector<D>,
    c: &Candidates,
    r2max: f64,
    out: Accepted,
) -> usize {
    let m = c.entries.len();
    assert!(c.x.len() == D * m && c.shift.len() == D * m, "one position and shift per candidate and axis");
    assert!(out.entries.len() >= m + LANES && out.r2.len() >= m + LANES, "room past the last candidate");
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: the CPU has AVX-512F (checked by the caller through `simd_available`), and
        // the lengths were checked above: every load reads lanes below `m` (the others are
        // masked off), every store writes a full vector at an index at most `m`.
        return unsafe { avx512::within(xi, c, r2max, out) };
    }
    let _ = simd;
    portable(xi, c, r2max, out)
}

/// The portable path: appends every candidate and advances the length only for the
/// accepted ones, so there is no branch on the distance test (which is unpredictable).
fn portable<const D: usize>(xi: &Vector<D>, c: &Candidates, r2max: f64, out: Accepted) -> usize {
    let m = c.entries.len();
    let mut len = 0;
    for (k, &e) in c.entries.iter().enumerate() {
        let mut r2 = 0.0;
        for d in 0..D {
            let t = (xi[d] - c.shift[d * m + k]) - c.x[d * m + k];
            r2 += t * t;
        }
        // `len <= k < m`, within both outputs (checked by `within`); the compiler cannot
        // see it, and a bounds check per store costs a third of this loop.
        // SAFETY: as just said.
        unsafe {
            *out.entries.get_unchecked_mut(len) = e;
            *out.r2.get_unchecked_mut(len) = r2;
        }
        len += (r2 < r2max) as usize;
    }
    len
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{Accepted, Candidates, Vector, LANES};
    use std::arch::x86_64::*;

    /// Eight candidates at a time: r2 per lane, a compare into a mask, and the accepted
    /// lanes packed in a register (a compress to memory is slow on some CPUs) and stored
    /// whole at the current length.
    #[target_feature(enable = "avx512f")]
    pub unsafe fn within<const D: usize>(xi: &Vector<D>, c: &Candidates, r2max: f64, out: Accepted) -> usize {
        let m = c.entries.len();
        let r2max = _mm512_set1_pd(r2max);
        let mut len = 0;
        let mut k = 0;
        while k < m {
            let lanes = (m - k).min(LANES);
            let live: __mmask8 = (((1u32 << lanes) - 1) & 0xff) as u8;
            let mut r2 = _mm512_setzero_pd();
            for d in 0..D {
                let x = _mm512_maskz_loadu_pd(live, c.x.as_ptr().add(d * m + k));
                let s = _mm512_maskz_loadu_pd(live, c.shift.as_ptr().add(d * m + k));
                let t = _mm512_sub_pd(_mm512_sub_pd(_mm512_set1_pd(xi[d]), s), x);
                r2 = _mm512_add_pd(r2, _mm512_mul_pd(t, t));
            }
            let keep = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(live, r2, r2max);
            _mm512_storeu_pd(out.r2.as_mut_ptr().add(len), _mm512_maskz_compress_pd(keep, r2));
            let e = _mm512_maskz_loadu_epi32(live as __mmask16, c.entries.as_ptr().add(k) as *const i32);
            let e = _mm512_maskz_compress_epi32(keep as __mmask16, e);
            _mm256_storeu_si256(out.entries.as_mut_ptr().add(len) as *mut __m256i, _mm512_castsi512_si256(e));
            len += keep.count_ones() as usize;
            k += LANES;
        }
        len
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn vector_and_portable_paths_agree_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for m in [0, 1, 7, 8, 9, 63, 81] {
            let entries: Vec<u32> = (0..m as u32).map(|k| k * 3 + 1).collect();
            let x: Vec<f64> = (0..2 * m).map(|_| rng.gen::<f64>()).collect();
            let shift: Vec<f64> = (0..2 * m).map(|_| [-1.0, 0.0, 1.0][rng.gen_range(0..3)]).collect();
            let c = Candidates { entries: &entries, x: &x, shift: &shift };
            let xi = nalgebra::SVector::<f64, 2>::new(0.5, 0.25);
            let run = |simd| {
                let (mut e, mut r2) = (vec![0u32; m + LANES], vec![0.0; m + LANES]);
                let n = within(simd, &xi, &c, 0.09, Accepted { entries: &mut e, r2: &mut r2 });
                e.truncate(n);
                r2.truncate(n);
                (e, r2)
            };
            let (e, r2) = run(false);
            // Against a direct evaluation.
            let mut expect = Vec::new();
            for k in 0..m {
                let d = nalgebra::SVector::<f64, 2>::new(
                    (xi[0] - shift[k]) - x[k],
                    (xi[1] - shift[m + k]) - x[m + k],
                );
                if d.norm_squared() < 0.09 {
                    expect.push((entries[k], d.norm_squared()));
                }
            }
            assert_eq!(e.iter().copied().zip(r2.iter().copied()).collect::<Vec<_>>(), expect, "m = {m}");
            if simd_available() {
                assert_eq!(run(true), (e, r2), "m = {m}");
            }
        }
    }
}
