//! Neighbour lists built once per step from a cell list and reused by every pass of the
//! step: the candidate search (and its unpredictable distance branch) is paid once, not
//! once per pass. Each entry packs the neighbour index with the periodic image it was
//! found through, so a pass recovers `x_ij` without a minimum-image rounding, and carries
//! a payload computed once per pair at build time (SPH stores the kernel value and
//! gradient factor there: the kernel is then evaluated once per pair and step).

use super::filter;
use super::{CellList, Gather};
use crate::solver::math::Vector;
use rayon::prelude::*;

/// Particles per build task; the lists are stored per chunk so building allocates nothing
/// once the chunks have grown, and the result does not depend on the thread count. (Under
/// Miri, smaller, so that a small body makes the wavefront's tiles, two chunks a tile at
/// least.)
pub const CHUNK: usize = if cfg!(miri) { 64 } else { 512 };
/// Bits of an entry holding the neighbour index (the rest hold the image code).
const J_BITS: u32 = 26;
const J_MASK: u32 = (1 << J_BITS) - 1;
/// Image codes an entry's bits above `J_BITS` can hold: the shift table has this many
/// rows (those past 3^D zero, never listed), so that looking up an entry's shift needs no
/// bounds check.
const CODES: usize = 1 << (32 - J_BITS);

/// The code of a periodic image, `wraps` (each in -1..=1) in base 3: an index into the
/// list's image shifts.
fn image_code<const D: usize>(wraps: [i8; D]) -> u32 {
    wraps.iter().rev().fold(0, |code, &w| code * 3 + (w + 1) as u32)
}

/// Where [`NeighbourList::write_pairs`] writes one point's pairs: the differences `x_ij`
/// and a value per neighbour.
pub struct PairSlices<'a, const D: usize> {
    /// `x_i - x_j`, through the periodic image the pair was found through.
    pub xij: &'a mut [Vector<D>],
    /// The neighbours' values.
    pub value: &'a mut [f64],
}

/// One point's neighbours as just listed by [`NeighbourList::build_reducing`].
pub struct Listed<'a, P> {
    entries: &'a [u32],
    payload: &'a [P],
}

impl<P> Listed<'_, P> {
    /// The neighbours' indices and payloads, in the order of the list.
    #[inline(always)]
    pub fn iter(&self) -> impl Iterator<Item = (usize, &P)> {
        self.entries.iter().map(|&e| (e & J_MASK) as usize).zip(self.payload)
    }
}

/// The pairs `j > i` of a run of points of a [`NeighbourList`], packed as the list packs
/// them (see [`NeighbourList::half_pairs`]).
#[derive(Clone, Debug, Default)]
pub struct HalfPairs {
    first: usize,
    /// The points of the list the pairs were taken from: every `j` is below.
    sources: usize,
    start: Vec<u32>,
    entries: Vec<u32>,
}

impl HalfPairs {
    /// Number of pairs `j > i` of point `i`.
    pub fn count(&self, i: usize) -> usize {
        self.entries(i).len()
    }

    /// Where point `i`'s pairs `j > i` sit among all the pairs of the run (in the order of
    /// [`neighbours_with`](Self::neighbours_with)).
    #[inline(always)]
    pub fn span(&self, i: usize) -> std::ops::Range<usize> {
        let l = i - self.first;
        self.start[l] as usize..self.start[l + 1] as usize
    }

    /// The neighbours `j` of the pairs of `span`, each with `values[j]`. Checked once for
    /// all of them, not for each (in IPST's sweeps the check took a compare and a branch a
    /// pair).
    #[inline(always)]
    pub fn neighbours_with<'a, T>(
        &'a self,
        span: std::ops::Range<usize>,
        values: &'a [T],
    ) -> impl Iterator<Item = (u32, &'a T)> + 'a {
        assert!(values.len() >= self.sources, "a value for each point the list was built from");
        // SAFETY: every j < self.sources (see the field) <= values.len().
        self.entries[span]
            .iter()
            .map(move |&e| (e & J_MASK, unsafe { values.get_unchecked((e & J_MASK) as usize) }))
    }

    /// The packed entries of point `i`'s pairs `j > i`.
    #[inline(always)]
    fn entries(&self, i: usize) -> &[u32] {
        &self.entries[self.span(i)]
    }
}

/// Lengthens `v` to at least `len` (never shortens it).
fn grow<T: Copy + Default>(v: &mut Vec<T>, len: usize) {
    if v.len() < len {
        v.resize(len, T::default());
    }
}

