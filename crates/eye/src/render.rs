//! Parallel rendering over tiles into a film with one layer per [`Class`].

use crate::{Class, PathOptions, PathTracer};
use film::{Film, TileBuffer, tiles};
use math::{Rng, Sampler, SobolSampler, mix64};
use rayon::prelude::*;
use scene::Scene;

/// Settings of one eye pass. Path depths come from the scene's `[render]` settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Samples per pixel (box-filtered, jittered within the pixel).
    pub spp: u32,
    /// Index of the first sample: a progressive run renders samples `first_sample ..
    /// first_sample + spp` of each pixel per pass, the same samples one run of all of them
    /// draws.
    pub first_sample: u32,
    /// Include the paths photon splatting owns at first eye vertices (`L S+ D S* E`, the
    /// `caustic` layer); see [`PathOptions::caustics`].
    pub caustics: bool,
    /// Include caustics seen after a further diffuse bounce (the `caustic_indirect` layer);
    /// see [`PathOptions::caustic_indirect`].
    pub caustic_indirect: bool,
    /// Worker threads; `None` uses rayon's global pool. Does not change the image.
    pub threads: Option<usize>,
    /// Tile edge in pixels. Does not change the image.
    pub tile: u32,
}

impl RenderOptions {
    /// `spp` and `tile` from the scene's `[render]` settings, caustics on, global pool.
    pub fn from_scene(scene: &Scene) -> RenderOptions {
        let r = scene.render();
        RenderOptions {
            spp: r.spp,
            first_sample: 0,
            caustics: true,
            caustic_indirect: true,
            threads: None,
            tile: r.tile,
        }
    }
}

/// Renders the scene from its camera into a film with the layers named by [`Class::name`], in
/// [`Class::ALL`] order. Each layer holds per-pixel sums of sample contributions (and the
/// sample count as weight): resolve with `Normalize::Constant(spp)` (or `Normalize::Weight`).
///
/// The film is bit-identical for any `threads` and `tile`: pixel sample `s` of pixel
/// `p = y * width + x` uses `Rng::for_index(scene.seed(), s * pixels + p)`, each pixel's samples
/// are summed in order in one tile buffer, and each pixel receives exactly one merge.
///
/// `progress` is called once per finished tile with the number of samples that tile took
/// (an increment, not a running total), from worker threads.
///
/// # Panics
/// If `opts.spp` or `opts.tile` is zero (callers validate settings first).
pub fn render(scene: &Scene, opts: &RenderOptions, progress: &(dyn Fn(u64) + Sync)) -> Film {
    let tracer = tracer(scene, opts);
    let names = Class::ALL.map(Class::name);
    match scene.render().sampler {
        scene::SamplerKind::Sobol => render_layers(scene, opts, names, progress, &|ray, s| {
            by_class::<SobolSampler>(&tracer, ray, s)
        }),
        scene::SamplerKind::Independent => {
            render_layers(scene, opts, names, progress, &|ray, s| {
                by_class::<Rng>(&tracer, ray, s)
            })
        }
    }
}

/// The path tracer of one eye pass.
fn tracer<'a>(scene: &'a Scene, opts: &RenderOptions) -> PathTracer<'a> {
    PathTracer::new(
        scene,
        PathOptions {
            caustics: opts.caustics,
            caustic_indirect: opts.caustic_indirect,
            ..PathOptions::from_scene(scene)
        },
    )
}

/// One sample's radiance per class, in [`Class::ALL`] order.
fn by_class<S: Sampler>(tracer: &PathTracer, ray: geom::Ray, s: &mut S) -> [glam::Vec3; 5] {
    let l = tracer.li(ray, s);
    Class::ALL.map(|p| l.get(p))
}

