//! Regions of an image drawn from the scene's geometry, where density estimation's biases
//! live: the caustic under a glass sphere, the inner edges and corners of a box, its outer
//! rim, the glass sphere itself, the open walls. A region is the set of pixels whose camera
//! ray through the pixel centre lands on the named surfaces.

use film::Mask;
use glam::Vec3;
use scene::{Material, Scene};

/// Whether `material` is a surface photons land on and estimates are made at: diffuse and
/// not an emitter. A light's own pixels are left out of every region but the whole image:
/// one sample per pixel at its edge flips between the light and the ceiling, which would
/// drown the walls' statistics, and its edges are no rim of the box.
fn receives(scene: &Scene, material: u32) -> bool {
    scene.is_diffuse(material) && scene.emission[material as usize] == Vec3::ZERO
}

/// Glass, smooth or rough.
fn is_glass(m: &Material) -> bool {
    matches!(
        m,
        Material::Dielectric { .. } | Material::RoughDielectric { .. }
    )
}

/// The named regions of an image of `scene`, from its geometry: the caustic under the glass
/// sphere, the inner edges and corners of the box, its outer rim (the open front), the glass
/// sphere, the open walls (diffuse surfaces away from edges and caustics), and the whole
/// image. Every region but the whole image leaves out the pixels that see a light.
pub fn regions(scene: &Scene) -> Vec<(&'static str, Mask)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let caustic = caustic_region(scene, 1.6);
    // Edge band: two percent of the scene's diagonal (the k-NN discs' scale).
    let b = scene.geometry.bounds();
    let band = 0.02 * (b.max - b.min).length();
    let rim = rim_mask(scene, band);
    let inner = edge_mask(scene, band);
    let edges = Mask::from_fn(w, h, |x, y| {
        inner.pixels[y * w + x] && !rim.pixels[y * w + x]
    });
    let seen = |x: usize, y: usize| {
        scene
            .geometry
            .intersect(&scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
    };
    let glass = Mask::from_fn(w, h, |x, y| {
        seen(x, y).is_some_and(|hit| is_glass(&scene.materials[hit.material as usize]))
    });
    let walls = Mask::from_fn(w, h, |x, y| {
        let i = y * w + x;
        !caustic.pixels[i]
            && !inner.pixels[i]
            && !rim.pixels[i]
            && seen(x, y).is_some_and(|hit| receives(scene, hit.material))
    });
    // Pixels that see an emitter anywhere in their footprint (centre and four points near the
    // corners): a sample or two per pixel either hits the light or misses it, so at the
    // light's outline one run's pixel reads a fraction of the light or none; left in, those
    // few pixels would swing a region's mean by a percent.
    let near_light = Mask::from_fn(w, h, |x, y| {
        [
            (0.5, 0.5),
            (0.02, 0.02),
            (0.98, 0.02),
            (0.02, 0.98),
            (0.98, 0.98),
        ]
        .iter()
        .any(|&(dx, dy)| {
            let ray = scene.camera.ray(x as f32 + dx, y as f32 + dy);
            scene
                .geometry
                .intersect(&ray)
                .is_some_and(|hit| scene.emission[hit.material as usize] != Vec3::ZERO)
        })
    });
    let away = |m: Mask| {
        Mask::from_fn(w, h, |x, y| {
            m.pixels[y * w + x] && !near_light.pixels[y * w + x]
        })
    };
    vec![
        ("image", Mask::all(w, h)),
        ("caustic", away(caustic)),
        ("edges and corners", away(edges)),
        ("outer rim", away(rim)),
        ("glass sphere", away(glass)),
        ("open walls", away(walls)),
    ]
}

/// Pixels whose camera ray (through the pixel centre) lands on the floor (a diffuse surface
/// facing up) within `radii` sphere radii, horizontally, of a glass sphere's centre: where
/// its caustic falls.
pub fn caustic_region(scene: &Scene, radii: f32) -> Mask {
    let cam = &scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let glass: Vec<(Vec3, f32)> = scene
        .geometry
        .spheres()
        .iter()
        .filter(|s| is_glass(&scene.materials[s.material as usize]))
        .map(|s| (s.center, s.radius))
        .collect();
    Mask::from_fn(w, h, |x, y| {
        let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
        let Some(hit) = scene.geometry.intersect(&ray) else {
            return false;
        };
        if !scene.is_diffuse(hit.material) || hit.point.n.y.abs() < 0.99 {
            return false;
        }
        let p = hit.point.p;
        glass.iter().any(|&(c, r)| {
            let d = Vec3::new(p.x - c.x, 0.0, p.z - c.z).length();
            p.y < c.y && d < radii * r
        })
    })
}

/// Pixels whose camera ray (through the pixel centre) lands on a diffuse surface within
/// `band` of a triangle that is not coplanar with it: the inner edges and corners of the box.
pub fn edge_mask(scene: &Scene, band: f32) -> Mask {
    let cam = &scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mesh = scene.geometry.mesh();
    let walls: Vec<usize> = (0..mesh.len())
        .filter(|&t| {
            matches!(
                scene.materials[mesh.materials[t] as usize],
                Material::Lambertian { .. }
            ) && receives(scene, mesh.materials[t])
        })
        .collect();
    Mask::from_fn(w, h, |x, y| {
        let Some(hit) = scene
            .geometry
            .intersect(&cam.ray(x as f32 + 0.5, y as f32 + 0.5))
        else {
            return false;
        };
        if !matches!(
            scene.materials[hit.material as usize],
            Material::Lambertian { .. }
        ) || !receives(scene, hit.material)
        {
            return false;
        }
        walls.iter().any(|&t| {
            let n = mesh.face_normal(t).normalize_or_zero();
            n.dot(hit.point.n).abs() < 0.9
                && point_triangle_distance(hit.point.p, mesh.vertices(t)) < band
        })
    })
}

/// Pixels whose camera ray lands on a diffuse surface within `band` of the box's outer rim:
/// an edge of a diffuse triangle that no other triangle touches (the open front of the box),
/// where a density estimate's disc reaches past the surface (boundary bias). Edges are tested
/// at their midpoints against every triangle: quadratic in the triangle count, which suits
/// boxes, not million-triangle meshes.
pub fn rim_mask(scene: &Scene, band: f32) -> Mask {
    let cam = &scene.camera;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mesh = scene.geometry.mesh();
    let b = scene.geometry.bounds();
    let eps = 1e-5 * (b.max - b.min).length();
    let mut rim: Vec<(Vec3, Vec3)> = Vec::new();
    for t in 0..mesh.len() {
        if !receives(scene, mesh.materials[t]) {
            continue;
        }
        let v = mesh.vertices(t);
        for i in 0..3 {
            let (a, c) = (v[i], v[(i + 1) % 3]);
            let mid = 0.5 * (a + c);
            let touched = (0..mesh.len())
                .any(|u| u != t && point_triangle_distance(mid, mesh.vertices(u)) < eps);
            if !touched {
                rim.push((a, c));
            }
        }
    }
    Mask::from_fn(w, h, |x, y| {
        let Some(hit) = scene
            .geometry
            .intersect(&cam.ray(x as f32 + 0.5, y as f32 + 0.5))
        else {
            return false;
        };
        receives(scene, hit.material)
            && rim
                .iter()
                .any(|&(a, c)| point_segment_distance(hit.point.p, a, c) < band)
    })
}

fn point_segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
    (p - (a + t * ab)).length()
}

/// Distance from `p` to the triangle `t` (Ericson, Real-Time Collision Detection, §5.1.5).
fn point_triangle_distance(p: Vec3, t: [Vec3; 3]) -> f32 {
    let [a, b, c] = t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (p - a).length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (p - b).length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).length();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (p - c).length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).length();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).length()
}

#[cfg(test)]
pub(crate) fn distance_for_test(p: Vec3, t: [Vec3; 3]) -> f32 {
    point_triangle_distance(p, t)
}
