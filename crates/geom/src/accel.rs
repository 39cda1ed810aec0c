use crate::bvh4::Bvh4;
#[cfg(target_arch = "x86_64")]
use crate::bvh8::Bvh8;
use crate::float::gamma;
use crate::isa::{Avx2, Isa};
use crate::{Bounds3, Ray, Sphere, SurfacePoint, TriMesh};
use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams, cwbvh::CwBvh, cwbvh::builder::build_cwbvh_from_tris, ray::RayHit,
    rt_triangle::RtTriangle, triangle::Triangle,
};
use std::time::Duration;

/// Which hierarchy indexes the primitives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BvhKind {
    /// Our 4-wide BVH over triangles and spheres (module `bvh4`).
    #[default]
    Bvh4,
    /// obvhs' 8-wide compressed BVH (Ylitie et al. 2017) over the triangles, spheres tested
    /// beside it: the previous default, kept for `bench-rays --compare`.
    CwBvh,
    /// Our 8-wide BVH traversed with AVX2 (module `bvh8`), where the processor has AVX2;
    /// elsewhere a `Bvh4` is built instead.
    Bvh8,
}

impl BvhKind {
    /// The structure ray casting uses on instruction set `isa`.
    pub fn for_isa(isa: Isa) -> BvhKind {
        match isa {
            Isa::Baseline => BvhKind::Bvh4,
            Isa::Avx2 => BvhKind::Bvh8,
        }
    }
}

enum Accel {
    None,
    Bvh4(Bvh4),
    #[cfg(target_arch = "x86_64")]
    Bvh8(Bvh8),
    CwBvh(CwBvh),
}

/// Which primitive a hit is on. Triangle ids index the [`TriMesh`]; sphere ids the sphere list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prim {
    Triangle(u32),
    Sphere(u32),
}

/// A closest hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    /// Position, its error bound and the unit geometric normal. For triangles the normal
    /// follows the winding `(p1 - p0) x (p2 - p0)`, turned to the shading normal's side when
    /// the mesh has vertex normals; for spheres it points outwards.
    pub point: SurfacePoint,
    /// Unit shading normal (interpolated vertex normals, or the geometric normal).
    pub ns: Vec3,
    /// Triangles: barycentrics `(b1, b2)` of vertices 1 and 2. Spheres: `(phi / 2pi, theta / pi)`.
    pub uv: [f32; 2],
    pub prim: Prim,
    pub material: u32,
}

/// The scene's ray-casting structure: triangles and spheres under one BVH.
pub struct Geometry {
    mesh: TriMesh,
    spheres: Vec<Sphere>,
    accel: Accel,
    /// `CwBvh` only: triangles in BVH leaf order (obvhs' `primitive_indices`), so traversal
    /// reads them contiguously without the extra indirection.
    rt: Vec<RtTriangle>,
    /// Original triangle id of each entry of `rt`.
    rt_ids: Vec<u32>,
    bounds: Bounds3,
    /// Seconds the index took to build (for `bench-load`).
    build_seconds: f64,
    /// Per sphere: whether its hits compute `uv` (see [`Geometry::set_sphere_uv`]).
    sphere_uv: Vec<bool>,
}

impl Geometry {
    /// The structure of the process's instruction set ([`Isa::active`]).
    pub fn new(mesh: TriMesh, spheres: Vec<Sphere>) -> Geometry {
        Geometry::with_bvh(mesh, spheres, BvhKind::for_isa(Isa::active()))
    }

