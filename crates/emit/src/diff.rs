//! Photon differentials: a photon ray with first-order derivatives with respect to two
//! emission parameters `(u, v)`, initialised at an area light and propagated through
//! transfer, reflection and refraction (Igehy 1999, "Tracing ray differentials"; Schjøth et
//! al. 2007, "Photon differentials"; Frisvad et al. 2014, "Photon differential splatting for
//! rendering caustics"). Each function below states the formulas it implements.
//!
//! Representation: one pair `(∂o/∂u, ∂d/∂u)` and one pair `(∂o/∂v, ∂d/∂v)`, with the
//! positional and the angular emission spread both assigned to the same `u` and `v` (the
//! merged form of Frisvad et al. 2014). `d` is unit, so `∂d/∂u ⊥ d` at emission and after
//! every interaction below (to first order).
//!
//! Conventions:
//! - directions point along the photon's travel (the incoming direction, *not* pbrt's `wo`);
//! - [`transfer`] accepts `n` facing either side;
//! - [`reflect_diff`] is invariant under flipping `n` together with its derivatives;
//! - [`refract_diff`] wants `n` facing the incoming side (`d·n < 0`) and `eta = n_incident /
//!   n_transmitted`; a normal facing the other way is flipped together with its derivatives;
//! - a normal's derivatives `∂n/∂u`, `∂n/∂v` are those of the *oriented* normal passed in:
//!   for a sphere use [`sphere_dn`] with the radius negated when `n` points inwards.
//!
//! Pure functions of their arguments; f32 per element (the finite-difference tests use f64).

use glam::Vec3;
use math::Frame;
use scene::{Emitted, LightTable};

/// Smallest `cos θ` about the light normal used for the angular footprint ([`emit_diff`]):
/// grazing emission would give an unbounded solid-angle cell. The area light owns it.
pub use scene::MIN_EMIT_COS;

/// Smallest `|d·n|` in the transfer denominator (grazing hits blow differentials up).
pub const MIN_TRANSFER_COS: f32 = 1e-3;

/// Smallest `|T·n|` in the refraction derivative (near-critical refraction).
pub const MIN_REFRACT_COS: f32 = 1e-3;

/// A ray with first-order derivatives of origin and (unit) direction with respect to two
/// emission parameters `u`, `v` (Igehy 1999 §2; Schjøth et al. 2007 §3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDiff {
    pub o: Vec3,
    /// Unit direction of travel.
    pub d: Vec3,
    pub dodu: Vec3,
    pub dodv: Vec3,
    pub dddu: Vec3,
    pub dddv: Vec3,
}

impl RayDiff {
    /// Area of the positional parallelogram `|∂o/∂u × ∂o/∂v|`.
    /// All six vectors finite (a degenerate transfer or refraction is not).
    pub fn is_finite(&self) -> bool {
        [self.o, self.d, self.dodu, self.dodv, self.dddu, self.dddv]
            .iter()
            .all(|v| v.is_finite())
    }

    pub fn footprint_area(&self) -> f32 {
        self.dodu.cross(self.dodv).length()
    }

    /// Solid angle of the directional parallelogram `|∂d/∂u × ∂d/∂v|`.
    pub fn spread_solid_angle(&self) -> f32 {
        self.dddu.cross(self.dddv).length()
    }
}

