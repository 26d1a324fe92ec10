//! Large acceleration arrays on transparent huge pages. Incoherent rays touch a new page on
//! most node visits; with 4 KiB pages a BVH of a few megabytes already overflows the first-
//! level TLB. Linux backs a region with 2 MiB pages when asked to (`madvise`, the default
//! policy of most distributions), but only the 2 MiB-aligned parts of it, so the array is
//! allocated 2 MiB-aligned, as Embree's allocator does. Elsewhere it stays a plain `Vec`.

use std::alloc::Layout;
use std::ops::Deref;
use std::ptr::NonNull;

/// Below this the array stays in an ordinary allocation (a huge page would waste most of
/// its 2 MiB).
const THRESHOLD: usize = 1 << 20;
const HUGE_PAGE: usize = 2 << 20;

/// An immutable array, on huge pages when it is large. Reading it is a plain pointer and
/// length (no branch on where it lives): traversal reads it on every node.
pub struct PageBuf<T: Copy> {
    ptr: NonNull<T>,
    len: usize,
    storage: Storage<T>,
}

enum Storage<T> {
    /// `ptr` points into this vector's buffer, which does not move with the vector; it is
    /// held only to keep the buffer alive.
    Small {
        _owner: Vec<T>,
    },
    Huge(Layout),
}

// SAFETY: `PageBuf` owns its elements like a `Vec` does and never shares the allocation.
unsafe impl<T: Copy + Send> Send for PageBuf<T> {}
unsafe impl<T: Copy + Sync> Sync for PageBuf<T> {}

impl<T: Copy> PageBuf<T> {
    /// Moves `v`'s contents into a buffer advised to use huge pages, when large enough.
    pub fn new(v: Vec<T>) -> PageBuf<T> {
        let bytes = std::mem::size_of_val(v.as_slice());
        if bytes < THRESHOLD || !cfg!(target_os = "linux") || std::mem::align_of::<T>() > HUGE_PAGE {
            return PageBuf::small(v);
        }
        let Ok(layout) = Layout::from_size_align(bytes.div_ceil(HUGE_PAGE) * HUGE_PAGE, HUGE_PAGE) else {
            return PageBuf::small(v);
        };
        // SAFETY: the layout has a non-zero size (bytes >= THRESHOLD).
        let raw = unsafe { std::alloc::alloc(layout) };
        let Some(ptr) = NonNull::new(raw as *mut T) else {
            return PageBuf::small(v);
        };
        #[cfg(target_os = "linux")]
        // SAFETY: the range is this allocation; madvise only changes how the kernel backs it,
        // and is asked before the first touch so that the pages are allocated huge. A failure
        // (no THP support) is harmless.
        unsafe {
            libc::madvise(raw as *mut libc::c_void, layout.size(), libc::MADV_HUGEPAGE);
        }
        // SAFETY: the allocation holds `v.len()` elements, is aligned for `T` (2 MiB is a
        // multiple of any smaller power-of-two alignment), and `T: Copy` needs no drop.
        unsafe { std::ptr::copy_nonoverlapping(v.as_ptr(), ptr.as_ptr(), v.len()) };
        PageBuf { ptr, len: v.len(), storage: Storage::Huge(layout) }
    }

    fn small(v: Vec<T>) -> PageBuf<T> {
        // SAFETY: a vector's pointer is never null (dangling but aligned when empty).
        let ptr = unsafe { NonNull::new_unchecked(v.as_ptr() as *mut T) };
        PageBuf { ptr, len: v.len(), storage: Storage::Small { _owner: v } }
    }

    /// Whether the array was placed on huge-page-advised memory.
    #[cfg(test)]
    fn is_huge(&self) -> bool {
        matches!(self.storage, Storage::Huge(_))
    }
}

impl<T: Copy> Deref for PageBuf<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: `ptr` holds `len` initialised elements for as long as `self` lives (in the
        // vector `storage` owns, or in the allocation it records).
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl<T: Copy> Drop for PageBuf<T> {
    fn drop(&mut self) {
        if let Storage::Huge(layout) = self.storage {
            // SAFETY: allocated in `new` with this layout; `T: Copy` has no destructor.
            unsafe { std::alloc::dealloc(self.ptr.as_ptr() as *mut u8, layout) };
        }
    }
}

impl<T: Copy> Clone for PageBuf<T> {
    fn clone(&self) -> PageBuf<T> {
        PageBuf::new(self.to_vec())
    }
}

impl<T: Copy> Default for PageBuf<T> {
    fn default() -> PageBuf<T> {
        PageBuf::small(Vec::new())
    }
}

impl<T: Copy + std::fmt::Debug> std::fmt::Debug for PageBuf<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_arrays_keep_their_contents() {
        for n in [0usize, 10, (THRESHOLD / 4) + 12345] {
            let v: Vec<u32> = (0..n as u32).collect();
            let b = PageBuf::new(v.clone());
            assert_eq!(&*b, v.as_slice());
            assert_eq!(&*b.clone(), v.as_slice());
            if n * 4 >= THRESHOLD && cfg!(target_os = "linux") {
                assert!(b.is_huge());
                assert_eq!(b.as_ptr() as usize % HUGE_PAGE, 0);
            }
        }
    }
}
