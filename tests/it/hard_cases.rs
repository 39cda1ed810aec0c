//! Hard cases stay numerically stable: one data-driven table ([`CASES`]),
//! each case a scene built by a function, the methods it runs (through
//! `render::methods::render`, as the binary does) and a check. Every case checks that every
//! pixel of every layer of every run is finite and non-negative and that the run made some
//! light; the checks add what the scene allows:
//!
//! - closed forms: Lambert's polygon irradiance under grazing camera rays, a photon file of
//!   1 000 photons at one point read back by the k-NN and fixed-radius estimates, the light's
//!   emitted radiance seen directly;
//! - flux: the fixed-radius estimate of a point's photons integrates to their flux, the
//!   splatted focused caustic integrates to its photons' flux, and the flux a light inside a
//!   glass cube sends to the floor (total internal reflection chains) matches an independent
//!   f64 simulation of the cube;
//! - invariances: the worksheet scene scaled by 1e-3 and 1e4 (every length in `[estimate]`
//!   scaled with it) renders the unscaled image; spheres of radius 1e-4 and degenerate
//!   triangles change nothing; a light near the f32 power limit renders the unit light's
//!   image times its radiance;
//! - agreement: seen from inside the glass sphere and on the ceiling round the light 0.0025
//!   under it, the photon methods against the path tracer; the ceiling behind the light gets
//!   no direct light at all, and the light seen directly reads its radiance; a glass sphere of
//!   radius 1e-4 seen from 4e-4 away is hit where the f64 root says and imaged alike by all.
//!
//! Seeds are fixed; each tolerance is a few standard errors, or near what was measured when
//! the case is deterministic (the numbers are in the comments and printed by the test).

use crate::kit::{TempDir, bad_pixels, dvec3s, footprint_axes, layer, render, worksheet_with};
use glam::{DVec3, Vec3};
use render::{Overrides, Rendered, Settings};
use scene::{Method, Scene, SceneFile};
use std::cell::OnceCell;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use store::MapKind;

// ---------------------------------------------------------------------------------------------
// The table.

/// One hard case: `scene` builds it in a scratch directory (files and photon cache), `runs`
/// lists the method runs (each an `Overrides` naming its method), `check` tests the results
/// beyond the common checks.
struct Case {
    name: &'static str,
    scene: fn(&Path) -> Scene,
    runs: fn() -> Vec<Overrides>,
    check: fn(&Ctx),
}

/// What a check sees: the case's scene and directory, every run's overrides and layers, and
/// what the cases share (the unscaled worksheet's runs).
struct Ctx<'a> {
    dir: &'a Path,
    scene: &'a Scene,
    runs: &'a [(Overrides, Rendered)],
    shared: &'a Shared,
}

const CASES: &[Case] = &[
    Case {
        name: "camera inside the glass sphere",
        scene: camera_in_glass,
        runs: || {
            all(&[
                Method::Path,
                Method::GlobalDirect,
                Method::FinalGather,
                Method::CausticSplat,
                Method::Sppm,
            ])
        },
        check: check_camera_in_glass,
    },
    Case {
        name: "light 0.0025 under the ceiling",
        scene: light_under_ceiling,
        runs: || {
            // The ceiling sees only indirect light: at 16 spp the path tracer's mean there
            // moved by 10% between two unbiased samplers (independent, then Sobol), more
            // than the methods' own differences; 128 spp makes it the reference it is
            // compared as.
            let mut runs = all(&[Method::GlobalDirect, Method::FinalGather, Method::Sppm]);
            runs.insert(0, quick(Method::Path).spp(128));
            runs
        },
        check: check_light_under_ceiling,
    },
    Case {
        name: "grazing camera rays",
        scene: grazing,
        runs: || {
            // k = 50 for the global map shown directly: at the framework's k = 1000 the discs
            // on the far floor, where 20 000 paths leave few photons, reach under the light
            // (measured +132%, the k-NN estimate's bias, not a numerical fault).
            vec![
                quick(Method::Path).spp(64),
                Overrides {
                    k: Some(50),
                    ..quick(Method::GlobalDirect)
                },
                quick(Method::FinalGather),
                quick(Method::Sppm),
            ]
        },
        check: check_grazing,
    },
    Case {
        name: "total internal reflection chains",
        scene: tir_cube,
        runs: || {
            all(&[
                Method::Path,
                Method::FinalGather,
                Method::CausticSplat,
                Method::Sppm,
            ])
        },
        check: check_tir,
    },
    Case {
        name: "caustic focus",
        scene: focus,
        runs: || {
            let mut v = all(&[Method::PathSplat, Method::FinalGather, Method::Sppm]);
            v.insert(
                0,
                Overrides {
                    photons: Some(FOCUS_PHOTONS),
                    ..quick(Method::CausticSplat).spp(16)
                },
            );
            v
        },
        check: check_focus,
    },
    Case {
        name: "1000 photons at one point",
        scene: point_photons,
        runs: || {
            vec![
                Overrides {
                    k: Some(50),
                    ..gd_on_point()
                },
                Overrides {
                    k: Some(POINT_PHOTONS as usize),
                    ..gd_on_point()
                },
                Overrides {
                    k: Some(50),
                    gather_rays: Some(8),
                    ..quick(Method::FinalGather)
                },
            ]
        },
        check: check_point_photons,
    },
    Case {
        name: "k larger than the photon count",
        scene: point_photons,
        runs: || {
            vec![
                Overrides {
                    k: Some(2 * POINT_PHOTONS as usize),
                    ..gd_on_point()
                },
                Overrides {
                    k: Some(2 * POINT_PHOTONS as usize),
                    gather_rays: Some(8),
                    ..quick(Method::FinalGather)
                },
            ]
        },
        check: check_k_above_count,
    },
    Case {
        name: "scene scaled by 1e-3",
        scene: |_| scaled_worksheet(WS_RES, 1e-3, |_| {}),
        runs: worksheet_runs,
        check: check_scaled,
    },
    Case {
        name: "scene scaled by 1e4",
        scene: |_| scaled_worksheet(WS_RES, 1e4, |_| {}),
        runs: worksheet_runs,
        check: check_scaled,
    },
    Case {
        name: "degenerate triangles",
        scene: |dir| floor_scene(dir, true),
        runs: || {
            all(&[
                Method::Path,
                Method::GlobalDirect,
                Method::FinalGather,
                Method::Sppm,
                Method::Light,
                Method::Vcm,
            ])
        },
        check: check_degenerate,
    },
    Case {
        name: "sphere of radius 1e-4",
        scene: |_| scaled_worksheet(WS_RES, 1.0, add_tiny_spheres),
        runs: worksheet_runs,
        check: check_tiny_sphere,
    },
    Case {
        name: "sphere of radius 1e-4 up close",
        scene: |_| {
            scaled_worksheet(WS_RES, 1.0, |f| {
                add_tiny_spheres(f);
                f.camera.eye = [TINY_CENTRE[0], TINY_CENTRE[1], TINY_CENTRE[2] + 4e-4];
                f.camera.look_at = TINY_CENTRE;
                f.camera.vfov = 40.0;
            })
        },
        runs: || all(&[Method::Path, Method::FinalGather, Method::Sppm]),
        check: check_tiny_sphere_close,
    },
    Case {
        name: "light power near the f32 limit",
        scene: |dir| power_scene(dir, HUGE_LE).unwrap_or_else(|e| panic!("{e}")),
        runs: || all(&Method::ALL),
        check: check_huge_power,
    },
    Case {
        name: "plastics, thin glass, conductors",
        scene: |_| new_materials_worksheet(WS_RES),
        runs: || all(&Method::ALL),
        check: check_new_materials,
    },
];

#[test]
fn hard_cases_render_finite_images_and_keep_their_flux() {
    let root = TempDir::new("hard-cases");
    let shared = Shared {
        root: root.path().to_path_buf(),
        reference: OnceCell::new(),
    };
    // One case may be chosen by name (`HARD_CASE=tir cargo test hard_cases`) while working.
    let only = std::env::var("HARD_CASE").ok();
    let mut failed = Vec::new();
    let mut report = String::new();
    let t_all = std::time::Instant::now();
    for (i, case) in CASES.iter().enumerate() {
        if only
            .as_ref()
            .is_some_and(|o| !case.name.contains(o.as_str()))
        {
            continue;
        }
        let t0 = std::time::Instant::now();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let dir = root.path().join(format!("case{i}"));
            std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
            let scene = (case.scene)(&dir);
            let runs: Vec<(Overrides, Rendered)> = (case.runs)()
                .into_iter()
                .map(|o| {
                    let r = render(&scene, &o, &dir.join("cache"), None);
                    common_checks(&o, &r);
                    (o, r)
                })
                .collect();
            (case.check)(&Ctx {
                dir: &dir,
                scene: &scene,
                runs: &runs,
                shared: &shared,
            });
        }));
        let s = t0.elapsed().as_secs_f64();
        let _ = writeln!(
            report,
            "{:<36} {:>6.2} s  {}",
            case.name,
            s,
            if outcome.is_ok() { "ok" } else { "FAILED" }
        );
        if outcome.is_err() {
            failed.push(case.name);
        }
    }
    eprintln!(
        "hard cases ({:.1} s in all):\n{report}",
        t_all.elapsed().as_secs_f64()
    );
    assert!(failed.is_empty(), "failed: {failed:?}");
}

