//! The distance test of the neighbour-list build: which of a point's candidates lie within
//! the search radius. It is the innermost loop of the build (about 80 candidates per point
//! in 2D for 28 neighbours), so it has vector paths next to the portable one, chosen at run
//! time: AVX-512 (eight candidates per instruction, the accepted ones packed with a register
//! compress) and AVX2 (four, packed by a permutation looked up from the mask, for CPUs
//! without AVX-512 such as AMD's Zen 3). All compute `r2 = sum_d ((x_i - shift) - x_j)_d^2`
//! with the same operations in the same order, so they accept the same candidates and
//! return the same r2, bit for bit (tested), and the r2 equals the one
//! `NeighbourList::for_each` recomputes.

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

/// The implementation of the test; every one gives the same result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// Scalar, on any CPU.
    Portable,
    /// Four candidates a vector (x86-64 with AVX2).
    Avx2,
    /// Eight candidates a vector (x86-64 with AVX-512F).
    Avx512,
}

impl Path {
    /// Every path, slowest first.
    const ALL: [Path; 3] = [Path::Portable, Path::Avx2, Path::Avx512];

    /// Whether this CPU runs the path (a cached bit: cheap enough to ask for every point).
    pub fn runs(self) -> bool {
        match self {
            Path::Portable => true,
            // Miri cannot ask the CPU: a path runs there if the build enables its feature
            // (`RUSTFLAGS=-Ctarget-feature=+avx2`; Miri interprets the AVX2 path's
            // intrinsics, not all of the AVX-512 path's).
            Path::Avx2 if cfg!(miri) => cfg!(target_feature = "avx2"),
            Path::Avx512 if cfg!(miri) => cfg!(target_feature = "avx512f"),
            #[cfg(target_arch = "x86_64")]
            Path::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(target_arch = "x86_64")]
            Path::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The fastest path this CPU runs.
    pub fn fastest() -> Path {
        Self::ALL.into_iter().rev().find(|p| p.runs()).unwrap_or(Path::Portable)
    }

    /// Its name, as the bench prints it.
    pub fn name(self) -> &'static str {
        match self {
            Path::Portable => "portable",
            Path::Avx2 => "avx2",
            Path::Avx512 => "avx512",
        }
    }

    /// Every path this CPU runs, slowest first (for the tests, which compare them all).
    #[cfg(test)]
    pub fn available() -> Vec<Path> {
        Self::ALL.into_iter().filter(|p| p.runs()).collect()
    }
}

/// Where the accepted candidates go, from the front: their entries and their r2. Both must
/// hold the number of candidates plus [`LANES`].
pub struct Accepted<'a> {
    pub entries: &'a mut [u32],
    pub r2: &'a mut [f64],
}

/// Writes the candidates within `sqrt(r2max)` of `xi` to `out` and returns how many.
/// A `path` this CPU cannot run falls back to the portable one.
pub fn within<const D: usize>(
    path: Path,
    xi: &Vector<D>,
    c: &Candidates,
    r2max: f64,
    out: Accepted,
) -> usize {
    let m = c.entries.len();
    assert!(c.x.len() == D * m && c.shift.len() == D * m, "one position and shift per candidate and axis");
    assert!(out.entries.len() >= m + LANES && out.r2.len() >= m + LANES, "room past the last candidate");
    // SAFETY (both vector paths): the CPU has the feature (checked here by `runs`, so that
    // this function stays sound whatever `path` a caller passes), and the lengths were
    // checked above: every load reads lanes below `m` (AVX-512 masks the others off; AVX2
    // leaves a partial vector to the portable loop), every store writes a full vector at
    // an index at most `m`.
    #[cfg(target_arch = "x86_64")]
    match path {
        Path::Avx512 if path.runs() => return unsafe { avx512::within(xi, c, r2max, out) },
        Path::Avx2 if path.runs() => return unsafe { avx2::within(xi, c, r2max, out) },
        _ => {}
    }
    let _ = path;
    portable(xi, c, r2max, out, 0, 0)
}