#[derive(Clone, Debug, Default)]
struct Chunk<const D: usize, P> {
    /// Where each point's entries start, and after the last point where they end: the
    /// entries and payload past that end are stale room, kept between builds so that
    /// [`NeighbourList::build_reducing`] writes no zeros into it.
    start: Vec<u32>,
    entries: Vec<u32>,
    payload: Vec<P>,
    /// Whether the payload was handed to another chunk since this one was built.
    payload_stale: bool,
    /// Scratch: |x_ij|^2 of the pairs whose payload is computed next.
    r2: Vec<f64>,
    /// Scratch: the candidates around the current cell, packed,
    candidates: Vec<u32>,
    /// with their positions and image shifts axis after axis (struct of arrays, for the
    /// vectorised distance test).
    candidate_x: Vec<f64>,
    candidate_shift: Vec<f64>,
}

impl<const D: usize, P: Copy + Default> Chunk<D, P> {
    fn clear(&mut self) {
        self.payload_stale = false;
        self.start.clear();
        self.entries.clear();
        self.payload.clear();
        self.r2.clear();
    }

    /// Hands this chunk's payload storage to `next` and takes `next`'s
    /// ([`ChunkWriter::recycle`]).
    fn hand_payload_to(&mut self, next: &mut Self) {
        std::mem::swap(&mut self.payload, &mut next.payload);
        self.payload_stale = true;
    }

    /// The number of pairs listed.
    fn pairs(&self) -> usize {
        self.start.last().map_or(0, |&end| end as usize)
    }

    /// Gathers the candidates of the points in `cell`: the points of the 3^D cells around
    /// it, with the image shifts they are seen through.
    fn gather_candidates(
        &mut self,
        cells: &CellList<D>,
        cell: usize,
        points: &[Vector<D>],
        shifts: &[Vector<D>],
    ) {
        self.candidates.clear();
        cells.for_each_cell_around(cell, |indices, wraps| {
            debug_assert!(
                wraps.iter().all(|w| (-1..=1).contains(w)),
                "self-queries wrap by one period at most"
            );
            let code = image_code(wraps);
            self.candidates.extend(indices.iter().map(|&j| j | (code << J_BITS)));
        });
        let m = self.candidates.len();
        self.candidate_x.resize(D * m, 0.0);
        self.candidate_shift.resize(D * m, 0.0);
        for (k, &e) in self.candidates.iter().enumerate() {
            let (x, s) = (&points[(e & J_MASK) as usize], &shifts[(e >> J_BITS) as usize]);
            for d in 0..D {
                self.candidate_x[d * m + k] = x[d];
                self.candidate_shift[d * m + k] = s[d];
            }
        }
    }

    /// Closes the chunk: the payload of all its pairs from their distances.
    fn finish(&mut self, payload: &impl Fn(&[f64], &mut [P])) {
        self.start.push(self.entries.len() as u32);
        self.payload.clear();
        self.payload.resize(self.entries.len(), P::default());
        payload(&self.r2, &mut self.payload);
        self.keep_headroom();
    }

    /// Keeps room for a quarter more pairs than this build found (plus the scratch a point
    /// needs), so that the next builds, whose pair counts differ by a few per cent, do not
    /// allocate: a step allocates nothing once the lists have grown (tested).
    fn keep_headroom(&mut self) {
        let want = self.pairs() + self.pairs() / 4 + 256;
        if self.entries.capacity() < want {
            self.entries.reserve(want - self.entries.len());
        }
        if self.payload.capacity() < want {
            self.payload.reserve(want - self.payload.len());
        }
    }
}

/// For every point of a body, its neighbours within the search radius in the same body,
/// each with a payload `P` computed from the pair's squared distance at build time.
#[derive(Clone, Debug, Default)]
pub struct NeighbourList<const D: usize, P = ()> {
    chunks: Vec<Chunk<D, P>>,
    /// Image shift per code: code = sum_k (wraps_k + 1) 3^k; [`CODES`] rows once built.
    shifts: Vec<Vector<D>>,
    /// The number of points the entries index: the last build read each listed one with a
    /// bounds check, so every entry's `j` is below it.
    sources: usize,
}

impl<const D: usize, P: Copy + Default + Send + Sync> NeighbourList<D, P> {
    /// An empty list.
    pub fn new() -> Self {
        Self { chunks: Vec::new(), shifts: Vec::new(), sources: 0 }
    }

    /// Lists the neighbours of every point of `points` among the same points, with their
    /// payload: `payload(r2, out)` fills `out[k]` from the squared distance `r2[k]` of each
    /// pair, a whole chunk of pairs at a time (so that a kernel evaluation vectorises).
    /// `cells` must have binned exactly these points (in this order: call it after
    /// [`CellList::mark_reordered`] if the points were reordered).
    /// Panics if the body has 2^26 points or more.
    pub fn build(
        &mut self,
        cells: &CellList<D>,
        points: &[Vector<D>],
        payload: impl Fn(&[f64], &mut [P]) + Sync,
    ) {
        self.build_reducing(cells, points, payload, &mut vec![(); points.len()], |_| ());
    }