// ---------------------------------------------------------------------------------------------
// Running methods, and the checks every case makes.

/// Small budgets: every case renders in a second or two in the test profile.
fn quick(method: Method) -> Overrides {
    let o = Overrides {
        method: Some(method),
        ..Overrides::default()
    };
    match method {
        Method::Path => o.spp(16),
        Method::GlobalDirect => Overrides {
            photons: Some(20_000),
            ..o.spp(4)
        },
        Method::FinalGather => Overrides {
            photons: Some(20_000),
            gather_rays: Some(8),
            ..o.spp(1)
        },
        Method::CausticSplat => Overrides {
            photons: Some(20_000),
            ..o.spp(4)
        },
        Method::PathSplat => Overrides {
            splat_photons: Some(20_000),
            ..o.spp(8)
        },
        Method::Sppm => Overrides {
            photons: Some(10_000),
            passes: Some(4),
            ..o
        },
        Method::Light => Overrides {
            photons: Some(20_000),
            passes: Some(2),
            ..o
        },
        Method::Vcm => Overrides {
            passes: Some(2),
            ..o
        },
    }
}

fn all(methods: &[Method]) -> Vec<Overrides> {
    methods.iter().map(|&m| quick(m)).collect()
}

trait Spp {
    fn spp(self, spp: u32) -> Overrides;
}

impl Spp for Overrides {
    fn spp(self, spp: u32) -> Overrides {
        Overrides {
            spp: Some(spp),
            ..self
        }
    }
}

fn method(o: &Overrides) -> Method {
    o.method.unwrap_or_else(|| panic!("a run names no method"))
}

/// Every pixel of every layer finite and non-negative, and some light made.
fn common_checks(o: &Overrides, r: &Rendered) {
    let m = method(o);
    for l in &r.layers {
        let bad: Vec<(usize, [f32; 3])> = bad_pixels(&l.image).into_iter().take(5).collect();
        assert!(bad.is_empty(), "{m}: layer {}: pixels {bad:?}", l.name);
    }
    // A mean in f64 of finite f32 pixels is finite: only the light needs checking.
    let total = mean(&image(r));
    assert!(total.max_element() > 0.0, "{m}: image mean {total}");
}

/// The image: the sum of every layer, in f64.
fn image(r: &Rendered) -> Vec<DVec3> {
    let mut img = vec![DVec3::ZERO; r.layers[0].image.data.len()];
    for l in &r.layers {
        for (s, p) in img.iter_mut().zip(&l.image.data) {
            *s += Vec3::from(*p).as_dvec3();
        }
    }
    img
}

fn mean(img: &[DVec3]) -> DVec3 {
    img.iter().sum::<DVec3>() / img.len() as f64
}

/// The run of `m` (the first one).
fn run_of<'a>(ctx: &Ctx<'a>, m: Method) -> &'a Rendered {
    let r = ctx.runs.iter().find(|(o, _)| method(o) == m);
    &r.unwrap_or_else(|| panic!("no {m} run")).1
}

/// Relative difference of two images' means, per channel.
fn rel_diff(a: &[DVec3], b: &[DVec3]) -> DVec3 {
    (mean(a) - mean(b)) / mean(b)
}

/// `a - b` pixel by pixel as a z score of its mean: the mean difference over its standard
/// error, the pixels' differences taken as independent (true of the path tracer, whose
/// pixels share no sample). The largest channel's |z|.
fn pixel_z(a: &[DVec3], b: &[DVec3]) -> f64 {
    let n = a.len() as f64;
    let d: Vec<DVec3> = a.iter().zip(b).map(|(x, y)| *x - *y).collect();
    let m = d.iter().sum::<DVec3>() / n;
    let var = d.iter().map(|x| (*x - m) * (*x - m)).sum::<DVec3>() / (n - 1.0);
    let se = (var / n).powf(0.5);
    (0..3)
        .map(|c| if m[c] == 0.0 { 0.0 } else { m[c] / se[c] })
        .fold(0.0f64, |a, z| a.max(z.abs()))
}

// ---------------------------------------------------------------------------------------------
// Scenes written into the case's directory.

/// An OBJ built face by face; each face its own object with its own material.
#[derive(Default)]
struct Obj {
    v: Vec<Vec3>,
    faces: Vec<(&'static str, [usize; 3])>,
}

impl Obj {
    fn vertex(&mut self, p: Vec3) -> usize {
        self.v.push(p);
        self.v.len()
    }

    /// A triangle as given (degenerate ones too).
    fn tri(&mut self, mat: &'static str, p: [Vec3; 3]) {
        let i = p.map(|p| self.vertex(p));
        self.faces.push((mat, i));
    }

    /// A convex quad (corners in order) whose geometric normal faces `out`.
    fn quad(&mut self, mat: &'static str, mut p: [Vec3; 4], out: Vec3) {
        if (p[1] - p[0]).cross(p[2] - p[0]).dot(out) < 0.0 {
            p.reverse();
        }
        self.tri(mat, [p[0], p[1], p[2]]);
        self.tri(mat, [p[0], p[2], p[3]]);
    }

    /// An axis-aligned square of half-size `h` at height `y` around `(x, z)`, facing `out`.
    fn square(&mut self, mat: &'static str, c: Vec3, h: f32, out: Vec3) {
        let p = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(a, b)| c + Vec3::new(a, 0.0, b));
        self.quad(mat, p, out);
    }

    /// An axis-aligned box, faces outwards.
    fn cube(&mut self, mat: &'static str, lo: Vec3, hi: Vec3) {
        let c = 0.5 * (lo + hi);
        for axis in 0..3 {
            for side in [lo[axis], hi[axis]] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let corner = |a: f32, b: f32| {
                    let mut p = Vec3::ZERO;
                    p[axis] = side;
                    p[u] = a;
                    p[v] = b;
                    p
                };
                let p = [
                    corner(lo[u], lo[v]),
                    corner(hi[u], lo[v]),
                    corner(hi[u], hi[v]),
                    corner(lo[u], hi[v]),
                ];
                let mut out = Vec3::ZERO;
                out[axis] = (side - c[axis]).signum();
                self.quad(mat, p, out);
            }
        }
    }

    /// Writes `name.obj` and `name.mtl` (every material grey: the scene file's replace them).
    fn write(&self, dir: &Path, name: &str) {
        let mut obj = format!("mtllib {name}.mtl\n");
        for p in &self.v {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        let mut mats: Vec<&str> = Vec::new();
        for (i, (m, f)) in self.faces.iter().enumerate() {
            let _ = writeln!(obj, "o f{i}\nusemtl {m}\nf {} {} {}", f[0], f[1], f[2]);
            if !mats.contains(m) {
                mats.push(m);
            }
        }
        let mtl: String = mats
            .iter()
            .map(|m| format!("newmtl {m}\nKd 0.5 0.5 0.5\n"))
            .collect();
        std::fs::write(dir.join(format!("{name}.obj")), obj).unwrap_or_else(|e| panic!("{e}"));
        std::fs::write(dir.join(format!("{name}.mtl")), mtl).unwrap_or_else(|e| panic!("{e}"));
    }
}

/// A scene file `name.toml` in `dir` over `name.obj`, with `body` after the mesh (spheres,
/// materials, `[photons]`, `[estimate]`).
fn scene_file(dir: &Path, name: &str, camera: &str, body: &str) -> Scene {
    try_scene_file(dir, name, camera, body).unwrap_or_else(|e| panic!("{e}"))
}

/// [`scene_file`], refusals returned.
fn try_scene_file(
    dir: &Path,
    name: &str,
    camera: &str,
    body: &str,
) -> Result<Scene, scene::SceneError> {
    let text = format!(
        "name = \"{name}\"\nseed = 3\n[camera]\n{camera}\n[[mesh]]\nobj = \"{name}.obj\"\n{body}"
    );
    Scene::from_toml(&dir.join(format!("{name}.toml")), &text)
}

const LAMP: &str = "type = \"lambertian\"\nalbedo = [0.0, 0.0, 0.0]\n";

