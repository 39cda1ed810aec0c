//! `vcm`: vertex connection and merging (Georgiev, Křivánek, Davidovič and Slusallek 2012,
//! "Light transport simulation with vertex connection and merging"; Hachisuka, Pantaleoni
//! and Jensen 2012 derive the same combination). Every pass traces one light subpath per
//! pixel, stores its non-delta vertices and joins each to the camera, then traces one eye
//! subpath per pixel that at every non-delta vertex
//! - counts emission it hits (path tracing),
//! - samples a light (next-event estimation),
//! - connects to each vertex of its pixel's light subpath (bidirectional connections; only
//!   with [`Options::bidirectional`], off by default: on the boxes measured they cost more
//!   than they returned), and
//! - merges with the light vertices within the pass's radius (photon mapping's density
//!   estimate, the radius shrinking per pass as in progressive photon mapping),
//!
//! and every full path is weighted by the power heuristic over all the strategies that could
//! have made it, so it is counted once, mostly by the strategies that see it best: a sharp
//! caustic seen directly by light tracing, a caustic seen through glass by merging, a diffuse
//! box by path tracing and connections.
//!
//! One exception to the plain heuristic: direct light at the first non-delta surface the
//! eye sees (`E S* D L`) is weighted between next-event estimation and BSDF sampling alone,
//! as the path tracer weighs it, and light tracing and merging leave those paths out: the
//! power heuristic would give them a share of the direct light from a small light, where
//! NEE alone is all but noiseless (measured on the point-light caustic and the spot box at
//! 15 s: their error 1.00x and 0.97x of the plain heuristic's, so within noise; kept for
//! the principle). Every path still sums to one over the strategies that keep it
//! (`tests.rs`).
//!
//! The weights use the recursive partial sums `dVCM`, `dVC`, `dVM` each subpath carries
//! (the paper's technical report, §6.3; SmallVCM's `vertexcm.hxx` spells them out), so a
//! weight costs a few products whatever the path's length. Without bidirectional
//! connections, the `dVCM` terms that stand for them are left out of the sums and weights
//! (`weights::joins`), so the strategies left still sum to one. They leave out Russian roulette
//! (it changes how often a strategy runs, not which paths it can make), so they still sum to
//! one over the strategies: the estimate is unbiased but for merging's own bias.
//!
//! Determinism: light path `i` of pass `j` is point `i` of the pass's scrambled Sobol
//! sequence and the eye path of pixel `i` sample `j` of the pixel's (both functions of
//! `(seed, j, i)` alone), the light vertices keep path order, and the grid visits them in
//! an order fixed by the vertices, so a pass is a pure function of the scene and `j` for any
//! split into chunks and any thread count.

mod eye;
mod grid;
mod light;
mod surface;
#[cfg(test)]
mod tests;
mod weights;

pub use eye::{LightSide, eye_paths};
pub use grid::Grid;
pub use light::{CameraSplat, LightVertex, Merged, light_paths};

use bsdf::BsdfSample;
use glam::Vec3;
use math::mix64;
use scene::Scene;

/// Which strategies run (all, for rendering; tests switch one off to see it matter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strategies {
    /// Emission found by eye paths (unidirectional path tracing).
    pub hits: bool,
    /// Next-event estimation at eye vertices.
    pub nee: bool,
    /// Light vertices joined to the camera (light tracing).
    pub camera: bool,
    /// Eye vertices joined to their pixel's light vertices.
    pub connect: bool,
    /// Eye vertices merged with light vertices within the radius.
    pub merge: bool,
}

impl Strategies {
    pub const ALL: Strategies = Strategies {
        hits: true,
        nee: true,
        camera: true,
        connect: true,
        merge: true,
    };
}

