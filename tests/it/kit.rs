//! The test kit: what more than one module of `it` needs, in one place. Scenes (loaded from
//! `scenes/`, the worksheet scene at a test's resolution and seed, scene files written into a
//! scratch directory), methods run as the binary runs them, reading images back (layers,
//! pixels, regions, bits), the mean and standard error of independent samples, the command
//! line in process. Each helper panics with the underlying message where the binary would
//! report an error: in a test, a failure.
//!
//! Here and not in the library (`tests/lib.rs`) because only `it` uses these; the library
//! holds what the `fuzz` binary shares with `it` (the fuzz loops and the allocation tracker).

use emit::CausticPhoton;
use film::Image;
use glam::{DVec3, Vec3};
use render::{Layer, Overrides, Photons, Rendered, Run, Settings};
use scene::{Scene, SceneFile};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// Scenes.

/// The worksheet scene (two spheres in the Cornell box, 512 x 512, seed 1), relative to
/// [`scenes_dir`].
pub const WORKSHEET: &str = "cornell-spheres/analytic.toml";

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Loads a scene from `scenes/` as the file has it.
pub fn load(rel: &str) -> Scene {
    Scene::load(scenes_dir().join(rel)).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads `rel` from `scenes/` at `res` x `res` pixels with seed `seed`, then `edit` applied to
/// the parsed file (before the scene is built).
pub fn scene_at(rel: &str, res: u32, seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    let path = scenes_dir().join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::from_toml_with(&path, &text, |f| {
        f.seed = seed;
        f.camera.width = res;
        f.camera.height = res;
        edit(f);
    })
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (scene.camera.width, scene.camera.height, scene.seed()),
        (res, res, seed)
    );
    scene
}

/// The worksheet scene ([`WORKSHEET`]) at `res` x `res` pixels with seed `seed`.
pub fn worksheet(res: u32, seed: u64) -> Scene {
    scene_at(WORKSHEET, res, seed, |_| {})
}

/// [`worksheet`] with `edit` applied to the parsed file.
pub fn worksheet_with(res: u32, seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at(WORKSHEET, res, seed, edit)
}

/// The worksheet scene's file at `res` x `res` pixels, its mesh named by absolute path and
/// `extra` (TOML) appended, written as `dir/name`: for the command line and the studies,
/// which read scene files. Its path.
pub fn write_worksheet(dir: &Path, name: &str, res: u32, extra: &str) -> PathBuf {
    let src = scenes_dir().join(WORKSHEET);
    let src_dir = src.parent().unwrap_or_else(|| panic!("{}", src.display()));
    let text = std::fs::read_to_string(&src).unwrap_or_else(|e| panic!("{e}"));
    let edited = text
        .replace("obj = \"", &format!("obj = \"{}/", src_dir.display()))
        .replace("width = 512", &format!("width = {res}"))
        .replace("height = 512", &format!("height = {res}"));
    assert_ne!(text, edited, "the worksheet's file changed its form");
    let p = dir.join(name);
    std::fs::write(&p, edited + extra).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    p
}

/// Writes `files` (name, text) into `dir`, then loads the scene file `text` as if it were
/// `dir/name` (it is not written).
pub fn scene_in(dir: &Path, files: &[(&str, &str)], name: &str, text: &str) -> Scene {
    for (file, contents) in files {
        std::fs::write(dir.join(file), contents).unwrap_or_else(|e| panic!("{file}: {e}"));
    }
    Scene::from_toml(&dir.join(name), text).unwrap_or_else(|e| panic!("{e}"))
}