/// The worksheet scene (`scenes/cornell-spheres/analytic.toml`) at `res` pixels square, with
/// its own seed (1), and every length multiplied by `s`: mesh scale, sphere centres and
/// radii, the camera, and every `[estimate]` length ([`estimate_lengths`]), then `edit`.
fn scaled_worksheet(res: u32, s: f32, edit: fn(&mut SceneFile)) -> Scene {
    worksheet_with(res, 1, |f| {
        f.camera.eye = f.camera.eye.map(|x| x * s);
        f.camera.look_at = f.camera.look_at.map(|x| x * s);
        for m in &mut f.meshes {
            // The file's scale is one number (the type is the loader's own: set it by value).
            let k = toml::Value::try_from(&m.scale).unwrap_or_else(|e| panic!("{e}"));
            let k = k.as_float().unwrap_or_else(|| panic!("mesh scale {k}"));
            m.scale = toml::Value::Float(k * s as f64)
                .try_into()
                .unwrap_or_else(|e| panic!("{e}"));
            m.translate = m.translate.map(|x| x * s);
        }
        for sp in &mut f.spheres {
            sp.center = sp.center.map(|x| x * s);
            sp.radius *= s;
        }
        f.estimate = estimate_lengths(s);
        edit(f);
    })
}

/// `[estimate]` with every length in scene units written out and multiplied by `s` (the
/// defaults of the others are lengths too, but automatic: `sppm.radius = 0` and
/// `splat.max_radius = 0` derive from the scene's size, `r_max` is infinite). `topo` is a
/// sine, `k` a count, neither scales. Unscaled values: the k-NN discs at 20 000 paths are
/// about 1 unit wide (global, k = 1000) and 0.2 (caustic, k = 250) on the 14-unit box.
fn estimate_lengths(s: f32) -> toml::Table {
    let text = format!(
        "[global]\nr_max = {}\n[caustic]\nr_max = {}\n[sppm]\nradius = {}\n\
         [splat]\nmax_radius = {}\nindirect_radius = {}\n",
        2.0 * s,
        0.5 * s,
        0.25 * s,
        0.28 * s,
        0.5 * s
    );
    toml::from_str(&text).unwrap_or_else(|e| panic!("{e}"))
}

// ---------------------------------------------------------------------------------------------
// Camera inside the glass sphere.

const GLASS_CENTRE: [f32; 3] = [-3.272, 2.29, -6.2395];
const GLASS_RADIUS: f32 = 2.25;

fn camera_in_glass(_: &Path) -> Scene {
    scaled_worksheet(24, 1.0, |f| {
        f.camera.eye = GLASS_CENTRE;
        // Towards the back wall and the silver sphere.
        f.camera.look_at = [-6.0, 2.29, -12.0];
        f.camera.vfov = 70.0;
    })
}

fn check_camera_in_glass(ctx: &Ctx) {
    let scene = ctx.scene;
    // The expected view: every camera ray leaves through the glass at normal incidence, the
    // sphere's radius away (f64 sphere roots: measured to 1.2e-7 relative).
    let glass = scene
        .material_of("glass")
        .unwrap_or_else(|| panic!("no glass"));
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut worst = 0.0f32;
    for y in 0..h {
        for x in 0..w {
            let ray = scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
            let hit = scene.geometry.intersect(&ray);
            let hit = hit.unwrap_or_else(|| panic!("pixel ({x}, {y}) escapes the sphere"));
            assert_eq!(hit.material, glass, "pixel ({x}, {y})");
            worst = worst.max((hit.t / GLASS_RADIUS - 1.0).abs());
            let cos = hit.point.n.dot(ray.d).abs();
            assert!(cos > 1.0 - 1e-5, "pixel ({x}, {y}): cos {cos}");
        }
    }
    eprintln!("camera in glass: every ray leaves at t = r (1 {worst:+.1e})");
    assert!(worst < 1e-5, "{worst}");
    // The methods agree on what the box looks like through the glass (global-direct and the
    // splat show only part of the light). Measured against the path tracer's image mean,
    // one run per seed over seeds 1 to 16, largest channel: sppm -0.6% ± 3.7% (mean ± sd of
    // one run), final gathering -1.1% ± 2.9%; each tolerance is the mean plus 4 sd.
    let path = image(run_of(ctx, Method::Path));
    for (m, tol) in [(Method::Sppm, 0.15), (Method::FinalGather, 0.12)] {
        let d = rel_diff(&image(run_of(ctx, m)), &path);
        eprintln!("camera in glass: {m} against path {d:+.3}");
        assert!(d.abs().max_element() < tol, "{m}: {d}");
    }
}

// ---------------------------------------------------------------------------------------------
// The light 0.0025 under the ceiling (the worksheet scene itself: 0.1 mm in the Cornell data,
// times the scale 0.025).

/// The worksheet scene seen from under the light, looking up at it and the ceiling round it.
fn light_under_ceiling(_: &Path) -> Scene {
    scaled_worksheet(24, 1.0, |f| {
        f.camera.eye = [-6.95, 4.0, -6.99];
        f.camera.look_at = [-6.95, 13.72, -6.99];
        f.camera.up = [0.0, 0.0, -1.0];
        f.camera.vfov = 60.0;
    })
}

fn check_light_under_ceiling(ctx: &Ctx) {
    let scene = ctx.scene;
    let mesh = scene.geometry.mesh();
    let light_y = mesh.vertices(scene.lights[0].triangle as usize)[0].y;
    let ceiling_y = (0..mesh.len())
        .map(|t| mesh.vertices(t))
        .filter(|v| v.iter().all(|p| p.y == v[0].y) && v[0].y > light_y)
        .map(|v| v[0].y)
        .fold(f32::INFINITY, f32::min);
    let gap = ceiling_y - light_y;
    assert!((gap - 0.0025).abs() < 1e-5, "gap {gap}");
    let le = scene.lights[0].le.as_dvec3();
    // What each pixel sees, sampled at its centre, corners and edge midpoints.
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let sees = |x: usize, y: usize, light: bool| {
        SUBPIXEL.iter().all(|(u, v)| {
            let ray = scene.camera.ray(x as f32 + u, y as f32 + v);
            scene.geometry.intersect(&ray).is_some_and(|hit| {
                let emits = scene.emission[hit.material as usize] != Vec3::ZERO;
                if light {
                    emits
                } else {
                    !emits && hit.point.n.y.abs() > 0.9 && hit.point.p.y > ceiling_y - 1e-3
                }
            })
        })
    };
    let lamp: Vec<usize> = (0..w * h).filter(|i| sees(i % w, i / w, true)).collect();
    let ceiling: Vec<usize> = (0..w * h).filter(|i| sees(i % w, i / w, false)).collect();
    assert!(
        lamp.len() >= 4 && ceiling.len() >= 20,
        "{lamp:?} {ceiling:?}"
    );
    // The light seen directly is its radiance, exactly (f64 sums of equal f32 values).
    for m in [Method::Path, Method::GlobalDirect, Method::FinalGather] {
        let e = dvec3s(layer(run_of(ctx, m), "emitted"));
        for &i in &lamp {
            assert_eq!(e[i], le, "{m}: pixel {i}");
        }
    }
    // The ceiling lies behind the light's emitting side: no direct light reaches it, so the
    // path tracer's direct layer is zero there, to the bit (a light leaking through the
    // 0.0025 gap or a shadow ray slipping past it would show here).
    let direct = dvec3s(layer(run_of(ctx, Method::Path), "direct"));
    let leak: Vec<(usize, DVec3)> = ceiling
        .iter()
        .filter(|&&i| direct[i] != DVec3::ZERO)
        .map(|&i| (i, direct[i]))
        .collect();
    assert!(leak.is_empty(), "direct light on the ceiling: {leak:?}");
    // And the ceiling is lit indirectly, alike by every method. Measured against the path
    // tracer over the ceiling's pixels, one run per seed over seeds 1 to 16, worst channel
    // (mean ± sd of one run): global-direct -4.5% ± 3.6%, final gathering -11.5% ± 3.7%
    // (its smoothing reads the ceiling round the light low), sppm +1.1% ± 3.7%; each
    // tolerance is the mean's size plus 4 sd.
    let ceiling_mean = |img: &[DVec3]| ceiling.iter().map(|&i| img[i]).sum::<DVec3>();
    let path = ceiling_mean(&image(run_of(ctx, Method::Path)));
    assert!(path.min_element() > 0.0, "{path}");
    for (m, tol) in [
        (Method::GlobalDirect, 0.19),
        (Method::FinalGather, 0.27),
        (Method::Sppm, 0.16),
    ] {
        let d = (ceiling_mean(&image(run_of(ctx, m))) - path) / path;
        eprintln!("light under the ceiling: ceiling {m} against path {d:+.3}");
        assert!(d.abs().max_element() < tol, "{m}: {d}");
    }
}

/// Points of a pixel (pixel units from its top-left corner): centre, corners, edge midpoints.
const SUBPIXEL: [(f32, f32); 9] = [
    (0.5, 0.5),
    (0.01, 0.01),
    (0.99, 0.01),
    (0.01, 0.99),
    (0.99, 0.99),
    (0.5, 0.01),
    (0.5, 0.99),
    (0.01, 0.5),
    (0.99, 0.5),
];

// ---------------------------------------------------------------------------------------------
// Grazing camera rays: a floor seen from 0.02 above it, 10 units from a small light.

const GRAZE_LE: f32 = 50.0;
const GRAZE_RHO: f64 = 0.5;
const GRAZE_LIGHT: [f32; 3] = [0.0, 2.0, 0.0];

