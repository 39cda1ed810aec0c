//! Which instruction set ray casting uses, chosen once per process at run time: one binary
//! runs everywhere. `Baseline` is the 4-wide BVH (`crates/geom/src/bvh4.rs`, SSE2, part of
//! x86_64 itself); `Avx2` the 8-wide one (`crates/geom/src/bvh8.rs`). `PHOTONFLOW_ISA=baseline`
//! forces the first on any processor (tests and benchmarks run both paths on one machine).
//!
//! The only module allowed `unsafe`: calling a `#[target_feature(enable = "avx2")]` function
//! from code compiled without AVX2.
#![allow(unsafe_code)]

use std::sync::OnceLock;

/// An instruction set the ray-casting code has a path for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// SSE2 (every x86_64) or glam's portable code elsewhere: the 4-wide BVH.
    Baseline,
    /// AVX2 (x86_64, detected at run time): the 8-wide BVH.
    Avx2,
}

impl Isa {
    /// The best path this processor runs, unless `PHOTONFLOW_ISA` asks for another
    /// (`baseline`, `avx2`, or `auto`, the default); read once per process. A path the
    /// processor lacks, or an unknown name, falls back to the best it has, with a warning.
    pub fn active() -> Isa {
        static ACTIVE: OnceLock<Isa> = OnceLock::new();
        *ACTIVE.get_or_init(|| {
            let best = Isa::best();
            match std::env::var("PHOTONFLOW_ISA").as_deref() {
                Err(_) | Ok("auto") | Ok("") => best,
                Ok("baseline") => Isa::Baseline,
                Ok("avx2") if best == Isa::Avx2 => Isa::Avx2,
                Ok(other) => {
                    eprintln!(
                        "warning: PHOTONFLOW_ISA={other}: not one of auto, baseline, avx2 \
                         that this processor runs; using {best:?}"
                    );
                    best
                }
            }
        })
    }

    /// The widest path this processor runs.
    pub fn best() -> Isa {
        if Avx2::detect().is_some() {
            Isa::Avx2
        } else {
            Isa::Baseline
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
