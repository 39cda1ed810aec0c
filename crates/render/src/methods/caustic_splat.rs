//! `caustic-splat`: the caustic layers alone (`L S+ D S* E`, D the first diffuse vertex from
//! the eye, and with `[estimate.splat] indirect` the caustics seen through further diffuse
//! bounces) by photon differential splatting onto eye vertices, with no photon map (the
//! course framework's `splat_caustics_map`). `[estimate.splat]` holds its knobs.

use super::single_pass::{self, Facts, PassMethod, Passes};
use crate::rendered::{CountKind, Layer, Rendered};
use crate::run::Run;
use crate::settings::{Knob, SplatSettings};
use crate::splat;
use film::Class;

/// The splatted caustic layers being accumulated pass by pass: each pass makes new eye
/// vertices (new pixel samples) and new photons, so the mean over passes converges in both.
pub(super) struct Progressive<'a> {
    run: &'a Run<'a>,
    params: emit::EmitParams,
    /// f64 sums per pixel: `caustic`, and `caustic_indirect` when the settings follow
    /// caustic paths past their first diffuse hit.
    images: [Vec<glam::DVec3>; 2],
    pub passes: u32,
    vertices: usize,
    max_in_flight: usize,
    t_vertices: f64,
    t_splat: f64,
}

impl<'a> Progressive<'a> {
    pub(super) fn new(run: &'a Run<'a>) -> Progressive<'a> {
        let s = run.settings;
        let mut params = s.emit.clone();
        if s.estimate.splat.photons > 0 {
            params.photons = s.estimate.splat.photons;
        }
        let pixels = (run.scene.camera.width * run.scene.camera.height) as usize;
        let indirect = if s.estimate.splat.indirect { pixels } else { 0 };
        Progressive {
            run,
            params,
            images: [
                vec![glam::DVec3::ZERO; pixels],
                vec![glam::DVec3::ZERO; indirect],
            ],
            passes: 0,
            vertices: 0,
            max_in_flight: 0,
            t_vertices: 0.0,
            t_splat: 0.0,
        }
    }

    /// One more pass.
    pub(super) fn step(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        let block = self.block(self.passes as u64, progress)?;
        self.add(&block);
        Ok(())
    }

    /// The layers' names, in the order [`Progressive::block`] returns their sums.
    pub(super) fn layer_names(&self) -> Vec<String> {
        let n = if self.images[1].is_empty() { 1 } else { 2 };
        [Class::Caustic, Class::CausticIndirect][..n]
            .iter()
            .map(|c| c.name().to_string())
            .collect()
    }

    /// The f64 sums per pixel of pass `pass` alone, per layer: the unit a shard renders and a
    /// merge adds. Passes are independent (new eye vertices and photons from their own
    /// streams), so any range of them can run anywhere.
    pub(super) fn block(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<glam::DVec3>>, String> {
        let (run, s) = (self.run, self.run.settings);
        let sp = &s.estimate.splat;
        let t0 = std::time::Instant::now();
        let eyes = splat::eye_index(run.scene, sp, s.estimate.spp, pass, run.threads);
        self.t_vertices += t0.elapsed().as_secs_f64();
        self.vertices += eyes.len();
        let splatter = splat::Splatter {
            scene: run.scene,
            params: &self.params,
            settings: sp,
            eyes: &eyes,
        };
        // The pass's own sums, added to the run's afterwards: a shard's passes then add up
        // exactly as the one-machine run's do.
        let mut images = [
            vec![glam::DVec3::ZERO; self.images[0].len()],
            vec![glam::DVec3::ZERO; self.images[1].len()],
        ];
        let stats = splatter.pass(pass, &mut images, run.threads(), progress)?;
        self.max_in_flight = self.max_in_flight.max(stats.max_in_flight);
        self.t_splat += t0.elapsed().as_secs_f64();
        let n = self.layer_names().len();
        Ok(images.into_iter().take(n).collect())
    }

    /// Adds one pass's sums ([`Progressive::block`]) to the run's.
    pub(super) fn add(&mut self, block: &[Vec<glam::DVec3>]) {
        for (sums, b) in self.images.iter_mut().zip(block) {
            for (s, v) in sums.iter_mut().zip(b) {
                *s += *v;
            }
        }
        self.passes += 1;
        let s = self.run.settings;
        let open = s.time.is_some_and(|b| !b.capped);
        if s.estimate.splat.passes > 1 || open {
            // A time budget alone has no count to show.
            let of = match open {
                true => String::new(),
                false => format!("/{}", s.estimate.splat.passes),
            };
            eprintln!(
                "splat pass {}{of}: {:.2} s, {:.3} M photons/s",
                self.passes,
                self.t_splat,
                (self.passes as u64 * self.params.photons) as f64 / self.t_splat / 1e6
            );
        }
    }

    /// The layers so far, each the mean over the passes made.
    pub(super) fn layers(&self) -> Vec<Layer> {
        let classes: &[Class] = if self.images[1].is_empty() {
            &[Class::Caustic]
        } else {
            &[Class::Caustic, Class::CausticIndirect]
        };
        let n = self.passes.max(1) as f64;
        classes
            .iter()
            .zip(&self.images)
            .map(|(&class, sums)| {
                let pixels: Vec<glam::DVec3> = sums.iter().map(|v| *v / n).collect();
                Layer {
                    name: class.name().into(),
                    classes: vec![class],
                    image: splat::to_image(self.run.scene, &pixels),
                    count: self.passes as u64 * self.params.photons,
                    count_kind: CountKind::PhotonPaths,
                }
            })
            .collect()
    }

    /// What `image.json` records of the splat.
    pub(super) fn facts(&self) -> Facts {
        let (scene, sp) = (self.run.scene, &self.run.settings.estimate.splat);
        let mut info = serde_json::Map::new();
        for (k, v) in [
            // The settings of the run made: a time budget sets the passes.
            (
                "splat",
                serde_json::json!(SplatSettings {
                    passes: self.passes,
                    ..*sp
                }),
            ),
            ("splat_photons_emitted", self.params.photons.into()),
            ("eye_vertices", self.vertices.into()),
            (
                "splat_indirect_radius",
                splat::indirect_radius(scene, sp).into(),
            ),
            ("splat_max_radius", splat::max_radius(scene, sp).into()),
            ("splat_passes", self.passes.into()),
            ("splat_max_chunks_in_flight", self.max_in_flight.into()),
            ("time_eye_vertices_s", self.t_vertices.into()),
            ("time_splat_s", self.t_splat.into()),
            (
                "splat_photons_per_s",
                ((self.passes as u64 * self.params.photons) as f64 / self.t_splat).into(),
            ),
        ] {
            info.insert(k.to_string(), v);
        }
        info
    }
}

/// Splatting's run as blocks: its passes, one block each.
pub(super) fn blocks<'a>(run: &'a Run<'a>) -> crate::run::Blocks<'a> {
    single_pass::blocks(Progressive::new(run))
}

impl PassMethod for Progressive<'_> {
    const KNOB: Knob = Knob::SplatPasses;
    const NAME: &'static str = "splatting";

    fn settings(&self) -> &crate::settings::Settings {
        self.run.settings
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn layer_names(&self) -> Vec<String> {
        Progressive::layer_names(self)
    }

    fn render_pass(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<glam::DVec3>>, String> {
        Progressive::block(self, pass, progress)
    }

    fn add_pass(&mut self, sums: &[Vec<glam::DVec3>]) {
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
    crate::passes::run(
        &mut Passes(Progressive::new(run)),
        run.settings.time,
        progress,
    )
}