fn grazing(dir: &Path) -> Scene {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, 10.0, Vec3::Y);
    obj.square("lamp", Vec3::from(GRAZE_LIGHT), 0.25, -Vec3::Y);
    obj.write(dir, "grazing");
    let camera = "eye = [0.0, 0.02, 9.5]\nlook_at = [0.0, 0.0, -10.0]\nvfov = 8.0\n\
                  width = 32\nheight = 32";
    let body = format!(
        "[material.floor]\ntype = \"lambertian\"\nalbedo = [{GRAZE_RHO}, {GRAZE_RHO}, \
         {GRAZE_RHO}]\n[material.lamp]\n{LAMP}emission = [{GRAZE_LE}, {GRAZE_LE}, {GRAZE_LE}]\n"
    );
    scene_file(dir, "grazing", camera, &body)
}

/// Where the ray through film point `(x, y)` meets the plane y = 0, in f64 (`None` if it
/// rises or lands outside `half`).
fn on_floor(scene: &Scene, x: f32, y: f32, half: f64) -> Option<DVec3> {
    let ray = scene.camera.ray(x, y);
    let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
    if d.y >= 0.0 {
        return None;
    }
    let p = o - d * (o.y / d.y);
    (p.x.abs() < half && p.z.abs() < half).then_some(p)
}

fn check_grazing(ctx: &Ctx) {
    let scene = ctx.scene;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let c = Vec3::from(GRAZE_LIGHT).as_dvec3();
    let poly: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|(a, b)| c + 0.25 * DVec3::new(*a, 0.0, *b))
        .collect();
    // The floor's radiance from the light alone, averaged over a pixel on a 16 x 16 grid of
    // film points (the path tracer's samples are uniform over the pixel): a 6 x 6 grid read
    // the far pixels' integral 0.05% low, which the z score below resolved (z = 2 on
    // average over seeds). Pixels whose corners all land on the floor only.
    let expected = |x: usize, y: usize| -> Option<DVec3> {
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            on_floor(scene, x as f32 + u, y as f32 + v, 9.9)?;
        }
        let n = 16;
        let mut sum = 0.0;
        for j in 0..n {
            for i in 0..n {
                let (u, v) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let p = on_floor(scene, x as f32 + u, y as f32 + v, 10.0)?;
                let e = math::analytic::polygon_irradiance(p, DVec3::Y, &poly, GRAZE_LE as f64);
                sum += GRAZE_RHO / std::f64::consts::PI * e;
            }
        }
        Some(DVec3::splat(sum / (n * n) as f64))
    };
    let pixels: Vec<(usize, DVec3)> = (0..w * h)
        .filter_map(|i| expected(i % w, i / w).map(|e| (i, e)))
        .collect();
    assert!(pixels.len() >= 200, "{} floor pixels", pixels.len());
    // How grazing: the camera rays' angle above the floor over those pixels.
    let angle = |i: usize| {
        let ray = scene.camera.ray((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
        (-ray.d.y).asin().to_degrees()
    };
    let (lo, hi) = pixels
        .iter()
        .map(|&(i, _)| angle(i))
        .fold((f32::INFINITY, 0.0f32), |(a, b), x| (a.min(x), b.max(x)));
    let path = dvec3s(layer(run_of(ctx, Method::Path), "direct"));
    let got: Vec<DVec3> = pixels.iter().map(|&(i, _)| path[i]).collect();
    let want: Vec<DVec3> = pixels.iter().map(|&(_, e)| e).collect();
    let z = pixel_z(&got, &want);
    let d = rel_diff(&got, &want);
    eprintln!(
        "grazing: {} floor pixels seen at {lo:.3} to {hi:.3} degrees; path direct against \
         Lambert's formula {d:+.4} (z = {z:.2})",
        pixels.len()
    );
    // The pixels' errors are independent: a z score. Measured: +0.01%, z = 0.47; over seeds
    // 1 to 16 (one run each) |z| at most 2.5 and |d| at most 0.06%.
    assert!(z < 4.0, "path: z = {z}, {d}");
    // The photon methods see the same floor (direct and indirect; the lamp is black, so the
    // indirect light is nil) with their smoothing. Measured: global-direct +5.7%, final
    // gathering -0.9%, sppm +0.7%; over seeds 1 to 16 (mean ± sd of one run) +3.6% ± 13%
    // (few photons reach the far floor, and its k-NN discs are wide: -13% to +42%), +0.6% ±
    // 1.0%, +0.2% ± 0.3%. Each tolerance is the mean's size plus 4 sd.
    let ds: Vec<(Method, f64, DVec3)> = [
        (Method::GlobalDirect, 0.6),
        (Method::FinalGather, 0.05),
        (Method::Sppm, 0.015),
    ]
    .into_iter()
    .map(|(m, tol)| {
        let img = image(run_of(ctx, m));
        let got: Vec<DVec3> = pixels.iter().map(|&(i, _)| img[i]).collect();
        let d = rel_diff(&got, &want);
        eprintln!("grazing: {m} against Lambert's formula {d:+.4}");
        (m, tol, d)
    })
    .collect();
    for (m, tol, d) in ds {
        assert!(d.abs().max_element() < tol, "{m}: {d}");
    }
}

// ---------------------------------------------------------------------------------------------
// Total internal reflection chains: a light inside a glass cube above a floor.

/// The cube spans [-1, 1] x [0.5, 2.5] x [-1, 1]; the lamp, facing down, sits at its centre.
const CUBE_LO: [f32; 3] = [-1.0, 0.5, -1.0];
const CUBE_HI: [f32; 3] = [1.0, 2.5, 1.0];
const TIR_LAMP_Y: f32 = 1.5;
const TIR_LAMP_HALF: f32 = 0.1;
const TIR_FLOOR_HALF: f32 = 20.0;
const TIR_IOR: f64 = 1.5;
const TIR_PATHS: u64 = 200_000;
const TIR_REFERENCE_PATHS: u64 = 1_000_000;

fn tir_cube(dir: &Path) -> Scene {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, TIR_FLOOR_HALF, Vec3::Y);
    obj.cube("glass", Vec3::from(CUBE_LO), Vec3::from(CUBE_HI));
    obj.square(
        "lamp",
        Vec3::new(0.0, TIR_LAMP_Y, 0.0),
        TIR_LAMP_HALF,
        -Vec3::Y,
    );
    obj.write(dir, "tir");
    let camera = "eye = [3.0, 4.0, 6.0]\nlook_at = [0.0, 1.0, 0.0]\nvfov = 50.0\n\
                  width = 24\nheight = 24";
    let body = format!(
        "[material.floor]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [material.glass]\ntype = \"dielectric\"\nior = {TIR_IOR}\n\
         [material.lamp]\n{LAMP}emission = [10.0, 10.0, 10.0]\n"
    );
    scene_file(dir, "tir", camera, &body)
}

/// Unpolarised Fresnel reflectance of a dielectric interface (Hecht; pbrt-v4 §9.5.1), `eta`
/// the ratio of the transmitted side's index to the incident side's, `cos_i` > 0.
fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The share of the lamp's photon paths whose first diffuse hit is the floor within
/// `max_depth` surface hits, by an independent f64 simulation of the cube (its own random
/// numbers): cosine emission downwards from a uniform point of the lamp, Fresnel reflection
/// or refraction chosen by reflectance at every face, absorption by the lamp (a black
/// two-sided square).
fn tir_reference(paths: u64, max_depth: u32) -> f64 {
    let mut rng = math::Rng::for_index(0x7152, 0);
    let (lo, hi) = (
        Vec3::from(CUBE_LO).as_dvec3(),
        Vec3::from(CUBE_HI).as_dvec3(),
    );
    let (ly, lh) = (TIR_LAMP_Y as f64, TIR_LAMP_HALF as f64);
    let mut floor = 0u64;
    for _ in 0..paths {
        let [a, b] = rng.uniform2().map(|u| (2.0 * u as f64 - 1.0) * lh);
        let mut p = DVec3::new(a, ly, b);
        let [u1, u2] = rng.uniform2().map(f64::from);
        let (r, phi) = (u1.sqrt(), 2.0 * std::f64::consts::PI * u2);
        let mut d = DVec3::new(r * phi.cos(), -(1.0 - u1).sqrt(), r * phi.sin());
        // Hits so far: each face, the lamp and the floor count one, as in the photon tracer.
        for hit in 1..=max_depth {
            // Inside the cube: the nearest face, unless the lamp's plane comes first.
            let (t, axis) = (0..3)
                .map(|k| {
                    let bound = if d[k] > 0.0 { hi[k] } else { lo[k] };
                    ((bound - p[k]) / d[k], k)
                })
                .fold((f64::INFINITY, 0), |m, x| if x.0 < m.0 { x } else { m });
            let t_lamp = (ly - p.y) / d.y;
            if t_lamp > 1e-9 && t_lamp < t {
                let q = p + t_lamp * d;
                if q.x.abs() <= lh && q.z.abs() <= lh {
                    break; // absorbed by the lamp
                }
            }
            p += t * d;
            let cos_i = d[axis].abs();
            if (rng.uniform() as f64) < fresnel(cos_i, 1.0 / TIR_IOR) {
                d[axis] = -d[axis];
                continue;
            }
            // Out: Snell's law, the tangential part scaled by eta_i / eta_t.
            let mut out = d * TIR_IOR;
            let tangential2 = out.length_squared() - out[axis] * out[axis];
            out[axis] = d[axis].signum() * (1.0 - tangential2).sqrt();
            if out.y < 0.0 && hit < max_depth {
                let q = p - out * (p.y / out.y);
                if q.x.abs() < TIR_FLOOR_HALF as f64 && q.z.abs() < TIR_FLOOR_HALF as f64 {
                    floor += 1;
                }
            }
            break;
        }
    }
    floor as f64 / paths as f64
}

