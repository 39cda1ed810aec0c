//! `geom`: everything a ray can hit, and nothing about what the surface *is* (materials are
//! opaque `u32` ids here).
//!
//! Key decisions:
//! - Triangles live in one world-space [`TriMesh`]; a BVH built by `obvhs` indexes them. Both
//!   `Bvh2` and the 8-wide compressed `CwBvh` are kept behind [`BvhKind`] so the benchmark can
//!   compare them (`cargo xtask bench rays --compare`); `CwBvh` is the default because it
//!   measured faster (that command records its output in `docs/benchmarks.md`).
//! - Analytic spheres are few (the worksheet has two), so they are tested one by one next to
//!   the BVH, in `f64`, which makes their roots exact enough to never re-hit their own surface.
//! - Secondary rays are never nudged by a fixed epsilon: every hit carries a bound on the
//!   floating-point error of its position and [`SurfacePoint::spawn_ray`] offsets the origin
//!   just past it (pbrt-v4 §6.8.6). The triangle test rejects any `t` that is not
//!   conservatively above zero (pbrt-v4 §6.8.7), which closes the remaining gap.

mod accel;
mod bounds;
mod bvh4;
pub mod float;
mod mesh;
mod ray;
mod simd;
mod sphere;

pub use accel::{BvhKind, Geometry, Hit, Prim};
pub use bounds::Bounds3;
pub use mesh::{TriMesh, smooth_vertex_normals};
pub use ray::{Ray, SurfacePoint};
pub use sphere::Sphere;

pub use glam::{Vec2, Vec3};

#[cfg(test)]
mod tests;