/// Emit one photon with [`LightTable::emit`] and attach its differentials: the photon
/// owns a cell of measure `1 / (N pdf)` of each sampled domain, which the light it left
/// measures ([`scene::Light::spread`]: the frame whose tangents carry the positional spread
/// `ρ_x`, and the angular spread `ρ_ω`). For an area light `ρ_x = sqrt(A_i / (π p_i N))` and
/// `ρ_ω = sqrt(1 / (N cos θ))`, `cos θ` clamped to [`MIN_EMIT_COS`]; the angular pair lies
/// along two orthonormal vectors perpendicular to `d` (the frame's `s` projected off `d`,
/// then `d × e1`).
///
/// `scale` is the user's smoothing parameter `s`: all four vectors are multiplied by it, so
/// for an area light `|∂o/∂u × ∂o/∂v| = s² A/(π N)` and `|∂d/∂u × ∂d/∂v| = s² / (N cos θ)`.
///
/// The differential's origin and direction are the emitted ray's.
pub fn emit_diff(
    sampler: &LightTable,
    u_light: f32,
    u_pos: [f32; 2],
    u_dir: [f32; 2],
    photons: u64,
    scale: f32,
) -> (Emitted, RayDiff) {
    let e = sampler.emit(u_light, u_pos, u_dir, photons);
    let d = e.ray.d;
    let spread = sampler.spread(&e, photons);
    let frame = spread.frame;
    let rho_x = spread.rho_x as f32 * scale;
    let rho_w = spread.rho_w as f32 * scale;
    let (e1, e2) = perpendicular_pair(d, &frame);
    let rd = RayDiff {
        o: e.ray.o,
        d,
        dodu: rho_x * frame.s,
        dodv: rho_x * frame.t,
        dddu: rho_w * e1,
        dddv: rho_w * e2,
    };
    (e, rd)
}

/// Two orthonormal vectors perpendicular to unit `d`: the frame's `s` (or `t`, when `d` is
/// nearly along `s`) projected off `d`, and `d × e1`.
fn perpendicular_pair(d: Vec3, frame: &Frame) -> (Vec3, Vec3) {
    let mut e1 = frame.s - frame.s.dot(d) * d;
    if e1.length_squared() < 1e-4 {
        e1 = frame.t - frame.t.dot(d) * d;
    }
    let e1 = e1.normalize();
    (e1, d.cross(e1))
}

/// One transferred positional derivative (Igehy 1999 eq. 9–10):
/// `dt = -((dx + t dd)·n) / (d·n)`, `dx' = dx + t dd + dt d`.
fn transfer_one(dx: Vec3, dd: Vec3, d: Vec3, t: f32, n: Vec3, dn_clamped: f32) -> Vec3 {
    let dx_t = dx + t * dd;
    let dt = -dx_t.dot(n) / dn_clamped;
    dx_t + dt * d
}

/// Move the ray a distance `t` to a surface with normal `n` (either orientation) (Igehy
/// 1999 §3.1.1): `o' = o + t d`, `∂o'/∂u = ∂o/∂u + t ∂d/∂u + (∂t/∂u) d` with
/// `∂t/∂u = -((∂o/∂u + t ∂d/∂u)·n) / (d·n)`, so `∂o'/∂u·n = 0`; directions are unchanged.
/// `|d·n|` is clamped from below by [`MIN_TRANSFER_COS`] (sign kept).
pub fn transfer(rd: &RayDiff, t: f32, n: Vec3) -> RayDiff {
    let dn = rd.d.dot(n);
    let dn = if dn < 0.0 {
        dn.min(-MIN_TRANSFER_COS)
    } else {
        dn.max(MIN_TRANSFER_COS)
    };
    RayDiff {
        o: rd.o + t * rd.d,
        dodu: transfer_one(rd.dodu, rd.dddu, rd.d, t, n, dn),
        dodv: transfer_one(rd.dodv, rd.dddv, rd.d, t, n, dn),
        ..*rd
    }
}

/// Mirror reflection at the ray's origin (call after [`transfer`]) about `n` with
/// derivatives `dndu`, `dndv` (Igehy 1999 §3.1.2): `r = d - 2 (d·n) n`,
/// `∂r = ∂d - 2 [(d·n) ∂n + (∂d·n + d·∂n) n]`. Positions are unchanged.
pub fn reflect_diff(rd: &RayDiff, n: Vec3, dndu: Vec3, dndv: Vec3) -> RayDiff {
    let dn = rd.d.dot(n);
    let one = |dd: Vec3, dnd: Vec3| dd - 2.0 * (dn * dnd + (dd.dot(n) + rd.d.dot(dnd)) * n);
    RayDiff {
        d: (rd.d - 2.0 * dn * n).normalize(),
        dddu: one(rd.dddu, dndu),
        dddv: one(rd.dddv, dndv),
        ..*rd
    }
}