/// A scratch directory under the system's temporary directory, unique to this process and
/// `name`, removed when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    /// Makes the directory (empty: whatever a killed earlier run left is removed first).
    pub fn new(name: &str) -> TempDir {
        let d = std::env::temp_dir().join(format!("photonflow-it-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        TempDir(d)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Running methods, as the binary does (`render::methods::render`).

fn run_method(
    scene: &Scene,
    o: &Overrides,
    cache: &Path,
    photons: Photons,
    threads: Option<usize>,
) -> Rendered {
    let settings = Settings::new(scene, o).unwrap_or_else(|e| panic!("{e}"));
    let run = Run {
        scene,
        settings: &settings,
        cache,
        photons,
        threads,
    };
    render::methods::render(&run, &|_| {}).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs the method `o` names on `threads` threads (`None`: all cores); photon methods trace
/// their photon sets into `cache`, or reuse the ones there, as `render` does.
pub fn render(scene: &Scene, o: &Overrides, cache: &Path, threads: Option<usize>) -> Rendered {
    run_method(scene, o, cache, Photons::TraceOrReuse, threads)
}

/// Runs the method `o` names on the photon sets already in `cache` (never traces), as
/// `estimate` does.
pub fn render_cached(scene: &Scene, o: &Overrides, cache: &Path) -> Rendered {
    run_method(scene, o, cache, Photons::CacheOnly, None)
}

/// [`render`] for the methods that read no photon file: the cache directory named does not
/// exist, and is never touched.
pub fn render_uncached(scene: &Scene, o: &Overrides, threads: Option<usize>) -> Rendered {
    let cache = Path::new("/nonexistent/photonflow-it-cache");
    render(scene, o, cache, threads)
}

/// Runs the command line `photonflow <args>` in process (`photonflow::run_args`, the
/// binary's own entry): its exit code and one-line message.
pub fn cli(args: impl IntoIterator<Item = String>) -> (u8, Option<String>) {
    photonflow::run_args(std::iter::once("photonflow".to_string()).chain(args))
}

// ---------------------------------------------------------------------------------------------
// Images.

/// The image of the layer `name` among `layers` (a run's or a snapshot's).
pub fn layer_in<'a>(layers: &'a [Layer], name: &str) -> &'a Image {
    let l = layers.iter().find(|l| l.name == name);
    let l = l.unwrap_or_else(|| {
        let names: Vec<&str> = layers.iter().map(|l| l.name.as_str()).collect();
        panic!("no `{name}` layer (layers: {names:?})")
    });
    &l.image
}

/// The image of the run's layer `name`.
pub fn layer<'a>(r: &'a Rendered, name: &str) -> &'a Image {
    layer_in(&r.layers, name)
}

/// The image: the sum of the run's layers whose names pass `keep`.
pub fn sum_layers(r: &Rendered, keep: impl Fn(&str) -> bool) -> Image {
    let first = &r.layers[0].image;
    let mut img = Image::new(first.width, first.height);
    for l in r.layers.iter().filter(|l| keep(&l.name)) {
        img.add(&l.image).unwrap_or_else(|e| panic!("{e}"));
    }
    img
}

/// The pixels in f64, row by row.
pub fn dvec3s(img: &Image) -> Vec<DVec3> {
    img.data.iter().map(|p| Vec3::from(*p).as_dvec3()).collect()
}

/// Pixel `(x, y)` in f64.
pub fn pixel(img: &Image, (x, y): (usize, usize)) -> DVec3 {
    Vec3::from(img.get(x, y)).as_dvec3()
}

/// The mean of `pixels` of the image, per channel.
pub fn region_mean(img: &Image, pixels: &[(usize, usize)]) -> DVec3 {
    pixels.iter().map(|&p| pixel(img, p)).sum::<DVec3>() / pixels.len() as f64
}

