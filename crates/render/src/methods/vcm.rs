//! `vcm`: vertex connection and merging (the `vcm` crate), in passes: each traces one light
//! subpath per pixel (their vertices stored and joined to the camera), builds the merging
//! grid over them, then one eye subpath per pixel. `[estimate.vcm]` holds its knobs.

use super::single_pass::{self, Facts, PassMethod, Passes};
use crate::rendered::{CountKind, Layer, Rendered};
use crate::run::Run;
use crate::settings::{Knob, VcmSettings};
use crate::splat;
use film::Class;
use flow::PipelineOptions;
use glam::{DVec3, Vec3};
use vcm::{CameraSplat, LightVertex};

/// Subpaths per chunk of work. Each pass waits for its slowest chunk twice (light side, then
/// eye side), so chunks are small: at 128 x 128 a pass of 4096-path chunks left a core idle a
/// fifth of the time (McGuire's Glossy box, 64 passes: 3.2 s against 2.7-2.8 s at 512 and 256,
/// images the same for any chunking).
const CHUNK: u64 = 512;

/// A chunk of light subpaths: their vertices, each path's vertex count, their camera splats
/// and, when merging, what the grid reads of each vertex.
type LightChunk = (
    Vec<LightVertex>,
    Vec<u32>,
    Vec<CameraSplat>,
    Vec<(Vec3, vcm::Merged)>,
);

/// The knobs of the `vcm` crate for this run.
pub(crate) fn options(run: &Run) -> vcm::Options {
    let s = run.settings;
    let v = &s.estimate.vcm;
    vcm::Options {
        max_depth: s.render.max_depth,
        rr_depth: s.render.rr_depth,
        light_paths: v.light_paths,
        radius: if v.radius > 0.0 {
            v.radius
        } else {
            auto_radius(run.scene)
        },
        alpha: v.alpha,
        strategies: vcm::Strategies {
            hits: v.strategies.hits,
            nee: v.strategies.nee,
            camera: v.strategies.camera,
            connect: v.strategies.connect,
            merge: v.strategies.merge,
        },
        bidirectional: v.bidirectional,
    }
}

/// A pixel's footprint at the distance from the camera to the scene's centre: merging
/// within it blurs no more than the pixels do, and leaves a focus sharper than that to light
/// tracing, whose MIS weight there grows as the radius shrinks.
pub fn auto_radius(scene: &scene::Scene) -> f32 {
    let b = scene.geometry.bounds();
    let centre = 0.5 * (b.min + b.max);
    let distance = (centre - scene.camera.eye).length();
    let pixel_angle =
        2.0 * (scene.camera.vfov_deg.to_radians() * 0.5).tan() / scene.camera.height as f32;
    let r = distance * pixel_angle;
    if r.is_finite() && r > 0.0 { r } else { 1.0 }
}

pub(super) struct Progressive<'a> {
    run: &'a Run<'a>,
    opts: vcm::Options,
    /// f64 sums per pixel over the passes made.
    image: Vec<DVec3>,
    pub passes: u32,
    light_vertices: u64,
    /// The last pass's light vertices and an eighth: the next pass's arrays start this big.
    last_vertices: usize,
    t_light: f64,
    t_eye: f64,
}