    /// As [`build`](Self::build), also reducing each point's pairs as soon as they are
    /// listed, while they are in cache: `out[i] = reduce(neighbours of i)` (a summation
    /// density, say, without a pass of its own). `out` must have one element per point.
    pub fn build_reducing<R: Send>(
        &mut self,
        cells: &CellList<D>,
        points: &[Vector<D>],
        payload: impl Fn(&[f64], &mut [P]) + Sync,
        out: &mut [R],
        reduce: impl Fn(Listed<'_, P>) -> R + Sync,
    ) {
        assert_eq!(out.len(), points.len(), "one reduction per point");
        let chunks = self.begin(cells, points.len());
        let into = ChunkRun { chunks: &mut self.chunks[chunks], first: 0, split: 1 };
        list_chunks(into, &self.shifts, self.sources, cells, points, payload, out, reduce);
    }

    /// Readies the list for a build over `n` points in [`CHUNK`]s: returns the chunks,
    /// which a [`ChunkWriter`] then lists, in any number of calls. Until every chunk is
    /// built, only the points of built chunks may be queried.
    pub fn begin(&mut self, cells: &CellList<D>, n: usize) -> std::ops::Range<usize> {
        assert!(n < (1 << J_BITS), "neighbour lists hold at most 2^{J_BITS} points");
        self.set_shifts(cells);
        self.sources = n;
        self.chunks.resize_with(n.div_ceil(CHUNK), Chunk::default);
        0..self.chunks.len()
    }

    /// After [`begin`](Self::begin): a writer through which several threads list disjoint
    /// runs of chunks at once while others read the list's other points through `&self`
    /// (a step run as a wavefront over tiles on several threads). It borrows nothing: the
    /// caller answers for the list outliving it and for its chunks not being resized.
    pub fn chunk_writer(&mut self) -> ChunkWriter<D, P> {
        ChunkWriter { chunks: self.chunks.as_mut_ptr(), len: self.chunks.len() }
    }

    /// Lists, for every query point, its neighbours among `sources` (binned by `cells`),
    /// with their payload as in [`build`](Self::build): the interaction of two bodies.
    /// Query points may lie anywhere; periodic images are found as for a body's own list.
    pub fn build_cross(
        &mut self,
        cells: &CellList<D>,
        sources: &[Vector<D>],
        queries: &[Vector<D>],
        payload: impl Fn(&[f64], &mut [P]) + Sync,
    ) {
        let n = queries.len();
        assert!(sources.len() < (1 << J_BITS), "neighbour lists hold at most 2^{J_BITS} points");
        self.set_shifts(cells);
        self.sources = sources.len();
        self.chunks.resize_with(n.div_ceil(CHUNK), Chunk::default);
        self.chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
            chunk.clear();
            for q in &queries[c * CHUNK..((c + 1) * CHUNK).min(n)] {
                chunk.start.push(chunk.entries.len() as u32);
                cells.visit(sources, q, |j, _, r2, wraps| {
                    let code = image_code(wraps.map(|w| w.clamp(-1, 1)));
                    chunk.entries.push(j as u32 | (code << J_BITS));
                    chunk.r2.push(r2);
                });
            }
            chunk.finish(&payload);
        });
    }

    fn set_shifts(&mut self, cells: &CellList<D>) {
        self.shifts.clear();
        for code in 0..3usize.pow(D as u32) {
            let mut wraps = [0i8; D];
            let mut c = code;
            for w in wraps.iter_mut() {
                *w = (c % 3) as i8 - 1;
                c /= 3;
            }
            self.shifts.push(cells.shift(wraps));
        }
        self.shifts.resize(CODES, Vector::zeros());
    }

    /// The shift table as an array, whose rows an entry's code always indexes.
    #[inline(always)]
    fn shift_table(&self) -> &[Vector<D>; CODES] {
        self.shifts.as_slice().try_into().expect("a built list")
    }

    /// Calls `f(j, x_ij, r2, payload)` for every neighbour `j` of point `i` (itself
    /// included), in the order of the cell list. `points` must be the positions the list
    /// was built from.
    #[inline(always)]
    pub fn for_each<F: FnMut(usize, Vector<D>, f64, &P)>(&self, i: usize, points: &[Vector<D>], f: F) {
        self.for_each_from(i, points[i], points, f);
    }

    /// As [`for_each`](Self::for_each) for a list between two bodies: query point `i` at
    /// `xi`, neighbours among `sources`.
    #[inline(always)]
    pub fn for_each_from<F: FnMut(usize, Vector<D>, f64, &P)>(
        &self,
        i: usize,
        xi: Vector<D>,
        points: &[Vector<D>],
        mut f: F,
    ) {
        self.for_each_with(i, xi, points, points.into(), |j, xij, r2, p, _| f(j, xij, r2, p));
    }

    /// As [`for_each_from`](Self::for_each_from), also handing `f` each neighbour's record
    /// `records[j]`: the loop of every pass, which reads a neighbour's position and record
    /// with one bounds check a call instead of two a pair. Only the neighbours' records are
    /// read (other threads may be writing others: the wavefront step's tiles).
    #[inline(always)]
    pub fn for_each_with<T, F: FnMut(usize, Vector<D>, f64, &P, &T)>(
        &self,
        i: usize,
        xi: Vector<D>,
        points: &[Vector<D>],
        records: Gather<'_, T>,
        mut f: F,
    ) {
        assert!(
            points.len() >= self.sources && records.len() >= self.sources,
            "a record and a position for each point the list was built from"
        );
        let (chunk, range) = self.range(i);
        assert!(!chunk.payload_stale, "point {i}: its payloads were handed on (`recycle`)");
        let shifts = self.shift_table();
        for (&e, p) in chunk.entries[range.clone()].iter().zip(&chunk.payload[range]) {
            let j = (e & J_MASK) as usize;
            // SAFETY: j < self.sources (see the field), and both slices are at least that long.
            let (xj, b) = unsafe { (points.get_unchecked(j), records.get_unchecked(j)) };
            let xij = Self::difference(shifts, e, xi, xj);
            f(j, xij, xij.norm_squared(), p, b);
        }
    }

    /// Calls `f(j, x_ij)` for every neighbour `j` of query point `i` at `xi` (itself
    /// included), as [`for_each_from`](Self::for_each_from) visits them, without their
    /// payloads (which the list may have handed on: `recycle`).
    #[inline(always)]
    pub fn for_each_difference<F: FnMut(usize, Vector<D>)>(
        &self,
        i: usize,
        xi: Vector<D>,
        points: &[Vector<D>],
        mut f: F,
    ) {
        assert!(points.len() >= self.sources, "a position for each point the list was built from");
        let (chunk, range) = self.range(i);
        let shifts = self.shift_table();
        for &e in &chunk.entries[range] {
            let j = (e & J_MASK) as usize;
            // SAFETY: j < self.sources (see the field) <= points.len().
            let xj = unsafe { points.get_unchecked(j) };
            f(j, Self::difference(shifts, e, xi, xj));
        }
    }

    /// Whether `f(j)` holds for any neighbour `j` of point `i` (itself included), stopping
    /// at the first that does: a test of the neighbours' indices alone, which reads neither
    /// positions nor payloads.
    #[inline(always)]
    pub fn any<F: FnMut(usize) -> bool>(&self, i: usize, mut f: F) -> bool {
        let (chunk, range) = self.range(i);
        chunk.entries[range].iter().any(|&e| f((e & J_MASK) as usize))
    }

    /// The chunk holding point `i` and the range of its entries in it. The chunk alone is
    /// borrowed, not the array of all (which a [`ChunkWriter`] may be filling elsewhere).
    #[inline(always)]
    fn range(&self, i: usize) -> (&Chunk<D, P>, std::ops::Range<usize>) {
        let c = i / CHUNK;
        assert!(c < self.chunks.len(), "point {i} of a list of {} chunks", self.chunks.len());
        // SAFETY: in bounds (checked); `Vec::as_ptr` borrows no other chunk.
        let chunk = unsafe { &*self.chunks.as_ptr().add(c) };
        let l = i % CHUNK;
        (chunk, chunk.start[l] as usize..chunk.start[l + 1] as usize)
    }

    /// `x_ij` of entry `e` for a query at `xi` and a neighbour at `xj`, through the entry's
    /// periodic image (the one formula every pass uses, so that all see the same bits).
    #[inline(always)]
    fn difference(shifts: &[Vector<D>; CODES], e: u32, xi: Vector<D>, xj: &Vector<D>) -> Vector<D> {
        (xi - shifts[(e >> J_BITS) as usize]) - *xj
    }

    /// Number of neighbours of query point `i`.
    #[inline(always)]
    pub fn count(&self, i: usize) -> usize {
        self.range(i).1.len()
    }

    /// Writes the neighbours of query point `i` at `xi` into the first
    /// [`count(i)`](Self::count) elements of `out`, as [`for_each_from`](Self::for_each_from)
    /// visits them, with `values[j]` of each neighbour `j` (e.g. its volume): the pairs as
    /// arrays, for passes that evaluate them in vectorised loops. Panics if a slice of
    /// `out` is shorter than the count.
    #[inline(always)]
    pub fn write_pairs(
        &self,
        i: usize,
        xi: Vector<D>,
        points: &[Vector<D>],
        values: &[f64],
        out: PairSlices<D>,
    ) {
        let (chunk, range) = self.range(i);
        let entries = &chunk.entries[range];
        let n = entries.len();
        let shifts = self.shift_table();
        assert!(
            points.len() >= self.sources && values.len() >= self.sources,
            "a position and a value for each point the list was built from"
        );
        for ((&e, xij), value) in entries.iter().zip(&mut out.xij[..n]).zip(&mut out.value[..n]) {
            let j = (e & J_MASK) as usize;
            // SAFETY: j < self.sources (see the field) <= both lengths. Checked once a point,
            // as in `write_half_pairs`.
            let (xj, v) = unsafe { (points.get_unchecked(j), values.get_unchecked(j)) };
            (*xij, *value) = (Self::difference(shifts, e, xi, xj), *v);
        }
    }

    /// As [`write_pairs`](Self::write_pairs) over the pairs `j > i` of point `i` listed in
    /// `half` (by [`half_pairs`](Self::half_pairs)), the differences `x_ij` only (the
    /// neighbours are [`HalfPairs::neighbours_with`]).
    /// Returns how many were written.
    #[inline(always)]
    pub fn write_half_pairs(
        &self,
        half: &HalfPairs,
        i: usize,
        xi: Vector<D>,
        points: Gather<'_, Vector<D>>,
        xij: &mut [Vector<D>],
    ) -> usize {
        let entries = half.entries(i);
        let n = entries.len();
        let shifts = self.shift_table();
        assert!(points.len() >= self.sources, "a position for each point the list was built from");
        for (&e, xij) in entries.iter().zip(&mut xij[..n]) {
            // SAFETY: j < self.sources (see the field) <= points.len(). Unchecked: in IPST's
            // sweeps the check of each pair took two of its thirteen instructions.
            let xj = unsafe { points.get_unchecked((e & J_MASK) as usize) };
            *xij = Self::difference(shifts, e, xi, xj);
        }
        n
    }

    /// Lists the neighbours `j > i` of the points `points` into `half`: each pair once, for
    /// loops that add its share to both points (see [`Slabs`](super::Slabs)), and that run
    /// over the pairs several times (the list is then filtered once).
    pub fn half_pairs(&self, points: std::ops::Range<usize>, half: &mut HalfPairs) {
        half.first = points.start;
        half.sources = self.sources;
        half.start.clear();
        half.entries.clear();
        for i in points {
            half.start.push(half.entries.len() as u32);
            let (chunk, range) = self.range(i);
            half.entries.extend(chunk.entries[range].iter().filter(|&&e| (e & J_MASK) as usize > i));
        }
        half.start.push(half.entries.len() as u32);
        // Room for a quarter more, as the list keeps, so that later steps do not allocate.
        let want = half.entries.len() + half.entries.len() / 4 + 256;
        half.entries.reserve(want.saturating_sub(half.entries.len()));
    }

    /// Total number of (ordered) pairs.
    pub fn pairs(&self) -> usize {
        self.chunks.iter().map(Chunk::pairs).sum()
    }

    /// Bytes held by the lists.
    pub fn bytes(&self) -> usize {
        self.chunks
            .iter()
            .map(|c| {
                4 * (c.entries.capacity() + c.start.capacity())
                    + c.payload.capacity() * std::mem::size_of::<P>()
            })
            .sum()
    }
}

