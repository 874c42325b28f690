//! Read access to a slice's elements one at a time, for the gathers of the neighbour loops.
//!
//! A `&[T]` asserts that none of its elements changes while it lives, and creating one
//! counts as reading all of them. The wavefront step and IPST's sweeps read the neighbours
//! of one tile while other threads write other tiles of the same arrays, so they must not
//! hold a reference to the whole array: a [`Gather`] reads only the elements asked for
//! (checked by Miri, `stages_on_threads_compute_what_a_loop_computes`).

use std::marker::PhantomData;

/// The elements of a slice, read one at a time.
pub struct Gather<'a, T> {
    ptr: *const T,
    len: usize,
    _elements: PhantomData<&'a [T]>,
}

impl<T> Clone for Gather<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Gather<'_, T> {}

// SAFETY: a `Gather` only reads, as a `&[T]` does.
unsafe impl<T: Sync> Send for Gather<'_, T> {}
unsafe impl<T: Sync> Sync for Gather<'_, T> {}

impl<'a, T> From<&'a [T]> for Gather<'a, T> {
    fn from(s: &'a [T]) -> Self {
        Self { ptr: s.as_ptr(), len: s.len(), _elements: PhantomData }
    }
}

impl<'a, T> Gather<'a, T> {
    /// The `len` elements from `ptr`.
    ///
    /// # Safety
    /// They are valid for `'a`, and no element read through the result is written while
    /// `'a` lasts (other elements may be).
    pub unsafe fn from_raw(ptr: *const T, len: usize) -> Self {
        Self { ptr, len, _elements: PhantomData }
    }

    /// Number of elements.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Element `j`.
    #[inline(always)]
    pub fn get(&self, j: usize) -> &'a T {
        if j >= self.len {
            out_of_bounds(j, self.len)
        }
        // SAFETY: in bounds (checked).
        unsafe { self.get_unchecked(j) }
    }

    /// Element `j`, unchecked.
    ///
    /// # Safety
    /// `j < self.len()`.
    #[inline(always)]
    pub unsafe fn get_unchecked(&self, j: usize) -> &'a T {
        // SAFETY: in bounds (the caller's contract), valid and not written (the
        // constructor's).
        unsafe { &*self.ptr.add(j) }
    }
}

/// The panic of [`Gather::get`], out of line so that the loops do not keep its arguments in
/// memory.
#[cold]
#[inline(never)]
#[track_caller]
fn out_of_bounds(j: usize, len: usize) -> ! {
    panic!("element {j} of {len}")
}