fn check_tir(ctx: &Ctx) {
    let scene = ctx.scene;
    let params = emit::EmitParams {
        photons: TIR_PATHS,
        ..emit::EmitParams::default()
    };
    let ps = emit::trace_caustics(scene, &params, 1.0, 0, 0..TIR_PATHS, false);
    let power = scene.light_power().as_dvec3();
    let landed: Vec<&emit::CausticPhoton> =
        ps.iter().filter(|p| p.position.y.abs() < 1e-4).collect();
    let flux: DVec3 = landed.iter().map(|p| p.flux.as_dvec3()).sum();
    assert!(
        ps.iter()
            .all(|p| p.flux.is_finite() && p.position.is_finite()),
        "a caustic photon is not finite"
    );
    let share = flux / power;
    let reference = tir_reference(TIR_REFERENCE_PATHS, params.max_depth);
    // Binomial standard errors of both shares.
    let se = (reference
        * (1.0 - reference)
        * (1.0 / TIR_PATHS as f64 + 1.0 / TIR_REFERENCE_PATHS as f64))
        .sqrt();
    let z = (share.x - reference) / se;
    eprintln!(
        "TIR: {} of {TIR_PATHS} paths reach the floor: {:.4} of the light's flux, f64 \
         simulation {reference:.4} ± {se:.4} (z = {z:.2})",
        landed.len(),
        share.x
    );
    // Measured: 0.6778 against 0.6783 ± 0.0011, z = -0.39; over seeds 1 to 16, z = +0.2 ±
    // 1.2 (mean ± sd), |z| at most 2.5. With the caustic tracer cut at 4 surface hits
    // instead of 64 (tried), 0.6666 and z = -10.3; at 16, z = -0.9. Without a cap on surface
    // hits the trapped paths (every direction component below the cosine of the critical
    // angle, 0.745) would never end.
    assert!(z.abs() < 4.0, "z = {z}");
    assert!((share - share.x).abs().max_element() < 1e-6, "{share}");
}

// ---------------------------------------------------------------------------------------------
// Caustic focus: a glass ball focusing a small light onto the floor, seen from low in front.

const FOCUS_PHOTONS: u64 = 100_000;
const FOCUS_RHO: f64 = 0.5;

fn focus(dir: &Path) -> Scene {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, 6.0, Vec3::Y);
    obj.square("lamp", Vec3::new(0.0, 11.765, 0.0), 0.15, -Vec3::Y);
    obj.write(dir, "focus");
    // The ball's focus for the light 10 units above its centre lies on the floor: the thick
    // lens' distance from the centre, 1/(1/f - 1/10) with f = n R / (2 (n - 1)) = 1.5,
    // is 1.765.
    let camera = "eye = [0.0, 1.0, 6.0]\nlook_at = [0.0, 0.0, -0.3]\nvfov = 30.0\n\
                  width = 32\nheight = 32";
    let body = format!(
        "[[sphere]]\ncenter = [0.0, 1.765, 0.0]\nradius = 1.0\nmaterial = \"glass\"\n\
         [material.floor]\ntype = \"lambertian\"\nalbedo = [{FOCUS_RHO}, {FOCUS_RHO}, \
         {FOCUS_RHO}]\n[material.glass]\ntype = \"dielectric\"\nior = 1.5\n\
         [material.lamp]\n{LAMP}emission = [100.0, 100.0, 100.0]\n"
    );
    scene_file(dir, "focus", camera, &body)
}

fn check_focus(ctx: &Ctx) {
    let scene = ctx.scene;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let floor = scene
        .material_of("floor")
        .unwrap_or_else(|| panic!("no floor"));
    // The pixels that see only floor (not the ball, not the floor through the ball).
    let clean = |x: usize, y: usize| {
        SUBPIXEL.iter().all(|(u, v)| {
            let ray = scene.camera.ray(x as f32 + u, y as f32 + v);
            scene
                .geometry
                .intersect(&ray)
                .is_some_and(|hit| hit.material == floor)
        })
    };
    let pixels: Vec<(usize, f64)> = (0..w * h)
        .filter(|&i| clean(i % w, i / w))
        .filter_map(|i| pixel_floor_area(scene, i % w, i / w).map(|a| (i, a)))
        .collect();
    let is_clean = {
        let mut v = vec![false; w * h];
        for &(i, _) in &pixels {
            v[i] = true;
        }
        v
    };
    // The photons the splat used (pass 0, the photon tracer's streams), and how focused their
    // footprints are: the principal semi-axes of [a b] in the floor's plane.
    let params = emit::EmitParams {
        photons: FOCUS_PHOTONS,
        ..emit::EmitParams::default()
    };
    let ps = emit::trace_caustics(scene, &params, 1.0, 0, 0..FOCUS_PHOTONS, false);
    let minor = |p: &emit::CausticPhoton| footprint_axes(p).1;
    let focused = ps.iter().filter(|p| minor(p) < 1e-3).count();
    let smallest = ps.iter().map(minor).fold(f32::INFINITY, f32::min);
    // The caustic flux landing in the clean pixels, by projecting each photon.
    let seen = |p: &emit::CausticPhoton| {
        p.position.y.abs() < 1e-4
            && project(scene, p.position).is_some_and(|(x, y)| {
                let (x, y) = (x.floor() as usize, y.floor() as usize);
                x < w && y < h && is_clean[y * w + x]
            })
    };
    let photon_flux: f64 = ps.iter().filter(|p| seen(p)).map(|p| p.flux.x as f64).sum();
    let all_flux: f64 = ps.iter().map(|p| p.flux.x as f64).sum();
    // What the splatted caustic layer integrates to over the same pixels: L = rho/pi E.
    let caustic = dvec3s(layer(run_of(ctx, Method::CausticSplat), "caustic"));
    let image_flux: f64 = pixels.iter().map(|&(i, a)| caustic[i].x * a).sum::<f64>()
        * std::f64::consts::PI
        / FOCUS_RHO;
    let rel = image_flux / photon_flux - 1.0;
    eprintln!(
        "caustic focus: {} photons, {focused} with a footprint narrower than 1e-3 (smallest \
         {smallest:.1e}); {} clean floor pixels hold {photon_flux:.4} of {all_flux:.4} W; the \
         splatted layer integrates to {image_flux:.4} ({rel:+.4})",
        ps.len(),
        pixels.len()
    );
    // Measured: 61 of 854 below 1e-3, the smallest 1.1e-4; over seeds 1 to 16, 53 to 92, the
    // smallest 1.0e-4 to 1.3e-4 (the lamp is 0.3 wide, so no footprint shrinks to exactly
    // zero; the clamps take over below the eye's spacing).
    assert!(focused > 30, "the light is not focused: {focused}");
    assert!(photon_flux > 0.5 * all_flux, "{photon_flux} of {all_flux}");
    // Measured: +2.5%; over seeds 1 to 16, -2.6% ± 4.6% (mean ± sd of one run, -9.9% to
    // +6.5%: the eye vertices' sampling of the focus, 16 per pixel, and splats crossing the
    // ball's silhouette), so the tolerance is the mean's size plus 4 sd. Before each spacing
    // level of eye vertices read the photons through its own footprint
    // (`density::splat::Receivers`), -24%: a focused photon's footprint was clamped to the
    // spacing of its nearest vertex, often one seen through the ball, and fell between the
    // directly seen floor's vertices (16 passes: -20%, so a bias, not noise). At this
    // budget the check only just tells that apart from noise.
    assert!(rel.abs() < 0.22, "{rel}");
}

// ---------------------------------------------------------------------------------------------
// Film and floor geometry shared by the checks.

/// Pixel coordinates (film units) of a world point in front of the camera.
fn project(scene: &Scene, p: Vec3) -> Option<(f32, f32)> {
    let c = &scene.camera;
    let forward = (c.look_at - c.eye).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let half_h = (0.5 * c.vfov_deg.to_radians()).tan();
    let half_w = half_h * c.width as f32 / c.height as f32;
    let v = p - c.eye;
    let z = v.dot(forward);
    if z <= 0.0 {
        return None;
    }
    let (sx, sy) = (v.dot(right) / z / half_w, v.dot(up) / z / half_h);
    Some((
        (sx + 1.0) * 0.5 * c.width as f32,
        (1.0 - sy) * 0.5 * c.height as f32,
    ))
}