/// [`render`]'s samples added straight to per-pixel sums a progressive run keeps: for each
/// entry of `classes`, `sums[k][p] += ` the sum of pixel `p`'s samples of that class, the
/// same f64 values (summed in the same order) as [`render`]'s film holds, for any thread
/// count. Without a film there is nothing to allocate, merge or copy per pass: rows of pixels
/// go to the workers, each adding into rows of `sums` it alone holds.
///
/// `progress` is called once per finished row with the samples it took.
///
/// # Panics
/// If `opts.spp` is zero, or `sums` is not one image of the camera's size per class.
pub fn render_into(
    scene: &Scene,
    opts: &RenderOptions,
    classes: &[Class],
    sums: &mut [Vec<glam::DVec3>],
    progress: &(dyn Fn(u64) + Sync),
) {
    let tracer = tracer(scene, opts);
    let slots: Vec<usize> = classes
        .iter()
        .map(|c| Class::ALL.iter().position(|a| a == c).unwrap_or(0))
        .collect();
    match scene.render().sampler {
        scene::SamplerKind::Sobol => add_rows(scene, opts, &slots, sums, progress, &|ray, s| {
            by_class::<SobolSampler>(&tracer, ray, s)
        }),
        scene::SamplerKind::Independent => {
            add_rows(scene, opts, &slots, sums, progress, &|ray, s| {
                by_class::<Rng>(&tracer, ray, s)
            })
        }
    }
}

/// The sums of samples `range` of pixel `(x, y)`, per entry of `sample`'s result, in sample
/// order: pixel sample `s` draws from [`PixelSampler::for_pixel_sample`]'s sampler, two
/// numbers for its jitter first.
fn pixel_sums<const N: usize, S: PixelSampler>(
    scene: &Scene,
    seed: u64,
    pixels: u64,
    (x, y): (usize, usize),
    range: std::ops::Range<u64>,
    sample: &(dyn Fn(geom::Ray, &mut S) -> [glam::Vec3; N] + Sync),
) -> [glam::DVec3; N] {
    let pixel = (y * scene.camera.width as usize + x) as u64;
    let mut sums = [glam::DVec3::ZERO; N];
    for s in range {
        let mut rng = S::for_pixel_sample(seed, pixels, pixel, s);
        let [jx, jy] = rng.uniform2();
        let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
        for (sum, v) in sums.iter_mut().zip(sample(ray, &mut rng)) {
            *sum += v.as_dvec3();
        }
    }
    sums
}

/// [`render_into`]'s row loop: `slots[k]` is the sample's entry that `sums[k]` adds.
fn add_rows<const N: usize, S: PixelSampler>(
    scene: &Scene,
    opts: &RenderOptions,
    slots: &[usize],
    sums: &mut [Vec<glam::DVec3>],
    progress: &(dyn Fn(u64) + Sync),
    sample: &(dyn Fn(geom::Ray, &mut S) -> [glam::Vec3; N] + Sync),
) {
    assert!(opts.spp > 0, "render: spp must be positive");
    let (width, height) = (scene.camera.width as usize, scene.camera.height as usize);
    assert!(
        sums.len() == slots.len() && sums.iter().all(|s| s.len() == width * height),
        "render_into: one {width}x{height} image per class"
    );
    let seed = scene.seed();
    let pixels = (width * height) as u64;
    let (first, spp) = (opts.first_sample as u64, opts.spp as u64);
    // Row `y` of every class's sums, so that each worker holds the rows it adds to.
    let mut rows: Vec<Vec<&mut [glam::DVec3]>> = (0..height).map(|_| Vec::new()).collect();
    for image in sums.iter_mut() {
        for (row, r) in rows.iter_mut().zip(image.chunks_mut(width)) {
            row.push(r);
        }
    }
    let work = || {
        rows.into_par_iter().enumerate().for_each(|(y, mut row)| {
            for x in 0..width {
                let acc = pixel_sums(scene, seed, pixels, (x, y), first..first + spp, sample);
                for (r, &slot) in row.iter_mut().zip(slots) {
                    r[x] += acc.get(slot).copied().unwrap_or_default();
                }
            }
            progress(width as u64 * spp);
        })
    };
    on_threads(opts.threads, work);
}