/// Refraction at the ray's origin (call after [`transfer`]) with `eta = n_incident /
/// n_transmitted` (Igehy 1999 §3.1.3). With `n` facing the incoming side (`d·n < 0`;
/// otherwise `n` and its derivatives are flipped):
/// `T = η d - μ n`, `T·n = -sqrt(1 - η² (1 - (d·n)²))`, `μ = η (d·n) - T·n`,
/// `∂(d·n) = ∂d·n + d·∂n`, `∂μ = (η - η² (d·n)/(T·n)) ∂(d·n)`, `∂T = η ∂d - (μ ∂n + ∂μ n)`.
/// `|T·n|` in `∂μ` is clamped by [`MIN_REFRACT_COS`]. Total internal reflection → `None`
/// (the caller then uses [`reflect_diff`]).
pub fn refract_diff(rd: &RayDiff, n: Vec3, dndu: Vec3, dndv: Vec3, eta: f32) -> Option<RayDiff> {
    let (n, dndu, dndv) = if rd.d.dot(n) > 0.0 {
        (-n, -dndu, -dndv)
    } else {
        (n, dndu, dndv)
    };
    let c = rd.d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - c * c);
    if k <= 0.0 {
        return None;
    }
    let tn = -k.sqrt();
    let mu = eta * c - tn;
    let dmu_dc = eta - eta * eta * c / tn.min(-MIN_REFRACT_COS);
    let one = |dd: Vec3, dnd: Vec3| {
        let dc = dd.dot(n) + rd.d.dot(dnd);
        eta * dd - (mu * dnd + dmu_dc * dc * n)
    };
    Some(RayDiff {
        d: (eta * rd.d - mu * n).normalize(),
        dddu: one(rd.dddu, dndu),
        dddv: one(rd.dddv, dndv),
        ..*rd
    })
}

/// Derivative of a sphere's unit normal for a positional derivative `dx` in the tangent
/// plane (after [`transfer`]): `n = (x - c)/R ⇒ ∂n = ∂x/R`. Pass the radius negated when
/// the normal used is the inward one, `n = -(x - c)/R`, e.g. for a photon leaving a glass
/// sphere.
pub fn sphere_dn(dx: Vec3, radius: f32) -> Vec3 {
    dx / radius
}

/// Derivative of a smooth-shaded triangle's interpolated normal `n = normalize(Σ b_i n_i)`
/// (Igehy 1999 §3.2.2) for a positional derivative `dx` in the triangle's plane (after
/// [`transfer`]): `dx = ∂b_1 e_1 + ∂b_2 e_2` with `e_k = p_k - p_0` (solved by
/// the 2×2 Gram system), `∂N = ∂b_1 (n_1 - n_0) + ∂b_2 (n_2 - n_0)`,
/// `∂n = (I - n nᵀ) ∂N / |N|`. `b` are the hit's barycentrics. Negate the result when the
/// normal used is `-n`.
pub fn mesh_dn(dx: Vec3, p: [Vec3; 3], ns: [Vec3; 3], b: [f32; 3]) -> Vec3 {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (a11, a12, a22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = a11 * a22 - a12 * a12;
    if det.abs() <= f32::MIN_POSITIVE {
        return Vec3::ZERO;
    }
    let (r1, r2) = (dx.dot(e1), dx.dot(e2));
    let db1 = (a22 * r1 - a12 * r2) / det;
    let db2 = (a11 * r2 - a12 * r1) / det;
    let big_n = b[0] * ns[0] + b[1] * ns[1] + b[2] * ns[2];
    let len = big_n.length();
    let n = big_n / len;
    let dbig_n = db1 * (ns[1] - ns[0]) + db2 * (ns[2] - ns[0]);
    (dbig_n - n * n.dot(dbig_n)) / len
}