impl<'a> Progressive<'a> {
    pub(super) fn new(run: &'a Run<'a>) -> Progressive<'a> {
        let pixels = (run.scene.camera.width * run.scene.camera.height) as usize;
        Progressive {
            run,
            opts: options(run),
            image: vec![DVec3::ZERO; pixels],
            passes: 0,
            light_vertices: 0,
            last_vertices: 0,
            t_light: 0.0,
            t_eye: 0.0,
        }
    }

    /// Pass `pass`'s pixel sums.
    pub(super) fn block(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<DVec3>, String> {
        let scene = self.run.scene;
        let p = vcm::Pass::new(scene, self.opts, pass);
        let opts = PipelineOptions {
            chunk: CHUNK,
            ..PipelineOptions::new(self.run.threads())
        };
        let t0 = std::time::Instant::now();
        let mut sums = vec![DVec3::ZERO; self.image.len()];
        let merge = self.opts.strategies.merge;
        // What the merging grid reads of each vertex, taken out on the workers: the grid's
        // build, serial between the two sides of a pass, then reads 52 bytes a vertex, not
        // 136 (at 128 x 128 the build was a tenth of a pass's time).
        let light = |range: std::ops::Range<u64>| {
            let (mut v, mut c, mut s) = (Vec::new(), Vec::new(), Vec::new());
            vcm::light_paths(scene, &p, range, &mut v, &mut c, &mut s);
            let m: Vec<_> = if merge {
                v.iter().map(LightVertex::merged).collect()
            } else {
                Vec::new()
            };
            // Only bidirectional connections read whole vertices: without them a pass keeps
            // what merging reads and the counts, and never copies the vertices together.
            if !p.opts.bidirectional {
                v = Vec::new();
            }
            (v, c, s, m)
        };
        let mut vertices: Vec<LightVertex> = Vec::new();
        if self.opts.bidirectional {
            vertices.reserve(self.last_vertices);
        }
        let mut merged: Vec<(Vec3, vcm::Merged)> = Vec::new();
        if merge {
            merged.reserve(self.last_vertices);
        }
        let mut starts: Vec<u32> = vec![0];
        flow::run_chunks(
            p.light_paths,
            &opts,
            &light,
            &mut |(v, c, s, m): LightChunk| {
                vertices.extend_from_slice(&v);
                merged.extend_from_slice(&m);
                for n in c {
                    let last = starts.last().copied().unwrap_or(0);
                    starts.push(last.saturating_add(n));
                }
                for splat in s {
                    if let Some(px) = sums.get_mut(splat.pixel as usize) {
                        *px += splat.value;
                    }
                }
                Ok(())
            },
        )?;
        let made = starts.last().copied().unwrap_or(0) as usize;
        if made >= u32::MAX as usize {
            return Err(format!(
                "vcm: {made} light vertices in one pass is more than it can index"
            ));
        }
        // No grid when merging is switched off: nothing would query it.
        let grid = merge.then(|| vcm::Grid::build(merged.iter().copied(), p.radius));
        drop(merged);
        self.last_vertices = made + made / 8;
        let t1 = std::time::Instant::now();
        let side = vcm::LightSide {
            vertices: &vertices,
            starts: &starts,
            grid: grid.as_ref(),
        };
        let eye =
            |range: std::ops::Range<u64>| (range.start, vcm::eye_paths(scene, &p, &side, range));
        let pixels = self.image.len() as u64;
        flow::run_chunks(pixels, &opts, &eye, &mut |(start, px): (
            u64,
            Vec<DVec3>,
        )| {
            let n = px.len() as u64;
            for (i, v) in px.into_iter().enumerate() {
                if let Some(s) = sums.get_mut(start as usize + i) {
                    *s += v;
                }
            }
            progress(n);
            Ok(())
        })?;
        self.light_vertices += made as u64;
        self.t_light += (t1 - t0).as_secs_f64();
        self.t_eye += t1.elapsed().as_secs_f64();
        Ok(sums)
    }

    pub(super) fn add(&mut self, block: &[DVec3]) {
        for (s, v) in self.image.iter_mut().zip(block) {
            *s += *v;
        }
        self.passes += 1;
    }

    /// The whole image, the mean over the passes made.
    pub(super) fn layers(&self) -> Vec<Layer> {
        let n = self.passes.max(1) as f64;
        let pixels: Vec<DVec3> = self.image.iter().map(|v| *v / n).collect();
        vec![Layer {
            name: "vcm".into(),
            classes: Class::ALL.to_vec(),
            image: splat::to_image(self.run.scene, &pixels),
            count: self.passes as u64,
            count_kind: CountKind::Spp,
        }]
    }

    fn facts(&self) -> Facts {
        let s = &self.run.settings.estimate.vcm;
        let mut info = serde_json::Map::new();
        for (k, v) in [
            (
                "vcm",
                serde_json::json!(VcmSettings {
                    passes: self.passes,
                    ..*s
                }),
            ),
            ("vcm_radius", self.opts.radius.into()),
            ("vcm_passes", self.passes.into()),
            ("vcm_light_vertices", self.light_vertices.into()),
            ("time_vcm_light_s", self.t_light.into()),
            ("time_vcm_eye_s", self.t_eye.into()),
        ] {
            info.insert(k.to_string(), v);
        }
        info
    }
}

/// The run as blocks: its passes, one block each (a pass's radius is a function of its
/// index alone, so any range of passes renders apart).
pub(super) fn blocks<'a>(run: &'a Run<'a>) -> crate::run::Blocks<'a> {
    single_pass::blocks(Progressive::new(run))
}

impl PassMethod for Progressive<'_> {
    const KNOB: Knob = Knob::VcmPasses;
    const NAME: &'static str = "vcm";

    fn settings(&self) -> &crate::settings::Settings {
        self.run.settings
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn layer_names(&self) -> Vec<String> {
        vec!["vcm".into()]
    }

    fn render_pass(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        Ok(vec![Progressive::block(self, pass, progress)?])
    }

    fn add_pass(&mut self, sums: &[Vec<DVec3>]) {
        if let Some(s) = sums.first() {
            Progressive::add(self, s);
        }
    }

    fn layers_so_far(&self) -> Vec<Layer> {
        Progressive::layers(self)
    }

    fn facts(&self) -> Facts {
        Progressive::facts(self)
    }
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    crate::passes::run(
        &mut Passes(Progressive::new(run)),
        run.settings.time,
        progress,
    )
}