/// The floor area (y = 0) a pixel covers: the quadrilateral of its corners' rays.
fn pixel_floor_area(scene: &Scene, x: usize, y: usize) -> Option<f64> {
    let c = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .map(|(u, v)| on_floor(scene, x as f32 + u, y as f32 + v, 1e9));
    let [a, b, cc, d] = [c[0]?, c[1]?, c[2]?, c[3]?];
    Some(0.5 * (cc - a).cross(d - b).length())
}

// ---------------------------------------------------------------------------------------------
// 1 000 photons at one point (a photon file written into the cache), and k larger than the
// photon count.

const POINT_PHOTONS: u64 = 1000;
/// Each photon's flux (already over the paths emitted): 1 W in all per channel.
const POINT_FLUX: f32 = 1.0 / POINT_PHOTONS as f32;
const POINT_R_MAX: f32 = 0.5;
const POINT_RHO: f64 = 0.5;

/// A floor seen from straight above, a light out of view, and a global photon file in the
/// case's cache holding 1 000 photons at the origin.
fn point_photons(dir: &Path) -> Scene {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, 2.0, Vec3::Y);
    obj.square("lamp", Vec3::new(0.0, 3.5, 0.0), 0.1, -Vec3::Y);
    obj.write(dir, "point");
    let camera = "eye = [0.0, 3.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
                  vfov = 30.0\nwidth = 32\nheight = 32";
    let body = format!(
        "[material.floor]\ntype = \"lambertian\"\nalbedo = [{POINT_RHO}, {POINT_RHO}, \
         {POINT_RHO}]\n[material.lamp]\n{LAMP}emission = [1.0, 1.0, 1.0]\n\
         [photons]\nphotons = {POINT_PHOTONS}\n[estimate.global]\nr_max = {POINT_R_MAX}\n"
    );
    let scene = scene_file(dir, "point", camera, &body);
    let settings = Settings::new(&scene, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
    let key = photons::CacheKey::new(&scene, &settings.emit);
    let cache = dir.join("cache");
    std::fs::create_dir_all(&cache).unwrap_or_else(|e| panic!("{e}"));
    let mut w = store::StoreWriter::create(
        &key.file(&cache, MapKind::Global),
        key.header(&scene, MapKind::Global),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let photon = store::Photon::new(Vec3::ZERO, Vec3::splat(POINT_FLUX), -Vec3::Y, 0);
    w.write(&vec![photon; POINT_PHOTONS as usize])
        .unwrap_or_else(|e| panic!("{e}"));
    w.finish(POINT_PHOTONS).unwrap_or_else(|e| panic!("{e}"));
    scene
}

fn gd_on_point() -> Overrides {
    Overrides {
        method: Some(Method::GlobalDirect),
        spp: Some(16),
        ..Overrides::default()
    }
}

/// Each pixel's footprint on the floor: the nearest and farthest distance of its corners and
/// edge points from the origin (nearest 0 if the pixel holds the origin), and its area.
fn footprints(scene: &Scene) -> Vec<(f64, f64, f64)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let origin = project(scene, Vec3::ZERO).unwrap_or_else(|| panic!("origin out of view"));
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let ds: Vec<f64> = SUBPIXEL
                .iter()
                .map(|(u, v)| {
                    on_floor(scene, x as f32 + u, y as f32 + v, 1e9)
                        .map_or(f64::INFINITY, |p| p.length())
                })
                .collect();
            let holds = origin.0.floor() as usize == x && origin.1.floor() as usize == y;
            let near = if holds {
                0.0
            } else {
                ds.iter().copied().fold(f64::INFINITY, f64::min)
            };
            let far = ds.iter().copied().fold(0.0, f64::max);
            let area = pixel_floor_area(scene, x, y).unwrap_or(f64::NAN);
            (near, far, area)
        })
        .collect()
}

fn check_point_photons(ctx: &Ctx) {
    let fp = footprints(ctx.scene);
    // k = 50 of 1 000 coincident photons: at distance d the 50 nearest all lie at d, so the
    // radius is d and all 50 sit on the kernel's edge: E = 50 phi / (pi d^2), L = rho/pi E.
    // At the point itself r = 0 and the density is undefined: the estimate gives zero, not
    // infinity. A pixel reads the mean of E over its footprint, so it lies between the
    // values at its farthest and nearest points; past r_max every pixel is black.
    for (run, k) in [(0, 50.0), (1, POINT_PHOTONS as f64)] {
        let (o, r) = &ctx.runs[run];
        assert_eq!(o.k, Some(k as usize));
        let img = dvec3s(layer(r, "global"));
        let l = |d: f64| {
            POINT_RHO / std::f64::consts::PI * k * POINT_FLUX as f64
                / (std::f64::consts::PI * d * d)
        };
        let (mut inside, mut centre) = (0, DVec3::ZERO);
        for (i, &(near, far, _)) in fp.iter().enumerate() {
            let v = img[i];
            if near == 0.0 {
                centre = v;
                continue;
            }
            if near > POINT_R_MAX as f64 {
                assert_eq!(v, DVec3::ZERO, "k = {k}: pixel {i} at {near:.3}");
            } else if far < POINT_R_MAX as f64 {
                inside += 1;
                let (lo, hi) = (l(far) * (1.0 - 1e-5), l(near) * (1.0 + 1e-5));
                assert!(
                    v.min_element() >= lo && v.max_element() <= hi,
                    "k = {k}: pixel {i} reads {v}, not in [{lo}, {hi}] ({near:.4} to {far:.4})"
                );
            }
        }
        eprintln!(
            "1000 photons at one point, k = {k}: {inside} pixels within the closed-form \
             bounds, the pixel holding the point reads {centre:.1}"
        );
        // The pixel holding the point is finite like every pixel (`common_checks`).
        assert!(inside >= 20, "{inside}");
    }
    // The estimate itself at and next to the point, where no eye sample lands: read from the
    // photon file as the method reads it. At the point r = 0 (zero, by the estimate's
    // contract), at 1e-20 the radius squared is a subnormal f32 (1e-40) and E = 1.6e38 is
    // finite, at 1e-23 it underflows to 0 (zero again), at 0.1 it is the closed form.
    let (o, _) = &ctx.runs[0];
    let settings = Settings::new(ctx.scene, o).unwrap_or_else(|e| panic!("{e}"));
    let key = photons::CacheKey::new(ctx.scene, &settings.emit);
    let maps = render::maps::load(&ctx.dir.join("cache"), &key, &[MapKind::Global]);
    let maps = maps.unwrap_or_else(|e| panic!("{e}"));
    let map = maps[MapKind::Global]
        .as_ref()
        .unwrap_or_else(|| panic!("no global map"));
    let p = settings.estimate.global;
    let mut scratch = Vec::new();
    let e = |x: f32, scratch: &mut Vec<density::Neighbor>| {
        map.irradiance(Vec3::new(x, 0.0, 0.0), Vec3::Y, &p, scratch)
    };
    let closed = |x: f64| 50.0 * POINT_FLUX as f64 / (std::f64::consts::PI * x * x);
    let (e0, e20, e23, e1) = (
        e(0.0, &mut scratch),
        e(1e-20, &mut scratch),
        e(1e-23, &mut scratch),
        e(0.1, &mut scratch),
    );
    eprintln!(
        "1000 photons at one point, k = 50: E at 0 {e0}, at 1e-20 {e20}, at 1e-23 {e23}, at 0.1 \
         {e1} (closed form {:.4})",
        closed(0.1)
    );
    // With the estimate's r = 0 guard loosened to r >= 0 (tried), the point reads f32::MAX.
    assert_eq!(e0, Vec3::ZERO, "at the point");
    assert_eq!(e23, Vec3::ZERO, "at 1e-23");
    assert!(e20.is_finite() && e20.min_element() > 1e38, "{e20}");
    assert!(((e1.x as f64) / closed(0.1) - 1.0).abs() < 1e-5, "{e1}");
}