    pub fn with_bvh(mesh: TriMesh, spheres: Vec<Sphere>, kind: BvhKind) -> Geometry {
        let start = std::time::Instant::now();
        let spheres_len = spheres.len();
        let kind = match (kind, Avx2::detect()) {
            (BvhKind::Bvh8, None) => BvhKind::Bvh4,
            (k, _) => k,
        };
        let (accel, order, rt) = match kind {
            #[cfg(target_arch = "x86_64")]
            BvhKind::Bvh8 => {
                let isa = Avx2::detect().expect("checked above");
                match Bvh8::build(&mesh, &spheres, BvhBuildParams::medium_build(), isa) {
                    Some(b) => (Accel::Bvh8(b), Vec::new(), Vec::new()),
                    None => (Accel::None, Vec::new(), Vec::new()),
                }
            }
            #[cfg(not(target_arch = "x86_64"))]
            BvhKind::Bvh8 => unreachable!("no AVX2 outside x86_64"),
            BvhKind::Bvh4 => {
                // `slow_build` and `very_slow_build` (more PLOC search, more reinsertion; their
                // spatial pre-splits do not apply to a build from boxes) traversed within noise
                // of `medium_build` on the tessellated Cornell scene (`bench-rays`, one run).
                let params = BvhBuildParams::medium_build();
                match Bvh4::build(&mesh, &spheres, params) {
                    Some(b) => (Accel::Bvh4(b), Vec::new(), Vec::new()),
                    None => (Accel::None, Vec::new(), Vec::new()),
                }
            }
            BvhKind::CwBvh => {
                let tris: Vec<Triangle> = (0..mesh.len())
                    .map(|i| {
                        let [a, b, c] = mesh.vertices(i);
                        Triangle {
                            v0: a.into(),
                            v1: b.into(),
                            v2: c.into(),
                        }
                    })
                    .collect();
                if tris.is_empty() {
                    (Accel::None, Vec::new(), Vec::new())
                } else {
                    let params = BvhBuildParams::medium_build();
                    let b = build_cwbvh_from_tris(&tris, params, &mut Duration::default());
                    let order = b.primitive_indices.clone();
                    let rt = order
                        .iter()
                        .map(|&i| RtTriangle::from(&tris[i as usize]))
                        .collect();
                    (Accel::CwBvh(b), order, rt)
                }
            }
        };
        let bounds = spheres.iter().fold(mesh.bounds(), |b, s| {
            b.union_point(s.center - Vec3::splat(s.radius))
                .union_point(s.center + Vec3::splat(s.radius))
        });
        Geometry {
            mesh,
            spheres,
            accel,
            rt,
            rt_ids: order,
            bounds,
            build_seconds: start.elapsed().as_secs_f64(),
            sphere_uv: vec![true; spheres_len],
        }
    }

    /// Which spheres' hits carry their `uv`, by material: a sphere's `(phi, theta)` costs an
    /// atan2 and an acos per hit that only a texture reads. Every sphere has it until this
    /// is called; the others' hits then carry zeros.
    pub fn set_sphere_uv(&mut self, needs_uv: impl Fn(u32) -> bool) {
        self.sphere_uv = self.spheres.iter().map(|s| needs_uv(s.material)).collect();
    }

    /// The structure that was built (`Bvh8` asked for without AVX2 builds a `Bvh4`).
    pub fn kind(&self) -> BvhKind {
        match self.accel {
            #[cfg(target_arch = "x86_64")]
            Accel::Bvh8(_) => BvhKind::Bvh8,
            Accel::CwBvh(_) => BvhKind::CwBvh,
            _ => BvhKind::Bvh4,
        }
    }

