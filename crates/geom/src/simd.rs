//! Four f32 lanes for the BVH4 and its triangle test: glam's `Vec4`, an SSE2 `__m128` on
//! x86_64 (the crate forbids `unsafe`, so no intrinsics of our own). glam never fuses
//! multiply-adds, so every lane rounds like the scalar expression it mirrors.

pub use glam::Vec4 as F4;

/// The operations traversal needs beyond `Vec4`'s own, with the NaN behaviour it relies on.
pub trait Lanes {
    /// `max(self, acc)` per lane, `acc` where `self` is NaN (SSE `maxps` returns its second
    /// operand on NaN; glam's scalar fallback `f32::max` returns the non-NaN one).
    fn max_into(self, acc: F4) -> F4;
    /// `min(self, acc)` per lane, `acc` where `self` is NaN.
    fn min_into(self, acc: F4) -> F4;
    /// Lane mask (bit i for lane i) of `self <= b`.
    fn le(self, b: F4) -> u32;
    fn lt(self, b: F4) -> u32;
    fn eq(self, b: F4) -> u32;
}

impl Lanes for F4 {
    #[inline(always)]
    fn max_into(self, acc: F4) -> F4 {
        self.max(acc)
    }
    #[inline(always)]
    fn min_into(self, acc: F4) -> F4 {
        self.min(acc)
    }
    #[inline(always)]
    fn le(self, b: F4) -> u32 {
        self.cmple(b).bitmask()
    }
    #[inline(always)]
    fn lt(self, b: F4) -> u32 {
        self.cmplt(b).bitmask()
    }
    #[inline(always)]
    fn eq(self, b: F4) -> u32 {
        self.cmpeq(b).bitmask()
    }
}