/// The method's knobs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Longest path in bounces, as the path tracer counts them.
    pub max_depth: u32,
    /// Russian roulette from this many bounces on, on both subpaths.
    pub rr_depth: u32,
    /// Light subpaths per pass (0: one per pixel). Pixel `i`'s eye path connects to light
    /// path `i` modulo their number; every light path is joined to the camera and merged.
    pub light_paths: u64,
    /// Merging radius of the first pass, in scene units.
    pub radius: f32,
    /// Radius reduction: pass `j` (from 0) merges within `radius (j + 1)^((alpha - 1) / 2)`
    /// (Knaus and Zwicker 2011's progressive photon mapping).
    pub alpha: f32,
    /// Which strategies contribute. Weights always count all five, so a switched-off
    /// strategy leaves its share of each path out.
    pub strategies: Strategies,
    /// Whether the method has bidirectional connections at all: eye vertices joined to light
    /// vertices with at least two vertices on each side. Without them the weights count
    /// only the strategies left (path tracing's hits and NEE, light tracing, merging), so
    /// the estimate stays whole, and each eye vertex saves a shadow ray and two BSDF
    /// evaluations per light vertex of its subpath.
    pub bidirectional: bool,
}

/// The power heuristic's `p^2` (Veach 1997 §9.2.4), applied to each density ratio.
#[inline]
pub(crate) fn mis(p: f32) -> f32 {
    p * p
}

/// Mixed into a pass's streams ("vcmlight", "vcm eye " in ASCII).
const LIGHT_STREAM: u64 = 0x7663_6d6c_6967_6874;
const EYE_STREAM: u64 = 0x7663_6d20_6579_6520;

/// What one pass shares between its light and eye subpaths.
#[derive(Clone, Copy, Debug)]
pub struct Pass {
    pub opts: Options,
    /// Light subpaths of the pass.
    pub light_paths: u64,
    /// This pass's merging radius.
    pub radius: f32,
    /// `mis(π r² N)`: merging's weight relative to connections (the paper's `η_VCM`).
    pub(crate) vm_factor: f32,
    /// `mis(1 / (π r² N))`.
    pub(crate) vc_factor: f32,
    /// Merging's kernel normalisation `1 / (π r² N)` (uniform kernel).
    pub(crate) vm_norm: f32,
    pub(crate) light_stream: u64,
    /// The run's eye sequences: pixel `p`'s pass `j` is sample `j` of its own scrambled
    /// Sobol sequence, seeded by this and `p` ([`math::SobolSampler`]).
    pub(crate) eye_seed: u64,
    /// This pass's number, the eye paths' sample index.
    pub(crate) index: u64,
    /// Longest path in segments: `max_depth + 1`.
    pub(crate) max_len: u32,
}

impl Pass {
    /// Pass `pass` (from 0) of a run over `scene`.
    pub fn new(scene: &Scene, opts: Options, pass: u64) -> Pass {
        let pixels = scene.camera.width as u64 * scene.camera.height as u64;
        let light_paths = if opts.light_paths > 0 {
            opts.light_paths
        } else {
            pixels
        };
        Pass::with(scene.seed(), light_paths, opts, pass)
    }

    /// [`Pass::new`] for `light_paths` subpaths per pass and a scene seeded `seed`.
    pub(crate) fn with(seed: u64, light_paths: u64, opts: Options, pass: u64) -> Pass {
        let shrink = ((pass + 1) as f64).powf(0.5 * (opts.alpha as f64 - 1.0));
        let radius = (opts.radius as f64 * shrink).max(1e-7) as f32;
        let eta = std::f64::consts::PI * (radius as f64).powi(2) * light_paths as f64;
        let stream = mix64(seed ^ mix64(pass.wrapping_add(0x0056_434d)));
        Pass {
            opts,
            light_paths,
            radius,
            vm_factor: mis(eta as f32),
            vc_factor: mis((1.0 / eta) as f32),
            vm_norm: (1.0 / eta) as f32,
            light_stream: stream ^ LIGHT_STREAM,
            eye_seed: mix64(seed ^ EYE_STREAM),
            index: pass,
            max_len: opts.max_depth.saturating_add(1),
        }
    }
}