fn check_k_above_count(ctx: &Ctx) {
    let fp = footprints(ctx.scene);
    // k = 2 000 > 1 000 photons with r_max = 0.5: the radius is r_max wherever the disc
    // holds the point, so E = Phi / (pi r_max^2) inside the disc and zero outside: a fixed
    // kernel, whose integral over the floor is the photons' flux (1 W per channel).
    let img = dvec3s(layer(&ctx.runs[0].1, "global"));
    let r = POINT_R_MAX as f64;
    let l_in = POINT_RHO / std::f64::consts::PI * 1.0 / (std::f64::consts::PI * r * r);
    let (mut inside, mut flux) = (0, 0.0);
    for (i, &(near, far, area)) in fp.iter().enumerate() {
        let v = img[i];
        if far < r {
            inside += 1;
            assert!(
                (v / l_in - 1.0).abs().max_element() < 1e-5,
                "pixel {i}: {v} against {l_in}"
            );
        } else if near > r {
            assert_eq!(v, DVec3::ZERO, "pixel {i}");
        }
        flux += v.x * area;
    }
    let flux = flux * std::f64::consts::PI / POINT_RHO;
    eprintln!(
        "k above the photon count: {inside} pixels read Phi / (pi r_max^2) exactly; the image \
         integrates to {flux:.5} W of 1"
    );
    // The disc's edge pixels are sampled by 16 eye samples each: measured 1.0017; over seeds
    // 1 to 16, 1.0013 ± 0.0027 (mean ± sd of one run): the mean's size plus 5 sd.
    assert!((flux - 1.0).abs() < 0.015, "{flux}");
    assert!(inside >= 20, "{inside}");
    // Final gathering reads the same estimate at its gather rays' hits (the common checks:
    // finite, non-negative, some light).
}

// ---------------------------------------------------------------------------------------------
// The worksheet scene scaled by 1e-3 and 1e4, and with spheres of radius 1e-4: the same
// image as the unscaled scene, whose runs the cases share.

const WS_RES: u32 = 24;

fn worksheet_runs() -> Vec<Overrides> {
    all(&[
        Method::Path,
        Method::FinalGather,
        Method::CausticSplat,
        Method::Sppm,
        Method::Vcm,
    ])
}

struct Shared {
    root: PathBuf,
    /// The unscaled worksheet's runs ([`worksheet_runs`]), made by the first case that asks.
    reference: OnceCell<Vec<(Overrides, Rendered)>>,
}

fn reference<'a>(ctx: &Ctx<'a>) -> &'a [(Overrides, Rendered)] {
    ctx.shared.reference.get_or_init(|| {
        let scene = scaled_worksheet(WS_RES, 1.0, |_| {});
        let cache = ctx.shared.root.join("reference-cache");
        worksheet_runs()
            .into_iter()
            .map(|o| {
                let r = render(&scene, &o, &cache, None);
                (o, r)
            })
            .collect()
    })
}

/// Each run's image against the unscaled scene's, with the tolerances measured for `what`.
fn against_reference(ctx: &Ctx, what: &str, tol: &[(Method, f64)]) {
    let reference = reference(ctx);
    for ((o, r), (o_ref, r_ref)) in ctx.runs.iter().zip(reference) {
        let m = method(o);
        assert_eq!(m, method(o_ref));
        let (a, b) = (image(r), image(r_ref));
        let d = rel_diff(&a, &b);
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        eprintln!(
            "{what}: {m}: image mean {d:+.6} against the unscaled scene's, {same} of {} pixels \
             identical",
            a.len()
        );
        let t = tol.iter().find(|(mm, _)| *mm == m).map_or(0.0, |t| t.1);
        assert!(d.abs().max_element() <= t, "{m}: {d} (tolerance {t})");
    }
}

fn check_scaled(ctx: &Ctx) {
    let s = ctx.scene.camera.eye.x / -6.95;
    // The same seed draws the same random numbers: the scaled scene repeats the unscaled
    // one's paths until rounding sends one elsewhere (most pixels then differ in their last
    // bits, a few by a path). Any length left unscaled (an absolute epsilon, a radius in
    // scene units) would show as a bias far above that. Measured, largest channel: at 1e-3
    // path 1e-6, final gathering 1.6e-4, caustic-splat 2.4e-4, sppm 5.1e-4; at 1e4 1e-6,
    // 2.6e-4, 5.6e-4, 2.9e-4. Over seeds 1 to 16 the largest is 1.5e-3 (caustic-splat at
    // 1e-3), and the tolerance is about 4 sd of caustic-splat's spread (5e-4) over those
    // seeds. One run's image mean varies between seeds (1 to 8) by 3.7% (path), 25% (final
    // gathering), 9.1% (caustic-splat) and 9.9% (sppm): the tolerance is a small fraction of
    // any method's noise. With the sppm radius left unscaled (tried), sppm reads -34% at
    // 1e4 (at 1e-3 the settings refuse a radius that large).
    let t = 2e-3;
    against_reference(
        ctx,
        &format!("scaled by {s:.0e}"),
        &[
            (Method::Path, t),
            (Method::FinalGather, t),
            (Method::CausticSplat, t),
            (Method::Sppm, t),
            (Method::Vcm, t),
        ],
    );
}

/// Centre of the glass sphere of radius 1e-4.
const TINY_CENTRE: [f32; 3] = [-6.95, 6.86, -6.99];

/// A glass and a silver sphere of radius 1e-4: one in the middle of the room on the camera's
/// axis, one resting on the floor.
fn add_tiny_spheres(f: &mut SceneFile) {
    for (c, m) in [(TINY_CENTRE, "glass"), ([-7.5, 1e-4, -4.0], "silver")] {
        f.spheres.push(scene::SphereDesc {
            center: c,
            radius: 1e-4,
            material: m.into(),
        });
    }
}

fn check_tiny_sphere(ctx: &Ctx) {
    let scene = ctx.scene;
    // The sphere is there and hit where it should be: a ray from the eye at its centre.
    let c = Vec3::new(-6.95, 6.86, -6.99);
    let eye = scene.camera.eye;
    let ray = geom::Ray::new(eye, (c - eye).normalize());
    let hit = scene.geometry.intersect(&ray);
    let hit = hit.unwrap_or_else(|| panic!("the tiny sphere is missed"));
    let t = (c - eye).length() - 1e-4;
    assert!(
        matches!(hit.prim, geom::Prim::Sphere(2)) && (hit.t - t).abs() < 1e-5,
        "{:?} at {} (expected {t})",
        hit.prim,
        hit.t
    );
    // Measured: every method's image identical to the bit (no camera ray, photon or eye
    // vertex at these budgets meets a sphere of cross-section 3e-8); the tolerance is the
    // scaled cases' (a path that does meet it changes a pixel, not the image).
    let t = 2e-3;
    against_reference(
        ctx,
        "spheres of radius 1e-4",
        &[
            (Method::Path, t),
            (Method::FinalGather, t),
            (Method::CausticSplat, t),
            (Method::Sppm, t),
        ],
    );
}

/// The glass sphere of radius 1e-4 seen from 4e-4 away, filling the middle of the view: a
/// ball lens 1e-4 across at coordinates near 7, where an f32 ulp is 5e-7.
fn check_tiny_sphere_close(ctx: &Ctx) {
    let scene = ctx.scene;
    let c = Vec3::from(TINY_CENTRE).as_dvec3();
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    // The pixels whose 9 points all see the ball, and how exactly their rays hit it: against
    // the ray-sphere root in f64 from the f32 ray (measured: 3.2e-6 relative, a few ulps of
    // the eye's coordinates over a distance of 3e-4).
    let mut ball = Vec::new();
    let mut worst = 0.0f64;
    for i in 0..w * h {
        let hits = SUBPIXEL.iter().all(|(u, v)| {
            let ray = scene.camera.ray((i % w) as f32 + u, (i / w) as f32 + v);
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return false;
            };
            let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
            let oc = o - c;
            let b = oc.dot(d);
            let disc = b * b - (oc.length_squared() - 1e-8);
            if disc < 0.0 {
                return false;
            }
            let t = -b - disc.sqrt();
            worst = worst.max((hit.t as f64 - t).abs() / t);
            matches!(hit.prim, geom::Prim::Sphere(2))
        });
        if hits {
            ball.push(i);
        }
    }
    eprintln!(
        "sphere of radius 1e-4 up close: {} pixels see only the ball, hit distances within \
         {worst:.1e} of the f64 root",
        ball.len()
    );
    assert!(ball.len() >= 100, "{}", ball.len());
    assert!(worst < 1e-4, "{worst}");
    // Through the ball: the room, inverted, alike by the path tracer and the photon methods.
    // Measured against the path tracer over the ball's pixels: final gathering -2.4% to
    // -4.7%, sppm +3.0% to +4.5% per channel; over seeds 1 to 16 (mean ± sd of one run,
    // worst channel) -2.0% ± 5.3% and -0.4% ± 10.6% (192 pixels, 4 sppm passes of 10 000
    // photons). Each tolerance is the mean's size plus 4 sd.
    let over_ball = |r: &Rendered| {
        let img = image(r);
        ball.iter().map(|&i| img[i]).sum::<DVec3>() / ball.len() as f64
    };
    let path = over_ball(run_of(ctx, Method::Path));
    assert!(path.min_element() > 0.0, "{path}");
    for (m, tol) in [(Method::FinalGather, 0.23), (Method::Sppm, 0.43)] {
        let d = (over_ball(run_of(ctx, m)) - path) / path;
        eprintln!("sphere of radius 1e-4 up close: {m} against path over the ball {d:+.3}");
        assert!(d.abs().max_element() < tol, "{m}: {d}");
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate triangles.

/// A floor under a light with a glass-free room: `degenerate` adds a zero-area triangle (one
/// vertex repeated), one with all three vertices equal and a collinear one, on the floor and
/// in the air, after every real triangle (so those keep their ids).
fn floor_scene(dir: &Path, degenerate: bool) -> Scene {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, 3.0, Vec3::Y);
    obj.cube("wall", Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5));
    obj.square("lamp", Vec3::new(0.0, 3.0, 0.0), 0.4, -Vec3::Y);
    if degenerate {
        let (a, b) = (Vec3::new(1.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.5));
        obj.tri("floor", [a, a, b]);
        obj.tri("floor", [b, b, b]);
        obj.tri("wall", [a, 0.5 * (a + b), b]);
        let (c, d) = (Vec3::new(-1.0, 1.5, 0.5), Vec3::new(1.0, 1.5, 0.5));
        obj.tri("wall", [c, d, c]);
        obj.tri("wall", [c, 0.25 * c + 0.75 * d, d]);
    }
    let name = if degenerate { "degenerate" } else { "clean" };
    obj.write(dir, name);
    let camera = "eye = [0.0, 4.0, 5.0]\nlook_at = [0.0, 0.5, 0.0]\nvfov = 50.0\n\
                  width = 24\nheight = 24";
    let body = format!(
        "[material.floor]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [material.wall]\ntype = \"lambertian\"\nalbedo = [0.8, 0.4, 0.2]\n\
         [material.lamp]\n{LAMP}emission = [20.0, 20.0, 20.0]\n"
    );
    scene_file(dir, name, camera, &body)
}

