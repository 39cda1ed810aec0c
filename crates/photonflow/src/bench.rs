//! `bench-rays`: single-thread closest-hit throughput. Rays are generated before the clock
//! starts; each kind is timed `runs` times and the median reported (machines are shared and
//! noisy, so one run says little).

use geom::{BvhKind, Geometry, Ray};
use glam::Vec3;
use math::Rng;
use std::path::Path;
use std::time::Instant;

pub fn rays(path: &Path, runs: usize, count: usize, compare: bool) -> Result<(), String> {
    if runs == 0 || count == 0 {
        return Err("--runs and --rays must be positive".into());
    }
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    let coherent = camera_rays(&s.camera, count);
    let incoherent = random_rays(&s.geometry, count, s.seed());
    println!(
        "scene {} ({} triangles, {} spheres), {} rays per run, median of {} runs, 1 thread",
        path.display(),
        s.geometry.mesh().len(),
        s.geometry.spheres().len(),
        count,
        runs
    );
    let mut kinds = vec![BvhKind::CwBvh];
    if compare {
        kinds.push(BvhKind::Bvh2);
    }
    for kind in kinds {
        let t0 = Instant::now();
        let geo = Geometry::with_bvh(
            s.geometry.mesh().clone(),
            s.geometry.spheres().to_vec(),
            kind,
        );
        let build = t0.elapsed();
        for (name, rays) in [("coherent", &coherent), ("incoherent", &incoherent)] {
            let (mrays, hits) = median_rate(&geo, rays, runs);
            println!(
                "{name:>10}: {mrays:7.2} M rays/s  ({kind:?}, build {:.1} ms, {:.1}% hit)",
                build.as_secs_f64() * 1e3,
                100.0 * hits as f64 / rays.len() as f64
            );
        }
    }
    Ok(())
}

fn median_rate(geo: &Geometry, rays: &[Ray], runs: usize) -> (f64, usize) {
    let mut rates = Vec::with_capacity(runs);
    let mut hits = 0;
    for _ in 0..runs {
        let t = Instant::now();
        hits = rays
            .iter()
            .filter(|r| std::hint::black_box(geo.intersect(r)).is_some())
            .count();
        rates.push(rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6);
    }
    rates.sort_by(f64::total_cmp);
    (rates[runs / 2], hits)
}

/// Primary rays through a square grid of pixel centres covering the camera's image.
fn camera_rays(cam: &scene::Camera, count: usize) -> Vec<Ray> {
    let n = (count as f64).sqrt().ceil() as usize;
    let (w, h) = (cam.width as f32, cam.height as f32);
    (0..count)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            cam.ray(
                (x as f32 + 0.5) / n as f32 * w,
                (y as f32 + 0.5) / n as f32 * h,
            )
        })
        .collect()
}

/// Origins uniform in the scene's bounding box, directions uniform on the sphere.
fn random_rays(geo: &Geometry, count: usize, seed: u64) -> Vec<Ray> {
    let b = geo.bounds();
    let mut rng = Rng::new(seed ^ 0xbe4c);
    (0..count)
        .map(|_| {
            let o = b.lerp(Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()));
            let z = 1.0 - 2.0 * rng.uniform();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * rng.uniform();
            Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect()
}