    /// Seconds the ray-casting index took to build.
    pub fn build_seconds(&self) -> f64 {
        self.build_seconds
    }

    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Closest hit with `0 < t < ray.t_max`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let (t, prim) = self.closest(ray)?;
        Some(self.hit(ray, prim, t))
    }

    /// The closest hit with `0 < t < ray.t_max` as its distance and primitive only, the
    /// query a ray-casting kernel such as Embree's `rtcIntersect1` answers; [`Geometry::intersect`]
    /// adds the surface record (point and its error bound, normals, uv).
    pub fn closest(&self, ray: &Ray) -> Option<(f32, Prim)> {
        match &self.accel {
            Accel::Bvh4(b) => b.intersect(ray, &self.spheres),
            #[cfg(target_arch = "x86_64")]
            Accel::Bvh8(b) => b.intersect(ray, &self.spheres),
            _ => self.intersect_cwbvh(ray),
        }
    }

    fn hit(&self, ray: &Ray, prim: Prim, t: f32) -> Hit {
        match prim {
            Prim::Sphere(i) => self.sphere_hit(ray, i, t),
            Prim::Triangle(id) => self.triangle_hit(ray, id as usize, t),
        }
    }

    /// The previous path: spheres one by one, then obvhs' `CwBvh` over the triangles.
    fn intersect_cwbvh(&self, ray: &Ray) -> Option<(f32, Prim)> {
        let (mut best_t, mut best) = self.closest_sphere(ray);
        let (shifted, real) = to_obvhs(ray, best_t);
        let mut hit = RayHit::none();
        let rt = &self.rt;
        // obvhs keeps a candidate exactly when the returned t is below the ray's current
        // `tmax`; remember the unshifted t of that candidate so no rounding of the shift
        // reaches the caller.
        let closest = std::cell::Cell::new(f32::INFINITY);
        let test = |r: &obvhs::ray::Ray, i: usize| {
            let real = obvhs::ray::Ray {
                tmax: r.tmax - T_SHIFT,
                ..real
            };
            let t = intersect_triangle(&rt[i], &real);
            let ts = t + T_SHIFT;
            if ts < r.tmax {
                closest.set(t);
            }
            ts
        };
        let found = match &self.accel {
            Accel::CwBvh(b) => b.ray_traverse(shifted, &mut hit, test),
            _ => false,
        };
        let t = closest.get();
        if found && t < best_t {
            best_t = t;
            best = Some(Prim::Triangle(self.rt_ids[hit.primitive_id as usize]));
        }
        best.map(|p| (best_t, p))
    }

    /// True if anything is hit with `0 < t < ray.t_max` (shadow rays).
    pub fn occluded(&self, ray: &Ray) -> bool {
        match &self.accel {
            Accel::Bvh4(b) => return b.occluded(ray, &self.spheres),
            #[cfg(target_arch = "x86_64")]
            Accel::Bvh8(b) => return b.occluded(ray, &self.spheres),
            _ => {}
        }
        if self.spheres.iter().any(|s| s.intersect(ray).is_some()) {
            return true;
        }
        let rt = &self.rt;
        let (shifted, real) = to_obvhs(ray, ray.t_max);
        let test = |_: &obvhs::ray::Ray, i: usize| intersect_triangle(&rt[i], &real) + T_SHIFT;
        match &self.accel {
            Accel::CwBvh(b) => !b.ray_traverse_miss(shifted, test),
            _ => false,
        }
    }

    /// Closest hit by testing every primitive: the reference the BVH is tested against.
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<Hit> {
        let (t, prim) = match &self.accel {
            Accel::Bvh4(b) => b.brute_force(ray, &self.spheres)?,
            #[cfg(target_arch = "x86_64")]
            Accel::Bvh8(b) => b.brute_force(ray, &self.spheres)?,
            _ => self.brute_force_cwbvh(ray)?,
        };
        Some(self.hit(ray, prim, t))
    }

    fn brute_force_cwbvh(&self, ray: &Ray) -> Option<(f32, Prim)> {
        let (mut best_t, mut best) = self.closest_sphere(ray);
        let (_, real) = to_obvhs(ray, best_t);
        for (slot, tri) in self.rt.iter().enumerate() {
            let t = intersect_triangle(
                tri,
                &obvhs::ray::Ray {
                    tmax: best_t,
                    ..real
                },
            );
            if t < best_t {
                best_t = t;
                best = Some(Prim::Triangle(self.rt_ids[slot]));
            }
        }
        best.map(|p| (best_t, p))
    }

    /// The nearest sphere hit below `ray.t_max` (spheres are few: tested one by one).
    fn closest_sphere(&self, ray: &Ray) -> (f32, Option<Prim>) {
        let mut best_t = ray.t_max;
        let mut best = None;
        for (i, s) in self.spheres.iter().enumerate() {
            let r = Ray {
                t_max: best_t,
                ..*ray
            };
            if let Some(t) = s.intersect(&r) {
                best_t = t;
                best = Some(Prim::Sphere(i as u32));
            }
        }
        (best_t, best)
    }

    fn sphere_hit(&self, ray: &Ray, i: u32, t: f32) -> Hit {
        let s = &self.spheres[i as usize];
        let uv = self.sphere_uv.get(i as usize).copied().unwrap_or(true);
        let (point, uv) = s.surface_point(ray, t, uv);
        Hit {
            t,
            point,
            ns: point.n,
            uv,
            prim: Prim::Sphere(i),
            material: s.material,
        }
    }

    fn triangle_hit(&self, ray: &Ray, id: usize, t: f32) -> Hit {
        let pv = self.mesh.vertices(id);
        // Barycentrics of the hit for vertices 1 and 2 (Möller–Trumbore's u, v with
        // e1 = v0 - v1, e2 = v2 - v0, the layout of obvhs' `RtTriangle`).
        let (e1, e2) = (pv[0] - pv[1], pv[2] - pv[0]);
        let r = ray.d.cross(pv[0] - ray.o);
        let det = e1.cross(e2).dot(ray.d);
        let b1 = r.dot(e2) / det;
        let b2 = r.dot(e1) / det;
        let b0 = 1.0 - b1 - b2;
        let p = b0 * pv[0] + b1 * pv[1] + b2 * pv[2];
        let p_err = SurfacePoint::barycentric_error([b0, b1, b2], pv);
        let mut ng = (pv[1] - pv[0]).cross(pv[2] - pv[0]).normalize_or_zero();
        let mut ns = ng;
        if !self.mesh.normals.is_empty() {
            let [i0, i1, i2] = self.mesh.indices[id];
            let nv = [i0, i1, i2].map(|i| self.mesh.normals[i as usize]);
            if nv.iter().all(|n| *n != Vec3::ZERO) {
                let n = (b0 * nv[0] + b1 * nv[1] + b2 * nv[2]).normalize_or_zero();
                if n != Vec3::ZERO {
                    ns = n;
                    // Shading normals say where "outside" is (pbrt-v4 §6.5.3 FaceForward).
                    if ng.dot(ns) < 0.0 {
                        ng = -ng;
                    }
                }
            }
        }
        Hit {
            t,
            point: SurfacePoint { p, p_err, n: ng },
            ns,
            uv: [b1, b2],
            prim: Prim::Triangle(id as u32),
            material: self.mesh.materials[id],
        }
    }
}

