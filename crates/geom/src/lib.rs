//! `geom`: everything a ray can hit, and nothing about what the surface *is* (materials are
//! opaque `u32` ids here).
//!
//! Key decisions:
//! - Triangles live in one world-space [`TriMesh`]. The default index is our 4-wide BVH
//!   (`bvh4`), collapsed from an obvhs `Bvh2`, with the analytic spheres inside it as
//!   primitives, so a ray pays for a sphere only when it enters its box. Where the processor
//!   has AVX2 (detected at run time, [`Isa`]) the same binary BVH is collapsed to 8 wide
//!   instead (`bvh8`) and traversed with AVX2; `PHOTONFLOW_ISA=baseline` keeps the BVH4.
//!   obvhs' 8-wide `CwBvh` (spheres tested beside it) stays behind [`BvhKind`] so the
//!   benchmark can compare (`cargo xtask bench rays --compare`; output in
//!   `docs/benchmarks.md`).
//! - Sphere roots are solved in `f64`, exact enough to never re-hit their own surface.
//! - Secondary rays are never nudged by a fixed epsilon: every hit carries a bound on the
//!   floating-point error of its position and [`SurfacePoint::spawn_ray`] offsets the origin
//!   just past it (pbrt-v4 §6.8.6). The triangle test rejects any `t` that is not
//!   conservatively above zero (pbrt-v4 §6.8.7), which closes the remaining gap.

mod accel;
mod bounds;
mod bvh4;
#[cfg(target_arch = "x86_64")]
mod bvh8;
pub mod float;
mod isa;
mod mesh;
mod ploc;
mod ray;
mod simd;
mod sphere;

pub use accel::{BvhKind, Geometry, Hit, Prim};
pub use bounds::Bounds3;
pub use isa::Isa;
pub use mesh::{TriMesh, smooth_vertex_normals};
pub use ray::{Ray, SurfacePoint};
pub use sphere::Sphere;

pub use glam::{Vec2, Vec3};

#[cfg(test)]
mod tests;