/// The pixels `(x, y)` of the rectangle `[x0, y0, x1, y1)`, row by row.
pub fn rect([x0, y0, x1, y1]: [usize; 4]) -> Vec<(usize, usize)> {
    (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .collect()
}

/// The image's bits, for comparing two images bit for bit.
pub fn bits(img: &Image) -> Vec<[u32; 3]> {
    img.data.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// The pixels (index, value) with a channel that is not finite or is negative.
pub fn bad_pixels(img: &Image) -> Vec<(usize, [f32; 3])> {
    img.data
        .iter()
        .enumerate()
        .filter(|(_, p)| p.iter().any(|c| !c.is_finite() || *c < 0.0))
        .map(|(i, p)| (i, *p))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// What the worksheet scene's camera sees.

/// Points of a pixel (pixel units from its top-left corner): its centre and four points
/// near its corners.
pub const PIXEL_POINTS: [(f32, f32); 5] = [
    (0.5, 0.5),
    (0.02, 0.02),
    (0.98, 0.02),
    (0.02, 0.98),
    (0.98, 0.98),
];

/// What the worksheet scene's camera ray through `(x, y)` (pixel units) sees first, as a
/// region name: a wall of the box (told by its material and which way it faces: `left
/// wall`, `right wall`, `back wall`, `floor`, `ceiling`), one of the spheres (`glass
/// sphere`, `silver sphere`), or `None` (the light, open space).
pub fn seen(scene: &Scene, x: f32, y: f32) -> Option<&'static str> {
    let ray = scene.camera.ray(x, y);
    let hit = scene.geometry.intersect(&ray)?;
    let name = scene.material_names[hit.material as usize].as_str();
    if let geom::Prim::Sphere(_) = hit.prim {
        return match name {
            "glass" => Some("glass sphere"),
            "silver" => Some("silver sphere"),
            _ => None,
        };
    }
    if scene.emission[hit.material as usize] != Vec3::ZERO {
        return None;
    }
    let n = hit.point.n * -hit.point.n.dot(ray.d).signum();
    match name {
        "red" if n.x > 0.9 => Some("left wall"),
        "green" if n.x < -0.9 => Some("right wall"),
        "white" if n.z > 0.9 => Some("back wall"),
        "white" if n.y > 0.9 => Some("floor"),
        "white" if n.y < -0.9 => Some("ceiling"),
        _ => None,
    }
}

/// The pixels of `r` (`[x0, y0, x1, y1)`) all of whose [`PIXEL_POINTS`] see ([`seen`]) what
/// `keep` accepts.
pub fn pixels_seeing(
    scene: &Scene,
    r: [usize; 4],
    keep: impl Fn(&str) -> bool,
) -> Vec<(usize, usize)> {
    rect(r)
        .into_iter()
        .filter(|&(x, y)| {
            PIXEL_POINTS
                .iter()
                .all(|(u, v)| seen(scene, x as f32 + u, y as f32 + v).is_some_and(&keep))
        })
        .collect()
}

/// A caustic photon's footprint on its surface: the principal semi-axes (major, minor) of
/// its differentials `[a b]` projected into the tangent plane (the singular values), before
/// any clamp.
pub fn footprint_axes(p: &CausticPhoton) -> (f32, f32) {
    let (a, b) = (
        p.a - p.a.dot(p.normal) * p.normal,
        p.b - p.b.dot(p.normal) * p.normal,
    );
    let (p2, q, r2) = (a.length_squared(), a.dot(b), b.length_squared());
    let dev = (0.25 * (p2 - r2) * (p2 - r2) + q * q).sqrt();
    let mean = 0.5 * (p2 + r2);
    ((mean + dev).sqrt(), (mean - dev).max(0.0).sqrt())
}

// ---------------------------------------------------------------------------------------------
// Statistics.

/// Mean and standard error of independent samples, per channel, in f64.
#[derive(Clone, Copy, Debug, Default)]
pub struct Mean {
    n: f64,
    sum: DVec3,
    sum2: DVec3,
}

impl Mean {
    /// The samples `xs`.
    pub fn of(xs: impl IntoIterator<Item = DVec3>) -> Mean {
        let mut m = Mean::default();
        for x in xs {
            m.add(x);
        }
        m
    }

    pub fn add(&mut self, x: DVec3) {
        self.n += 1.0;
        self.sum += x;
        self.sum2 += x * x;
    }

    /// The number of samples.
    pub fn n(&self) -> f64 {
        self.n
    }

    /// The samples' sum.
    pub fn sum(&self) -> DVec3 {
        self.sum
    }

    pub fn mean(&self) -> DVec3 {
        self.sum / self.n
    }

    /// The standard error of [`Mean::mean`]: the samples' standard deviation (with Bessel's
    /// correction) over the square root of their number.
    pub fn se(&self) -> DVec3 {
        let m = self.mean();
        let var = (self.sum2 / self.n - m * m) * (self.n / (self.n - 1.0));
        (var.max(DVec3::ZERO) / self.n).powf(0.5)
    }
}

/// The noise of an estimate per `block` x `block` pixels (1: per pixel): per block and
/// channel, the sample variance of its mean over `images` (one per seed) over the squared
/// mean, averaged over the blocks and channels whose mean is above `1e-3`.
pub fn relative_variance(images: &[Image], block: usize) -> f64 {
    let n = images.len() as f64;
    let (w, h) = (images[0].width / block, images[0].height / block);
    let mean_of = |m: &Image, bx: usize, by: usize, c: usize| {
        let mut s = 0.0f64;
        for y in by * block..(by + 1) * block {
            for x in bx * block..(bx + 1) * block {
                s += f64::from(m.data[y * m.width + x][c]);
            }
        }
        s / (block * block) as f64
    };
    let (mut sum, mut count) = (0.0f64, 0usize);
    for (by, bx, c) in (0..h).flat_map(|y| (0..w).flat_map(move |x| (0..3).map(move |c| (y, x, c))))
    {
        let x: Vec<f64> = images.iter().map(|m| mean_of(m, bx, by, c)).collect();
        let mean = x.iter().sum::<f64>() / n;
        if mean > 1e-3 {
            let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            sum += var / (mean * mean);
            count += 1;
        }
    }
    sum / count.max(1) as f64
}