fn check_degenerate(ctx: &Ctx) {
    let mesh = ctx.scene.geometry.mesh();
    let zero: Vec<usize> = (0..mesh.len()).filter(|&t| mesh.area(t) == 0.0).collect();
    assert_eq!(zero.len(), 5, "zero-area triangles {zero:?}");
    // The same scene without them renders the same image: the degenerate triangles are
    // never hit, and everything else (ids, light table, random streams) is unchanged.
    // Measured: identical to the bit.
    let clean = floor_scene(ctx.dir, false);
    let cache = ctx.dir.join("clean-cache");
    for (o, r) in ctx.runs {
        let c = render(&clean, o, &cache, None);
        let (a, b) = (image(r), image(&c));
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        eprintln!(
            "degenerate triangles: {}: {same} of {} pixels identical, mean {:+.2e}",
            method(o),
            a.len(),
            rel_diff(&a, &b).abs().max_element()
        );
        assert_eq!(same, a.len(), "{}", method(o));
    }
}

// ---------------------------------------------------------------------------------------------
// Light power near the f32 limit.

/// Emitted radiance of the 1 x 1 lamp: its power pi A Le = 2.83e38 per channel is 83% of
/// f32::MAX (3.40e38). The loader accepts any power that is finite in f32 and refuses the
/// rest with one line naming the light (checked below): a power beyond f32 cannot be
/// stored in a photon file or a light table, while anything up to it is a legitimate, if
/// odd, choice of units (radiance is linear), so a real renderer must render it finitely.
const HUGE_LE: f32 = 9.0e37;

fn power_scene(dir: &Path, le: f32) -> Result<Scene, scene::SceneError> {
    let mut obj = Obj::default();
    obj.square("floor", Vec3::ZERO, 3.0, Vec3::Y);
    obj.square("lamp", Vec3::new(0.0, 3.0, 0.0), 0.5, -Vec3::Y);
    let name = format!("power{}", le.log10().round());
    obj.write(dir, &name);
    let camera = "eye = [0.0, 2.5, 4.0]\nlook_at = [0.0, 0.5, 0.0]\nvfov = 60.0\n\
                  width = 24\nheight = 24";
    let body = format!(
        "[[sphere]]\ncenter = [0.0, 0.6, 0.0]\nradius = 0.6\nmaterial = \"glass\"\n\
         [material.floor]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [material.glass]\ntype = \"dielectric\"\nior = 1.5\n\
         [material.lamp]\n{LAMP}emission = [{le:e}, {le:e}, {le:e}]\n"
    );
    try_scene_file(dir, &name, camera, &body)
}

fn check_huge_power(ctx: &Ctx) {
    let p = ctx.scene.light_power();
    assert!(p.x > 0.8 * f32::MAX && p.x.is_finite(), "{p}");
    // Radiance is linear in the emission: every pixel of every layer is the unit light's
    // times HUGE_LE, to f32 rounding (the same seed draws the same paths). Measured: at most
    // 1.4e-7 relative in any pixel of any method, 1.8e-7 over seeds 1 to 16 (pixels below
    // 1e-3 compared absolutely).
    let unit = power_scene(ctx.dir, 1.0).unwrap_or_else(|e| panic!("{e}"));
    let cache = ctx.dir.join("unit-cache");
    for (o, r) in ctx.runs {
        let u = render(&unit, o, &cache, None);
        let mut worst = 0.0f64;
        for (lh, lu) in r.layers.iter().zip(&u.layers) {
            for (a, b) in lh.image.data.iter().zip(&lu.image.data) {
                for c in 0..3 {
                    let (a, b) = (a[c] as f64 / HUGE_LE as f64, b[c] as f64);
                    if a != b {
                        worst = worst.max((a - b).abs() / b.abs().max(1e-3));
                    }
                }
            }
        }
        eprintln!(
            "huge light: {}: worst relative difference {worst:.2e}",
            method(o)
        );
        assert!(worst < 1e-5, "{}: {worst}", method(o));
    }
    // Beyond f32: refused at load, in one line naming the scene file and the light.
    let msg = match power_scene(ctx.dir, 1.2e38) {
        Ok(_) => panic!("a light of power 3.8e38 per channel was accepted"),
        Err(e) => e.to_string(),
    };
    eprintln!("huge light: beyond f32: {msg}");
    assert!(
        !msg.contains('\n') && msg.contains("overflows f32") && msg.contains(".toml"),
        "{msg}"
    );
}

/// The worksheet with Mitsuba 3's newer models in place of its spheres and beside them: a
/// smooth plastic (silver's sphere), a rough one (glass's), a thin slab and a gold conductor
/// (two more spheres in front).
fn new_materials_worksheet(res: u32) -> Scene {
    use scene::{MaterialDesc, SphereDesc};
    worksheet_with(res, 1, |f| {
        f.materials.insert(
            "silver".into(),
            MaterialDesc::Plastic {
                diffuse: [0.7, 0.2, 0.1],
                specular: [1.0; 3],
                ior: 1.49,
                nonlinear: false,
                texture: None,
            },
        );
        f.materials.insert(
            "glass".into(),
            MaterialDesc::RoughPlastic {
                diffuse: [0.1, 0.3, 0.7],
                specular: [1.0; 3],
                ior: 1.5,
                alpha: 0.2,
                nonlinear: true,
                texture: None,
            },
        );
        f.materials.insert(
            "thin".into(),
            MaterialDesc::ThinDielectric {
                ior: 1.5,
                reflectance: [1.0; 3],
                transmittance: [1.0; 3],
            },
        );
        f.materials.insert(
            "gold".into(),
            MaterialDesc::Conductor {
                reflectance: [1.0; 3],
                eta: None,
                k: None,
                material: Some("Au".into()),
            },
        );
        for (x, material) in [(-9.0, "thin"), (-4.9, "gold")] {
            f.spheres.push(SphereDesc {
                center: [x, 1.2, -2.5],
                radius: 1.2,
                material: material.into(),
            });
        }
    })
}

/// Every method renders the new models without panicking (the common checks), and each one's
/// image mean departs from the path tracer's about as much as it does on the plain worksheet
/// at these quick budgets (photon blur, few samples): a model some method read wrongly (its
/// diffuse lobe without the internal bounces is 2.5 times darker, a lost coating reflection
/// drops the spheres' highlights) would move it much further. Measured, relative to the path
/// tracer on each scene (new / plain, worst channel): global-direct +0.13 / +0.04,
/// final-gather +0.36 / +0.26, caustic-splat -0.99 / -0.96 (quick runs hold few caustics),
/// path+splat -0.02 / -0.06, sppm -0.03 / -0.09, light -0.03 / -0.12, vcm -0.18 / -0.24.
fn check_new_materials(ctx: &Ctx) {
    let path = image(run_of(ctx, Method::Path));
    let plain = worksheet_with(WS_RES, 1, |_| {});
    let cache = ctx.dir.join("plain-cache");
    let plain_path = image(&render(&plain, &quick(Method::Path), &cache, None));
    for (o, r) in ctx.runs {
        let d = rel_diff(&image(r), &path);
        let p = rel_diff(&image(&render(&plain, o, &cache, None)), &plain_path);
        eprintln!(
            "new materials: {} mean vs path {d:+.3}, plain {p:+.3}",
            method(o)
        );
        assert!(
            (d - p).abs().max_element() < 0.15,
            "{}: {d} vs plain {p}",
            method(o)
        );
    }
}
