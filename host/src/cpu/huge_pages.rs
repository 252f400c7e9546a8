//! The BVH's large arrays on 2 MiB pages where the kernel allows it. Traversal reads nodes and
//! leaf blocks at random across the whole tree (88 MiB at a million triangles), so with 4 KiB
//! pages nearly every node visit of an incoherent ray misses the TLB; Linux backs memory with
//! transparent huge pages when it is advised to (`MADV_HUGEPAGE`, the default `madvise` mode)
//! before it is first touched. Measured in docs/performance.md ("Huge pages").
//!
//! Advice only: contents, results and images are the same with or without it, and where the
//! call fails (another OS, THP disabled) nothing changes but speed.

/// An empty vector with room for `n` elements, its buffer advised onto huge pages (the 2 MiB
/// aligned part of it; a buffer under 2 MiB is left alone).
pub(super) fn vec_with_capacity<T>(n: usize) -> Vec<T> {
    let v = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    {
        const HUGE_PAGE: usize = 2 << 20;
        let start = v.as_ptr() as usize;
        let end = start + v.capacity() * std::mem::size_of::<T>();
        let (lo, hi) = (
            start.next_multiple_of(HUGE_PAGE),
            end / HUGE_PAGE * HUGE_PAGE,
        );
        if hi > lo {
            // SAFETY: advice on address space this vector owns; it never changes its contents.
            unsafe { libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE) };
        }
    }
    v
}

/// A copy of `items` in a vector advised as [`vec_with_capacity`]'s.
pub(super) fn copy_of<T: Copy>(items: &[T]) -> Vec<T> {
    let mut v = vec_with_capacity(items.len());
    v.extend_from_slice(items);
    v
}