/// obvhs' `CwBvh` node test clamps the entry distance to `t >= 1e-4` (obvhs 0.4,
/// `cwbvh::node::EPSILON`), so it skips every node that lies entirely closer than that: in
/// our Cornell scene, the floor as seen from a point 1e-5 above it. A fixed epsilon is
/// exactly what `spawn_ray` avoids, so traversal gets a ray whose origin is moved back by
/// `T_SHIFT` (in t units) along its direction; the triangle test uses the true origin and
/// reports `t + T_SHIFT`. Regression test: `tests/it/cornell.rs`, `bvh_equals_brute_force...`.
const T_SHIFT: f32 = 2e-4;

/// The traversal ray (origin moved back by `T_SHIFT`) and the true one, both ending at
/// `t_max` of the caller's ray.
#[inline]
fn to_obvhs(ray: &Ray, t_max: f32) -> (obvhs::ray::Ray, obvhs::ray::Ray) {
    // `+ 0.0` turns -0.0 into +0.0: obvhs picks a ray's octant with `d < 0.0` (false for
    // -0.0) but inverts it with a sign-keeping `safe_inverse` (-1/eps for -0.0); the two
    // disagree and the CwBvh node test then misses everything. `-Vec3::Y` is such a ray.
    let d = ray.d + Vec3::ZERO;
    let real = obvhs::ray::Ray::new(ray.o.into(), d.into(), 0.0, t_max);
    let shifted = obvhs::ray::Ray {
        origin: real.origin - T_SHIFT * real.direction,
        tmax: t_max + T_SHIFT,
        ..real
    };
    (shifted, real)
}

/// Möller–Trumbore ("Fast, minimum storage ray-triangle intersection", 1997) in the layout of
/// `RtTriangle` (e1 = v0 - v1, e2 = v2 - v0, ng = e1 x e2), plus a conservative `t > 0` test:
/// the numerator `ng . (v0 - o)` is accepted only if it exceeds its own rounding-error bound
/// (pbrt-v4 §6.8.4 does the same for its watertight test), so a ray spawned from this
/// triangle's surface can never re-hit it at `t ~ 0`. Returns `INFINITY` for a miss.
#[inline(always)]
fn intersect_triangle(tri: &RtTriangle, ray: &obvhs::ray::Ray) -> f32 {
    let c: Vec3A = tri.v0 - ray.origin;
    let r = ray.direction.cross(c);
    let det = tri.ng.dot(ray.direction);
    let inv_det = 1.0 / det;
    let u = r.dot(tri.e2) * inv_det;
    let v = r.dot(tri.e1) * inv_det;
    let w = 1.0 - u - v;
    // Sign bits of u, v, w together: any negative (including -0.0) is a miss.
    let inside = (u.to_bits() | v.to_bits() | w.to_bits()) & 0x8000_0000 == 0;
    if !(inside && det != 0.0) {
        return f32::INFINITY;
    }
    let num = tri.ng.dot(c);
    let t = num * inv_det;
    if t > 0.0 && t < ray.tmax {
        // |ng . c| must exceed gamma(7) |ng| . |c|: the bound on the rounding of `c`, of `ng`
        // and of the dot product together.
        let err = gamma(7) * tri.ng.abs().dot(c.abs());
        if num.abs() > err {
            return t;
        }
    }
    f32::INFINITY
}
