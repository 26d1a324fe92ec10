//! Large acceleration arrays on transparent huge pages. Random access over hundreds of
//! megabytes of nodes misses the TLB on most node visits with 4 KiB pages; Linux backs a
//! region with 2 MiB pages when asked to (`madvise`, the default policy of most
//! distributions), as Embree's allocator asks. Elsewhere this is a plain copy.

/// Below this the TLB covers the array anyway.
const THRESHOLD: usize = 4 << 20;

/// Returns `v`'s contents in memory advised to use huge pages (when large enough).
pub fn on_huge_pages<T: Copy>(v: Vec<T>) -> Vec<T> {
    let bytes = v.len() * std::mem::size_of::<T>();
    if bytes < THRESHOLD || !cfg!(target_os = "linux") {
        return v;
    }
    let mut out: Vec<T> = Vec::with_capacity(v.len());
    #[cfg(target_os = "linux")]
    {
        // Advise before the first touch, so that the pages are allocated huge.
        let page = 4096usize;
        let start = (out.as_ptr() as usize).div_ceil(page) * page;
        let end = out.as_ptr() as usize + bytes;
        if end > start {
            // SAFETY: the range lies inside `out`'s allocation; madvise only changes how
            // the kernel backs it. A failure (no THP support) is harmless.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    out.extend_from_slice(&v);
    out
}
