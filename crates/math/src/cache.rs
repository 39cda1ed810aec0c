//! A cache hint for the structures too large to stay in cache (photon maps, a pass's light
//! vertices): their lines asked for before a long computation needs them, so several misses
//! are under way at once instead of one after the other.

/// Ask the cache for every line of `s` ahead of reading it: `prefetcht0` on x86_64,
/// nothing elsewhere. No effect on any result.
#[inline(always)]
pub fn prefetch<T>(s: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let bytes = std::mem::size_of_val(s);
        let p = s.as_ptr().cast::<i8>();
        // One address in each 64-byte line `s` touches: every 64th byte from the first,
        // then the last (the first's line need not start at `s`).
        let offs = (0..bytes).step_by(64).chain(bytes.checked_sub(1));
        for off in offs {
            // SAFETY: a prefetch is a hint: it never faults and changes no memory (Intel
            // SDM, PREFETCHh), and every address lies inside `s` anyway.
            #[allow(unsafe_code)]
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(off))
            };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = s;
}