/// The portable path, from candidate `k0` with `len` accepted before it: appends every
/// candidate and advances the length only for the accepted ones, so there is no branch on
/// the distance test (which is unpredictable).
fn portable<const D: usize>(
    xi: &Vector<D>,
    c: &Candidates,
    r2max: f64,
    out: Accepted,
    k0: usize,
    len: usize,
) -> usize {
    let m = c.entries.len();
    let mut len = len;
    for (k, &e) in c.entries.iter().enumerate().skip(k0) {
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

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{portable, Accepted, Candidates, Vector};
    use std::arch::x86_64::*;

    /// For each 4-bit mask of accepted lanes, the 32-bit lanes that pack them to the front:
    /// of four f64 (two 32-bit halves each, `R2`) and of four u32 (`ENTRIES`).
    const R2: [[i32; 8]; 16] = pack(2);
    const ENTRIES: [[i32; 8]; 16] = pack(1);

    const fn pack(width: i32) -> [[i32; 8]; 16] {
        let mut lut = [[0; 8]; 16];
        let mut mask = 0;
        while mask < 16 {
            let (mut lane, mut p) = (0, 0);
            while lane < 4 {
                if mask & (1 << lane) != 0 {
                    let mut h = 0;
                    while h < width {
                        lut[mask][(p * width + h) as usize] = lane * width + h;
                        h += 1;
                    }
                    p += 1;
                }
                lane += 1;
            }
            mask += 1;
        }
        lut
    }

    /// Four candidates at a time: r2 per lane, a compare into a 4-bit mask, the accepted
    /// lanes packed by the permutation of that mask and stored whole at the current length;
    /// the last partial vector goes to the portable loop.
    #[target_feature(enable = "avx2")]
    pub unsafe fn within<const D: usize>(xi: &Vector<D>, c: &Candidates, r2max: f64, out: Accepted) -> usize {
        let m = c.entries.len();
        let whole = m - m % 4;
        let limit = _mm256_set1_pd(r2max);
        let mut len = 0;
        let mut k = 0;
        while k < whole {
            let mut r2 = _mm256_setzero_pd();
            for d in 0..D {
                let x = _mm256_loadu_pd(c.x.as_ptr().add(d * m + k));
                let s = _mm256_loadu_pd(c.shift.as_ptr().add(d * m + k));
                let t = _mm256_sub_pd(_mm256_sub_pd(_mm256_set1_pd(xi[d]), s), x);
                r2 = _mm256_add_pd(r2, _mm256_mul_pd(t, t));
            }
            let keep = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(r2, limit)) as usize;
            let by = _mm256_loadu_si256(R2[keep].as_ptr() as *const __m256i);
            let r2 = _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(r2), by));
            _mm256_storeu_pd(out.r2.as_mut_ptr().add(len), r2);
            let e = _mm256_castsi128_si256(_mm_loadu_si128(c.entries.as_ptr().add(k) as *const __m128i));
            let by = _mm256_loadu_si256(ENTRIES[keep].as_ptr() as *const __m256i);
            let e = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(e, by));
            _mm_storeu_si128(out.entries.as_mut_ptr().add(len) as *mut __m128i, e);
            len += keep.count_ones() as usize;
            k += 4;
        }
        portable(xi, c, r2max, out, whole, len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn vector_and_portable_paths_agree_bit_for_bit() {
        assert_eq!(Path::available().last(), Some(&Path::fastest()));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for m in [0, 1, 3, 4, 5, 7, 8, 9, 63, 81, 400] {
            let entries: Vec<u32> = (0..m as u32).map(|k| k * 3 + 1).collect();
            let x: Vec<f64> = (0..2 * m).map(|_| rng.gen::<f64>()).collect();
            let shift: Vec<f64> = (0..2 * m).map(|_| [-1.0, 0.0, 1.0][rng.gen_range(0..3)]).collect();
            let c = Candidates { entries: &entries, x: &x, shift: &shift };
            let xi = nalgebra::SVector::<f64, 2>::new(0.5, 0.25);
            let run = |path| {
                let (mut e, mut r2) = (vec![0u32; m + LANES], vec![0.0; m + LANES]);
                let n = within(path, &xi, &c, 0.09, Accepted { entries: &mut e, r2: &mut r2 });
                e.truncate(n);
                r2.truncate(n);
                (e, r2)
            };
            let (e, r2) = run(Path::Portable);
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
            for path in Path::available() {
                assert_eq!(run(path), (e.clone(), r2.clone()), "{path:?}, m = {m}");
            }
        }
    }
}
