//! Which instruction set ray casting uses, chosen at run time: one binary runs everywhere.
//! `Baseline` is the 4-wide BVH (`crates/geom/src/bvh4.rs`, SSE2, part of x86_64 itself);
//! `Avx2` the 8-wide one (`crates/geom/src/bvh8.rs`). The process's choice is the best the
//! processor runs unless the program sets another ([`Isa::set_active`]; the `photonflow`
//! binary reads `PHOTONFLOW_ISA`), so tests and benchmarks run both paths on one machine.
//!
//! The only module allowed `unsafe`: calling a `#[target_feature(enable = "avx2")]` function
//! from code compiled without AVX2.
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction set the ray-casting code has a path for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// SSE2 (every x86_64) or glam's portable code elsewhere: the 4-wide BVH.
    Baseline,
    /// AVX2 (x86_64, detected at run time): the 8-wide BVH.
    Avx2,
}

/// The process's choice: 0 for none (the best), else `1 + Isa as u8`.
static ACTIVE: AtomicU8 = AtomicU8::new(0);

impl Isa {
    /// The path geometry built from now on uses ([`crate::Geometry::new`]): the one set by
    /// [`Isa::set_active`], else [`Isa::best`].
    pub fn active() -> Isa {
        match ACTIVE.load(Ordering::Relaxed) {
            1 => Isa::Baseline,
            2 => Isa::Avx2,
            _ => Isa::best(),
        }
    }

    /// Makes `isa` the path of geometry built from now on; geometry already built keeps its
    /// own.
    pub fn set_active(isa: Isa) {
        ACTIVE.store(1 + isa as u8, Ordering::Relaxed);
    }

    /// The widest path this processor runs.
    pub fn best() -> Isa {
        if Avx2::detect().is_some() {
            Isa::Avx2
        } else {
            Isa::Baseline
        }
    }

    /// `auto` (the best), `baseline` or `avx2`; an error for other names and for a path the
    /// processor lacks.
    pub fn from_name(name: &str) -> Result<Isa, String> {
        match name {
            "auto" => Ok(Isa::best()),
            "baseline" => Ok(Isa::Baseline),
            "avx2" if Isa::best() == Isa::Avx2 => Ok(Isa::Avx2),
            "avx2" => Err("this processor has no AVX2".into()),
            _ => Err("expected auto, baseline or avx2".into()),
        }
    }
}

/// Proof that the processor has AVX2: made only by [`Avx2::detect`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2 {
    _private: (),
}

impl Avx2 {
    pub(crate) fn detect() -> Option<Avx2> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            return Some(Avx2 { _private: () });
        }
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod calls {
    use super::Avx2;
    use crate::bvh8::{Bvh8, Entry, avx2};
    use crate::{Prim, Ray, Sphere};

    // SAFETY (all three): an `Avx2` exists only once `is_x86_feature_detected!("avx2")` said
    // this processor has AVX2, the one requirement of these `target_feature` functions.
    impl Avx2 {
        #[inline]
        pub(crate) fn closest(
            self,
            b: &Bvh8,
            ray: &Ray,
            spheres: &[Sphere],
            stack: &mut [Entry],
        ) -> Option<(f32, Prim)> {
            unsafe { avx2::closest(b, ray, spheres, stack) }
        }

        #[inline]
        pub(crate) fn any(
            self,
            b: &Bvh8,
            ray: &Ray,
            spheres: &[Sphere],
            stack: &mut [u32],
        ) -> bool {
            unsafe { avx2::any(b, ray, spheres, stack) }
        }

        pub(crate) fn brute_force(
            self,
            b: &Bvh8,
            ray: &Ray,
            spheres: &[Sphere],
        ) -> Option<(f32, Prim)> {
            unsafe { avx2::brute_force(b, ray, spheres) }
        }
    }
}