/// A subpath's state between vertices: the ray it follows, its throughput and the partial
/// MIS sums (the technical report's Eqs. 34-38).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SubPath {
    pub throughput: Vec3,
    /// Segments so far, the one being traced included.
    pub length: u32,
    pub d_vcm: f32,
    pub d_vc: f32,
    pub d_vm: f32,
    /// [`Options::bidirectional`]: whether a connection at a vertex past the subpath's first
    /// is a strategy.
    pub bidirectional: bool,
    /// Non-delta bounces made, and whether the last bounce was a delta one.
    pub diffuse: u32,
    pub last_specular: bool,
}

impl SubPath {
    /// A subpath of `pass` leaving its first vertex (the pinhole or the light) with these
    /// sums.
    pub fn start(pass: &Pass, d_vcm: f32, d_vc: f32, d_vm: f32) -> SubPath {
        SubPath {
            throughput: Vec3::ONE,
            length: 1,
            d_vcm,
            d_vc,
            d_vm,
            bidirectional: pass.opts.bidirectional,
            diffuse: 0,
            last_specular: false,
        }
    }

    /// An eye subpath whose last bounce was its first non-delta one (`E S* D`): emission it
    /// hits now is direct light at the first surface seen, which [`weights`] leaves to
    /// next-event estimation and BSDF sampling alone.
    pub fn direct(&self) -> bool {
        self.diffuse == 1 && !self.last_specular
    }

    pub fn sums(&self) -> weights::Sums {
        weights::Sums {
            d_vcm: self.d_vcm,
            d_vc: self.d_vc,
            d_vm: self.d_vm,
            joins: self.joins(),
        }
    }

    /// 1 where the vertex the subpath has reached (`length` segments from its start) can be
    /// the far end of a connection, 0 where that connection would be a bidirectional one
    /// (two or more vertices on each side) and the pass has none: the factor on `dVCM`
    /// wherever a weight or a sum counts that connection as a strategy.
    #[inline]
    pub fn joins(&self) -> f32 {
        weights::joins(self.bidirectional, self.length)
    }

    /// Arrival at a vertex `dist` away whose cosine to the incoming direction is `cos`: the
    /// sums move from solid angle at the last vertex to area at this one (skipping the
    /// distance for the first segment of a light at infinity, whose density is per area).
    #[inline]
    pub fn arrive(&mut self, dist2: f32, cos: f32, with_distance: bool) {
        if with_distance {
            self.d_vcm *= mis(dist2);
        }
        let c = mis(cos.abs());
        self.d_vcm /= c;
        self.d_vc /= c;
        self.d_vm /= c;
    }

    /// The sums after sampling `s` at a vertex whose reverse density (of sampling the way
    /// the subpath came, given `s.wi`) is `rev_pdf`.
    #[inline]
    pub fn scatter(&mut self, s: &BsdfSample, rev_pdf: f32, pass: &Pass) {
        let cos_out = s.wi.z.abs();
        self.last_specular = s.is_specular();
        if s.is_specular() {
            // A delta lobe's forward and reverse probabilities are equal (Fresnel is
            // symmetric), so only the cosine survives; no strategy but the subpath itself
            // ends here.
            self.d_vcm = 0.0;
            self.d_vc *= mis(cos_out);
            self.d_vm *= mis(cos_out);
        } else {
            self.diffuse += 1;
            let k = mis(cos_out / s.pdf);
            // `dVCM` here stands for the connection that samples this vertex from the other
            // side (the report's §6.3): a bidirectional one past the first vertex.
            let d_vcm = self.d_vcm * self.joins();
            self.d_vc = k * (self.d_vc * mis(rev_pdf) + d_vcm + pass.vm_factor);
            self.d_vm = k * (self.d_vm * mis(rev_pdf) + d_vcm * pass.vc_factor + 1.0);
            self.d_vcm = mis(1.0 / s.pdf);
        }
        self.throughput *= s.weight();
    }
}