/// A run of a list's chunks, from chunk `first` on, to list in rayon tasks of at least
/// `split` chunks.
struct ChunkRun<'a, const D: usize, P> {
    chunks: &'a mut [Chunk<D, P>],
    first: usize,
    split: usize,
}

/// Lists the points of the chunks of `into` among `points`, as
/// [`NeighbourList::build_reducing`] lists all (`shifts` and `sources` are the list's).
#[allow(clippy::too_many_arguments)]
fn list_chunks<const D: usize, P: Copy + Default + Send + Sync, R: Send>(
    into: ChunkRun<'_, D, P>,
    shifts: &[Vector<D>],
    sources: usize,
    cells: &CellList<D>,
    points: &[Vector<D>],
    payload: impl Fn(&[f64], &mut [P]) + Sync,
    out: &mut [R],
    reduce: impl Fn(Listed<'_, P>) -> R + Sync,
) {
    let n = points.len();
    let ChunkRun { chunks, first, split } = into;
    assert_eq!(n, sources, "the points of `begin`");
    let last = first + chunks.len();
    assert_eq!(out.len(), (last * CHUNK).min(n) - first * CHUNK, "one reduction per point");
    let r2max = cells.radius2();
    let path = filter::Path::fastest();
    chunks.par_iter_mut().zip(out.par_chunks_mut(CHUNK)).enumerate().with_min_len(split).for_each(
        |(c, (chunk, out))| {
            let c = first + c;
            // The entries and payload keep their length (the room of the last build):
            // they only grow, so that no point's room is zeroed before it is written.
            chunk.start.clear();
            chunk.payload_stale = false;
            let mut len = 0;
            // Points are visited in cell order, so the candidates of a cell serve every
            // point in it.
            let mut current = usize::MAX;
            for (i, out) in (c * CHUNK..((c + 1) * CHUNK).min(n)).zip(out) {
                let cell = cells.cell_of(i);
                if cell != current {
                    current = cell;
                    chunk.gather_candidates(cells, cell, points, shifts);
                }
                let first = len;
                chunk.start.push(first as u32);
                let m = chunk.candidates.len();
                // Room for every candidate plus one vector of lanes past the last.
                grow(&mut chunk.entries, first + m + filter::LANES);
                chunk.r2.resize(m + filter::LANES, 0.0);
                let c = filter::Candidates {
                    entries: &chunk.candidates,
                    x: &chunk.candidate_x,
                    shift: &chunk.candidate_shift,
                };
                let accepted = filter::within(
                    path,
                    &points[i],
                    &c,
                    r2max,
                    filter::Accepted { entries: &mut chunk.entries[first..], r2: &mut chunk.r2 },
                );
                len = first + accepted;
                // The payload over whole vectors: the pairs padded with copies of the search
                // radius, whose values are then dropped (a scalar tail loop would cost as
                // much as the vector body).
                let padded = accepted.next_multiple_of(filter::LANES);
                chunk.r2[accepted..padded].fill(r2max);
                grow(&mut chunk.payload, first + padded);
                payload(&chunk.r2[..padded], &mut chunk.payload[first..first + padded]);
                let (entries, payload) = (&chunk.entries[first..len], &chunk.payload[first..len]);
                *out = reduce(Listed { entries, payload });
            }
            chunk.start.push(len as u32);
            chunk.keep_headroom();
        },
    );
}

/// Lists runs of a [`NeighbourList`]'s chunks from several threads at once (see
/// [`NeighbourList::chunk_writer`]).
pub struct ChunkWriter<const D: usize, P> {
    chunks: *mut Chunk<D, P>,
    len: usize,
}

// SAFETY: a writer hands out chunks only through its unsafe methods, whose callers keep
// the threads' chunks apart.
unsafe impl<const D: usize, P: Send> Send for ChunkWriter<D, P> {}
unsafe impl<const D: usize, P: Send> Sync for ChunkWriter<D, P> {}

impl<const D: usize, P: Copy + Default + Send + Sync> ChunkWriter<D, P> {
    /// The chunks `run`, for this thread alone.
    ///
    /// # Safety
    /// `run` is within the list; no other thread touches these chunks until the returned
    /// borrow ends, and the list is alive and not resized meanwhile.
    #[allow(clippy::mut_from_ref)]
    unsafe fn run(&self, run: std::ops::Range<usize>) -> &mut [Chunk<D, P>] {
        assert!(run.start <= run.end && run.end <= self.len, "chunks {run:?} of {}", self.len);
        // SAFETY: in bounds (checked) and exclusive (the caller's contract).
        unsafe { std::slice::from_raw_parts_mut(self.chunks.add(run.start), run.len()) }
    }

    /// Lists the points of `chunks` of `list`, the list this writer was made from, as
    /// [`NeighbourList::build_reducing`] lists all, in one task on the calling thread:
    /// `out` holds one reduction per point of these chunks, from the first chunk's first
    /// point.
    ///
    /// # Safety
    /// While it runs, no other thread reads or writes the chunks `chunks` (their points'
    /// neighbours), and `list` is the writer's list, [`begin`](NeighbourList::begin)
    /// since the writer was made.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn build_chunks<R: Send>(
        &self,
        list: &NeighbourList<D, P>,
        cells: &CellList<D>,
        points: &[Vector<D>],
        payload: impl Fn(&[f64], &mut [P]) + Sync,
        chunks: std::ops::Range<usize>,
        out: &mut [R],
        reduce: impl Fn(Listed<'_, P>) -> R + Sync,
    ) {
        assert!(
            std::ptr::eq(list.chunks.as_ptr(), self.chunks) && list.chunks.len() == self.len,
            "the writer's own list, not resized"
        );
        // SAFETY: the caller's contract.
        let into =
            ChunkRun { chunks: unsafe { self.run(chunks.clone()) }, first: chunks.start, split: usize::MAX };
        list_chunks(into, &list.shifts, list.sources, cells, points, payload, out, reduce);
    }

    /// Hands the payload storage of chunk `dead`, whose payloads will not be read again
    /// before the next build, to chunk `next`, about to be built (and `next`'s to `dead`):
    /// the payloads, most of a list's bytes, are then written into memory just read, still
    /// in cache, rather than into memory last touched a build ago. `dead` keeps its pairs
    /// ([`NeighbourList::half_pairs`] still reads them); a query of its payloads panics.
    ///
    /// # Safety
    /// While it runs, no other thread reads or writes chunks `dead` or `next`.
    pub unsafe fn recycle(&self, dead: usize, next: usize) {
        assert_ne!(dead, next, "two chunks");
        // SAFETY: the caller's contract; two distinct chunks.
        let (dead, next) = unsafe { (&mut self.run(dead..dead + 1)[0], &mut self.run(next..next + 1)[0]) };
        dead.hand_payload_to(next);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{brute_force_neighbours, Domain};
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn lists_equal_brute_force_with_exact_differences() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for periodic in [[true, true], [false, false], [true, false]] {
            let d = Domain { min: [0.0, 0.0], max: [1.0, 0.8], periodic };
            let pts: Vec<Vector<2>> =
                (0..1500).map(|_| Vector::<2>::new(rng.gen(), 0.8 * rng.gen::<f64>())).collect();
            let radius = 0.07;
            let mut cells = CellList::new(d, radius);
            cells.update(&pts);
            let mut nl = NeighbourList::<2, f64>::new();
            // Built with a reduction per point: the sum of j * r2 over its neighbours.
            let mut sums = vec![0.0; pts.len()];
            let reduce = |l: Listed<'_, f64>| l.iter().fold(0.0, |s, (j, &r2)| s + j as f64 * r2);
            nl.build_reducing(&cells, &pts, |r2, out| out.copy_from_slice(r2), &mut sums, reduce);
            let brute = brute_force_neighbours(&d, radius, &pts, &pts);
            for i in 0..pts.len() {
                let mut v = Vec::new();
                nl.for_each(i, &pts, |j, xij, r2, &payload| {
                    assert_eq!(payload, r2);
                    assert!((xij - d.delta(&pts[i], &pts[j])).norm() < 1e-12);
                    assert!(r2 < radius * radius);
                    v.push(j);
                });
                let mut sum = 0.0;
                nl.for_each(i, &pts, |j, _, r2, _| sum += j as f64 * r2);
                assert_eq!(sums[i], sum, "the reduction sums the listed pairs in list order");
                v.sort();
                assert_eq!(v, brute[i], "point {i}");
                // The same pairs as arrays, at moved positions, with a value per neighbour.
                let moved: Vec<Vector<2>> = pts.iter().map(|x| x * 1.001).collect();
                let values: Vec<f64> = (0..pts.len()).map(|j| j as f64).collect();
                let n = nl.count(i);
                assert_eq!(n, brute[i].len());
                let (mut xij, mut value) = (vec![Vector::zeros(); n], vec![0.0; n]);
                let out = PairSlices { xij: &mut xij, value: &mut value };
                nl.write_pairs(i, moved[i], &moved, &values, out);
                let mut k = 0;
                nl.for_each(i, &moved, |j, x, _, _| {
                    assert_eq!((xij[k], value[k]), (x, j as f64));
                    k += 1;
                });
            }
            assert_eq!(nl.pairs(), brute.iter().map(|v| v.len()).sum::<usize>());
            // The half lists of two runs of points hold every pair j > i once, as the
            // list's own entries.
            let (mut first, mut second) = (HalfPairs::default(), HalfPairs::default());
            let split = pts.len() / 3;
            nl.half_pairs(0..split, &mut first);
            nl.half_pairs(split..pts.len(), &mut second);
            for i in 0..pts.len() {
                let half = if i < split { &first } else { &second };
                let mut xij = vec![Vector::zeros(); nl.count(i)];
                let m = nl.write_half_pairs(half, i, pts[i], pts[..].into(), &mut xij);
                assert_eq!(m, half.count(i));
                let span = half.span(i);
                assert_eq!(span.len(), m);
                let mut expected = Vec::new();
                nl.for_each(i, &pts, |j, x, _, _| {
                    if j > i {
                        expected.push((j as u32, pts[j], x));
                    }
                });
                let pairs = half.neighbours_with(span, &pts).zip(&xij[..m]);
                let got: Vec<_> = pairs.map(|((j, &xj), &x)| (j, xj, x)).collect();
                assert_eq!(got, expected, "point {i}");
            }
        }
    }

    #[test]
    #[should_panic(expected = "a record and a position for each point")]
    fn records_shorter_than_the_listed_points_are_refused() {
        let d = Domain { min: [0.0, 0.0], max: [1.0, 1.0], periodic: [true, true] };
        let pts: Vec<Vector<2>> =
            (0..100).map(|k| Vector::<2>::new(0.1 * (k % 10) as f64, 0.1 * (k / 10) as f64)).collect();
        let mut cells = CellList::new(d, 0.15);
        cells.update(&pts);
        let mut nl = NeighbourList::<2>::new();
        nl.build(&cells, &pts, |_, _| ());
        nl.for_each_with(0, pts[0], &pts, pts[..99].into(), |_, _, _, _, _| ());
    }

    #[test]
    fn a_rebuilt_list_holds_only_the_new_pairs() {
        // One list built on a dense set, then on sparser and denser ones: the room a build
        // leaves is reused, never read as pairs.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let d = Domain { min: [0.0, 0.0], max: [1.0, 1.0], periodic: [true, false] };
        let radius = 0.08;
        let mut nl = NeighbourList::<2, f64>::new();
        for n in [2000, 300, 1200] {
            let pts: Vec<Vector<2>> = (0..n).map(|_| Vector::<2>::new(rng.gen(), rng.gen())).collect();
            let mut cells = CellList::new(d, radius);
            cells.update(&pts);
            let mut counts = vec![0usize; n];
            nl.build_reducing(
                &cells,
                &pts,
                |r2, out| out.copy_from_slice(r2),
                &mut counts,
                |l| l.iter().count(),
            );
            let brute = brute_force_neighbours(&d, radius, &pts, &pts);
            for (i, expected) in brute.iter().enumerate() {
                let mut v = Vec::new();
                nl.for_each(i, &pts, |j, _, r2, &payload| {
                    assert_eq!(payload, r2, "point {i} of {n}: the payload of this build");
                    v.push(j);
                });
                // The loop with a record a point sees the same pairs and hands each its record.
                let mut with = Vec::new();
                nl.for_each_with(i, pts[i], &pts, pts[..].into(), |j, xij, _, _, xj| {
                    assert_eq!(*xj, pts[j]);
                    with.push((j, xij));
                });
                let mut plain = Vec::new();
                nl.for_each(i, &pts, |j, xij, _, _| plain.push((j, xij)));
                assert_eq!(with, plain, "point {i} of {n}");
                assert_eq!(counts[i], v.len(), "the reduction saw the listed pairs only");
                v.sort();
                assert_eq!(&v, expected, "point {i} of {n}");
            }
            assert_eq!(nl.pairs(), brute.iter().map(Vec::len).sum::<usize>(), "{n} points");
        }
    }

    /// A [`ChunkWriter`] used as the wavefront step uses it: two threads list runs of
    /// chunks at once; then one hands a listed chunk's payload storage to the last chunk and
    /// lists it while the other reads the chunks between. The list equals one build; the
    /// chunk handed on keeps its pairs and refuses its payload. (Under Miri, which checks
    /// the writer's shared access: `MIRIFLAGS=-Zmiri-tree-borrows cargo +nightly miri test
    /// --lib chunks_listed`.)
    #[test]
    fn chunks_listed_on_two_threads_and_recycled_equal_one_build() {
        let n = 4 * CHUNK;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let d = Domain { min: [0.0, 0.0], max: [1.0, 1.0], periodic: [true, true] };
        let pts: Vec<Vector<2>> = (0..n).map(|_| Vector::<2>::new(rng.gen(), rng.gen())).collect();
        // Some twelve neighbours a point.
        let mut cells = CellList::new(d, 2.0 / (n as f64).sqrt());
        cells.update(&pts);
        let copy = |r2: &[f64], out: &mut [f64]| out.copy_from_slice(r2);
        let count = |l: Listed<'_, f64>| l.iter().count();
        let mut whole = NeighbourList::<2, f64>::new();
        let mut counts = vec![0; n];
        whole.build_reducing(&cells, &pts, copy, &mut counts, count);
        let pairs = |nl: &NeighbourList<2, f64>, i: usize| {
            let mut v = Vec::new();
            nl.for_each(i, &pts, |j, xij, _, &p| v.push((j, xij, p)));
            v
        };

        let mut nl = NeighbourList::<2, f64>::new();
        assert_eq!(nl.begin(&cells, n), 0..4);
        let writer = nl.chunk_writer();
        let nl = &nl;
        let mut got = vec![0; n];
        let (first, rest) = got.split_at_mut(2 * CHUNK);
        let (third, last) = rest.split_at_mut(CHUNK);
        let listed = std::sync::Barrier::new(2);
        std::thread::scope(|s| {
            s.spawn(|| {
                // SAFETY: chunks 0 and 1, then 0 and 3, are this thread's alone.
                unsafe { writer.build_chunks(nl, &cells, &pts, copy, 0..2, first, count) };
                listed.wait();
                unsafe {
                    writer.recycle(0, 3);
                    writer.build_chunks(nl, &cells, &pts, copy, 3..4, last, count);
                }
            });
            s.spawn(|| {
                // SAFETY: chunk 2 is this thread's alone, and chunks 1 and 2 are only read
                // once both threads listed theirs.
                unsafe { writer.build_chunks(nl, &cells, &pts, copy, 2..3, third, count) };
                listed.wait();
                for i in CHUNK..3 * CHUNK {
                    assert_eq!(pairs(nl, i), pairs(&whole, i), "point {i}, read while chunk 3 is listed");
                }
            });
        });
        assert_eq!(got, counts, "each point's reduction");
        for i in 3 * CHUNK..n {
            assert_eq!(pairs(nl, i), pairs(&whole, i), "point {i}, listed into recycled storage");
        }
        let (mut kept, mut built) = (HalfPairs::default(), HalfPairs::default());
        nl.half_pairs(0..CHUNK, &mut kept);
        whole.half_pairs(0..CHUNK, &mut built);
        assert_eq!((kept.start, kept.entries), (built.start, built.entries), "chunk 0 keeps its pairs");
        let query = std::panic::catch_unwind(|| nl.for_each(0, &pts, |_, _, _, _| ()));
        assert!(query.is_err(), "chunk 0's payload was handed on");
    }
}
