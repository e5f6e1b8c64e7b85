//! Large buffers on transparent huge pages.
//!
//! A build at 10^6 primitives writes about 180 MB of fresh memory (merged boxes, Morton codes,
//! the leaves as bodies, the split's nodes, the merges); faulting it in 4 KiB at a time took
//! about 17 % of the build's processor time on the machine the bench runs on, and advising it
//! made the two-thread build about 10 % faster (best of 18: 210 against 236 ms). Linux backs a range with 2 MiB
//! pages on first touch when the range is advised (`MADV_HUGEPAGE`, honoured when
//! `/sys/kernel/mm/transparent_hugepage/enabled` is `always` or `madvise`), one fault per
//! 512 small ones. The advice covers only the unwritten capacity of a vector, is dropped
//! silently where the kernel refuses it and does nothing on other systems: a hint, never a
//! change to what is computed.

/// Below this many bytes of spare capacity no advice is given (too few whole huge pages).
const MIN_BYTES: usize = 4 << 20;

/// A vector with room for `cap` items, its memory advised to huge pages (see the module doc).
pub(super) fn vec_with_capacity<T>(cap: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(cap);
    advise_spare(&mut v);
    v
}

/// Advises the unwritten capacity of `v` to huge pages (see the module doc).
pub(super) fn advise_spare<T>(v: &mut Vec<T>) {
    let spare = v.spare_capacity_mut();
    let bytes = std::mem::size_of_val(spare);
    if bytes < MIN_BYTES {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        let page = 4096usize;
        let start = (spare.as_ptr() as usize).next_multiple_of(page);
        let end = (spare.as_ptr() as usize + bytes) & !(page - 1);
        if end > start {
            // SAFETY: the range lies within `v`'s allocation, which stays mapped while `v`
            // lives; MADV_HUGEPAGE changes how pages are backed, not their contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
}
