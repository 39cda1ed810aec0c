//! `light`: light tracing, light paths connected to the camera at every vertex that can
//! carry light to it (`emit::trace_to_camera`), in passes of new paths. Unbiased wherever it
//! sees: sharp caustics from small lights come out as sharp as the pixels. It cannot see
//! light reaching the camera through specular surfaces (`S+ E`), which a `warning:` line
//! names when the scene has such surfaces. `[estimate.light]` holds its knobs.

use super::single_pass::{self, Facts, PassMethod, Passes};
use crate::rendered::{CountKind, Layer, Rendered};
use crate::run::Run;
use crate::settings::{Knob, LightSettings};
use crate::splat;
use film::Class;
use flow::PipelineOptions;
use glam::DVec3;

/// Paths per chunk of work: a chunk's contributions wait in memory until it is added.
const CHUNK: u64 = 4096;

/// Light paths per pass: `[estimate.light] photons`, or `[photons] photons` when it is 0.
pub(super) fn photons_per_pass(s: &crate::settings::Settings) -> u64 {
    match s.estimate.light.photons {
        0 => s.emit.photons,
        n => n,
    }
}

/// The image's f64 sums per class, pass by pass.
pub(super) struct Progressive<'a> {
    run: &'a Run<'a>,
    photons: u64,
    /// Per [`Class::ALL`], f64 sums per pixel over the passes made.
    images: Vec<Vec<DVec3>>,
    pub passes: u32,
    splats: u64,
    t_trace: f64,
}

impl<'a> Progressive<'a> {
    pub(super) fn new(run: &'a Run<'a>) -> Progressive<'a> {
        let photons = photons_per_pass(run.settings);
        let pixels = (run.scene.camera.width * run.scene.camera.height) as usize;
        Progressive {
            run,
            photons,
            images: vec![vec![DVec3::ZERO; pixels]; Class::ALL.len()],
            passes: 0,
            splats: 0,
            t_trace: 0.0,
        }
    }

    /// Pass `pass`'s sums per class (its own, so shards of passes add up as one run).
    pub(super) fn block(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        let (scene, photons) = (self.run.scene, self.photons);
        let max_depth = self.run.settings.emit.max_depth;
        let stream = emit::pass_stream(scene.seed(), pass);
        let t0 = std::time::Instant::now();
        let mut sums = vec![vec![DVec3::ZERO; self.images[0].len()]; Class::ALL.len()];
        let work = |range: std::ops::Range<u64>| {
            let n = range.end - range.start;
            let mut out = Vec::new();
            emit::trace_to_camera(scene, photons, max_depth, stream, range, &mut out);
            (n, out)
        };
        let opts = PipelineOptions {
            chunk: CHUNK,
            ..PipelineOptions::new(self.run.threads())
        };
        let mut splats = 0u64;
        flow::run_chunks(photons, &opts, &work, &mut |(n, out): (
            u64,
            Vec<emit::CameraSplat>,
        )| {
            splats += out.len() as u64;
            for c in out {
                if let Some(p) = sums[c.class as usize].get_mut(c.pixel as usize) {
                    *p += c.value;
                }
            }
            progress(n);
            Ok(())
        })?;
        self.splats += splats;
        self.t_trace += t0.elapsed().as_secs_f64();
        Ok(sums)
    }

    pub(super) fn add(&mut self, block: &[Vec<DVec3>]) {
        for (sums, b) in self.images.iter_mut().zip(block) {
            for (s, v) in sums.iter_mut().zip(b) {
                *s += *v;
            }
        }
        self.passes += 1;
    }

    /// One layer per class, each the mean over the passes made.
    pub(super) fn layers(&self) -> Vec<Layer> {
        let n = self.passes.max(1) as f64;
        Class::ALL
            .iter()
            .zip(&self.images)
            .map(|(&class, sums)| {
                let pixels: Vec<DVec3> = sums.iter().map(|v| *v / n).collect();
                Layer {
                    name: class.name().into(),
                    classes: vec![class],
                    image: splat::to_image(self.run.scene, &pixels),
                    count: self.passes as u64 * self.photons,
                    count_kind: CountKind::PhotonPaths,
                }
            })
            .collect()
    }

    fn facts(&self) -> Facts {
        let sp = &self.run.settings.estimate.light;
        let mut info = serde_json::Map::new();
        for (k, v) in [
            (
                "light",
                serde_json::json!(LightSettings {
                    passes: self.passes,
                    ..*sp
                }),
            ),
            ("light_photons_per_pass", self.photons.into()),
            ("light_passes", self.passes.into()),
            ("light_camera_splats", self.splats.into()),
            ("time_light_s", self.t_trace.into()),
            (
                "light_paths_per_s",
                ((self.passes as u64 * self.photons) as f64 / self.t_trace).into(),
            ),
        ] {
            info.insert(k.to_string(), v);
        }
        info
    }
}

/// Light tracing's run as blocks: its passes, one block each.
pub(super) fn blocks<'a>(run: &'a Run<'a>) -> crate::run::Blocks<'a> {
    single_pass::blocks(Progressive::new(run))
}

impl PassMethod for Progressive<'_> {
    const KNOB: Knob = Knob::LightPasses;
    const NAME: &'static str = "light tracing";

    fn settings(&self) -> &crate::settings::Settings {
        self.run.settings
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn layer_names(&self) -> Vec<String> {
        Class::ALL.iter().map(|c| c.name().to_string()).collect()
    }

    fn render_pass(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        Progressive::block(self, pass, progress)
    }

    fn add_pass(&mut self, sums: &[Vec<DVec3>]) {
        Progressive::add(self, sums);
    }

    fn layers_so_far(&self) -> Vec<Layer> {
        Progressive::layers(self)
    }

    fn facts(&self) -> Facts {
        Progressive::facts(self)
    }
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let scene = run.scene;
    let specular: Vec<&str> = scene
        .material_names
        .iter()
        .zip(&scene.materials)
        .filter(|(_, m)| m.is_specular())
        .map(|(n, _)| n.as_str())
        .collect();
    if !specular.is_empty() {
        eprintln!(
            "warning: light: light reaching the camera through specular surfaces ({}) is not \
             drawn: a light path cannot be joined to a pinhole through a delta lobe",
            specular.join(", ")
        );
    }
    crate::passes::run(
        &mut Passes(Progressive::new(run)),
        run.settings.time,
        progress,
    )
}