/// How the tile loop makes the sampler of pixel sample `s` of pixel `p` (of `pixels`).
pub(crate) trait PixelSampler: Sampler + Sized {
    fn for_pixel_sample(seed: u64, pixels: u64, pixel: u64, s: u64) -> Self;
}

impl PixelSampler for Rng {
    /// Stream `s * pixels + p`: sample-major, so a pass of samples draws what the same
    /// samples of a longer run draw.
    fn for_pixel_sample(seed: u64, pixels: u64, pixel: u64, s: u64) -> Rng {
        Rng::for_index(seed, s * pixels + pixel)
    }
}

impl PixelSampler for SobolSampler {
    /// Sample `s` of the pixel's own scrambled sequence (indices past 2^32 wrap: the
    /// sequence repeats only after four billion samples of one pixel).
    fn for_pixel_sample(seed: u64, _pixels: u64, pixel: u64, s: u64) -> SobolSampler {
        SobolSampler::new(mix64(seed ^ mix64(pixel ^ 0x736f_626f_6c00)), s as u32)
    }
}

/// The tile machinery shared by every eye-pass method: one film layer per entry of `names`,
/// pixel sample `s` of pixel `p` drawing from the sampler [`PixelSampler::for_pixel_sample`]
/// makes (after two numbers for the pixel jitter), `sample` returning one contribution per
/// layer.
pub(crate) fn render_layers<const N: usize, S: PixelSampler>(
    scene: &Scene,
    opts: &RenderOptions,
    names: [&str; N],
    progress: &(dyn Fn(u64) + Sync),
    sample: &(dyn Fn(geom::Ray, &mut S) -> [glam::Vec3; N] + Sync),
) -> Film {
    assert!(opts.spp > 0, "render: spp must be positive");
    assert!(opts.tile > 0, "render: tile must be positive");
    let (width, height) = (scene.camera.width as usize, scene.camera.height as usize);
    let mut film = Film::new(width, height);
    // All layers exist before tiles are handed out, so every tile has them in the same order.
    for name in names {
        film.layer_mut(name);
    }
    let rects = tiles(width, height, opts.tile as usize);
    let work = || -> Vec<TileBuffer> {
        rects
            .par_iter()
            .map(|&rect| {
                let buf = render_tile(scene, &film, rect, opts, names, sample);
                progress(rect.area() as u64 * opts.spp as u64);
                buf
            })
            .collect()
    };
    let buffers = on_threads(opts.threads, work);
    // `collect` keeps tile order; merging in that order is deterministic (and, since tiles
    // partition the image, the order would not matter anyway).
    for buf in &buffers {
        film.merge_tile(buf);
    }
    film
}

fn render_tile<const N: usize, S: PixelSampler>(
    scene: &Scene,
    film: &Film,
    rect: film::Rect,
    opts: &RenderOptions,
    names: [&str; N],
    sample: &(dyn Fn(geom::Ray, &mut S) -> [glam::Vec3; N] + Sync),
) -> TileBuffer {
    let seed = scene.seed();
    let width = film.width();
    // Sample-major indices: sample s of every pixel before sample s + 1 of any, so a pass
    // of samples draws what the same samples of a longer run draw.
    let pixels = (width * film.height()) as u64;
    let (first, spp) = (opts.first_sample as u64, opts.spp as u64);
    let mut buf = film.tile_buffer(rect);
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let sums = pixel_sums(scene, seed, pixels, (x, y), first..first + spp, sample);
            for (name, sum) in names.iter().zip(sums) {
                let layer = buf.layer_mut(name);
                layer.add_f64(x, y, sum.to_array());
                layer.add_weight(x, y, spp as f64);
            }
        }
    }
    buf
}

/// Runs `work` on a pool of `threads` workers (`None`, or no pool to be had under resource
/// limits: rayon's global pool). Every eye pass's result is the same for any pool.
pub fn on_threads<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> T {
    match threads.and_then(|n| rayon::ThreadPoolBuilder::new().num_threads(n).build().ok()) {
        Some(pool) => pool.install(work),
        None => work(),
    }
}
