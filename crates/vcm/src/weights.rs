//! The MIS weight of each strategy, from the partial sums its two subpaths carry and the
//! densities at the vertices it joins (the technical report's Eqs. 44-47; SmallVCM's
//! `GetLightRadiance`, `DirectIllumination`, `ConnectVertices`, `ConnectToCamera` and
//! `RangeQuery`). Pure functions, so a test can sum them over every strategy of one path.

use crate::{Pass, mis};

/// A subpath's partial sums at a vertex (on arrival, before it scatters there).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sums {
    pub d_vcm: f32,
    pub d_vc: f32,
    pub d_vm: f32,
    /// [`joins`] at the vertex: the factor on `d_vcm` where it stands for a connection.
    pub joins: f32,
}

/// 1 where a subpath `length` segments long (its vertex `length`) can be the far end of a
/// connection, 0 where that would be a bidirectional connection and `bidirectional` is off.
/// At a subpath's first vertex the connection that samples it from the other side is next-
/// event estimation (light side) or light tracing (eye side): always strategies.
#[inline]
pub(crate) fn joins(bidirectional: bool, length: u32) -> f32 {
    if bidirectional || length <= 1 {
        1.0
    } else {
        0.0
    }
}

/// Emission an eye path hits, against every strategy that reaches the light from its side:
/// `direct` is NEE's density of the point (per area, or solid angle at infinity), `emit` the
/// light's density of emitting the ray back along the path (both with the light's choice).
/// When `first` (the path is `E S* D L`, direct light at the first surface seen), against
/// next-event estimation alone.
#[inline]
pub(crate) fn hit(eye: Sums, direct: f32, emit: f32, first: bool) -> f32 {
    if first {
        return 1.0 / (1.0 + mis(direct) * eye.d_vcm);
    }
    1.0 / (1.0 + mis(direct) * eye.d_vcm + mis(emit) * eye.d_vc)
}

/// Next-event estimation: `bsdf_dir` the eye vertex's density of sampling the light's
/// direction (0 for a delta light, which BSDF sampling never hits), `bsdf_rev` of sampling
/// the way the path came given it, `cos_eye` the cosine there; `direct_w` NEE's density per
/// solid angle, `emit` and `cos_light` the light's emission density and cosine. When
/// `first` (the eye vertex is the first non-delta one: direct light at the first surface
/// seen), against BSDF sampling alone.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn nee(
    pass: &Pass,
    eye: Sums,
    bsdf_dir: f32,
    bsdf_rev: f32,
    cos_eye: f32,
    direct_w: f32,
    emit: f32,
    cos_light: f32,
    first: bool,
) -> f32 {
    let w_light = mis(bsdf_dir / direct_w);
    if first {
        return 1.0 / (w_light + 1.0);
    }
    let w_camera = mis(emit * cos_eye / (direct_w * cos_light))
        * (pass.vm_factor + eye.joins * eye.d_vcm + eye.d_vc * mis(bsdf_rev));
    1.0 / (w_light + 1.0 + w_camera)
}

/// An eye vertex joined to a light vertex: each side's density of sampling the other's
/// vertex per unit area there (`*_dir_a`), and of sampling the way it came (`*_rev`).
#[inline]
pub(crate) fn connect(
    pass: &Pass,
    eye: Sums,
    eye_dir_a: f32,
    eye_rev: f32,
    light: Sums,
    light_dir_a: f32,
    light_rev: f32,
) -> f32 {
    let w_light = mis(eye_dir_a) * (pass.vm_factor + light.d_vcm + light.d_vc * mis(light_rev));
    let w_camera = mis(light_dir_a) * (pass.vm_factor + eye.d_vcm + eye.d_vc * mis(eye_rev));
    1.0 / (w_light + 1.0 + w_camera)
}

/// A light vertex merged at an eye vertex: the eye vertex's density of sampling the light
/// vertex's incoming direction (`eye_dir`) and the reverse (`eye_rev`).
#[inline]
pub(crate) fn merge(pass: &Pass, eye: Sums, eye_dir: f32, eye_rev: f32, light: Sums) -> f32 {
    let w_light = light.joins * light.d_vcm * pass.vc_factor + light.d_vm * mis(eye_dir);
    let w_camera = eye.joins * eye.d_vcm * pass.vc_factor + eye.d_vm * mis(eye_rev);
    1.0 / (w_light + 1.0 + w_camera)
}

/// A light vertex joined to the camera: `camera_pdf_a` the camera's density of the vertex
/// per unit area over a pass's pixel samples, `rev` the vertex's density of sampling the way
/// its path came given the direction to the eye.
#[inline]
pub(crate) fn camera(pass: &Pass, light: Sums, camera_pdf_a: f32, rev: f32) -> f32 {
    let w_light = mis(camera_pdf_a / pass.light_paths as f32)
        * (pass.vm_factor + light.joins * light.d_vcm + light.d_vc * mis(rev));
    1.0 / (1.0 + w_light)
}
