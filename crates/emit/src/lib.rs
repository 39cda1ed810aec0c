//! `emit`: photons from the scene's lights (emissive triangles, point, spot, directional,
//! sun and environment lights), traced through it and stored on diffuse surfaces (Jensen
//! 2001, "Realistic Image Synthesis Using Photon Mapping", ch. 5–6), and caustic photons
//! carrying photon differentials for splatting (`diff.rs`, `caustic.rs`).
//!
//! Key decision: **photon `i` is a pure function of `(scene seed, i)`**. Its random numbers
//! come from [`math::Rng::for_index`] and nothing it does depends on any other photon, so
//! [`trace_range`] over consecutive ranges, concatenated, equals one big range bit for bit,
//! whatever the thread count and chunk size (pbrt-v4's habit in SPPM: a photon's samples are
//! indexed by the photon's number). Workers therefore need no shared state and no ordering
//! beyond "concatenate chunks in index order".
//!
//! Second decision: an **effects plan** ([`Plan`]) is made from the scene before any photon
//! is traced. A set no surface can produce is not traced at all (no specular surface → no
//! caustic set; no diffuse surface → no global set), and a path stops as soon as it can no
//! longer add to a planned set, so a caustic-only run ends every path at its first diffuse hit.
//!
//! Estimators normalise by the number of photon *paths emitted*, never by the number stored:
//! [`Traced::emitted`] carries it next to the photons.
//!
//! Tracing rules (the whole contract, see [`trace_range`]):
//! - emission (`scene::LightTable::emit`, each light type's own): a light chosen with
//!   probability ∝ its power (summed over RGB); a triangle sends from a point uniform on it
//!   in a cosine-weighted direction about its normal (one-sided), a point light uniformly
//!   over the sphere, a spot uniformly in its cone weighted by its falloff, a light at
//!   infinity from a disc covering the scene; flux `Φ_i / (p_i N)` in the mean, which is
//!   `Φ_total / N` for power-proportional choice (Jensen 2001 §5.1, multiple lights);
//! - diffuse hit (a diffuse lobe, albedo > 0: Lambertian, or glossy's base): store; on a
//!   Lambertian surface Russian roulette with survival `P = max(ρ·Φ) / max(Φ)` (Jensen 2001
//!   ch. 5, Russian roulette), survivors carry `Φ ρ / P`; a glossy one is sampled whole,
//!   with roulette on the sample's weight;
//! - specular hit (mirror, metal, conductor, glass): sample the BSDF in
//!   `TransportMode::Importance`, `Φ *= f |cos θ| / pdf` (glass: Fresnel-chosen reflection
//!   or refraction, weight 1); rough conductors and rough glass are sampled like glossy
//!   surfaces; coloured glass scales the flux by its transmittance and absorption;
//! - black surfaces absorb; a path ends on escape or after [`EmitParams::max_depth`] hits.

mod caustic;
pub mod diff;
mod light;
mod params;
mod plan;
mod trace;

pub use caustic::{CausticPhoton, pass_stream, trace_caustics};
pub use diff::{RayDiff, emit_diff, mesh_dn, reflect_diff, refract_diff, sphere_dn, transfer};
pub use light::{CameraSplat, LIGHT_STREAM, trace_to_camera};
pub use params::EmitParams;
pub use plan::{Plan, PlanError};
pub use trace::{EMIT_STREAM, Traced, trace_parallel, trace_pass, trace_range};

#[cfg(test)]
mod tests;
