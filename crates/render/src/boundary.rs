//! Boundary-bias correction of photon-map estimates ("cut and normalise"): the estimate
//! divides by pi r^2 as if the whole disc of radius r were surface, so dividing by the
//! fraction of the kernel's mass that lies on surface the estimate can see removes the
//! darkening at edges, corners and rims (Jensen 2001 §7.2 names the bias; the ray-cast
//! support test follows Tobler & Maierhofer 2006). It needs geometry, which `density` does
//! not see, so it lives here.

use density::EstimateParams;
use glam::Vec3;
use scene::Scene;

/// Kernel mass below which the correction stops growing (a point in a corner of three walls
/// keeps about a quarter of its disc): bounds the gain, so noise cannot blow up.
pub const MIN_MASS: f32 = 0.2;

/// Fraction of the kernel's mass (radius `r` about `x`, unit normal `n`) over which the
/// estimate could have found photons. Quadrature: 4 equal-area rings x 8 angles on the
/// tangent disc; each point q at distance rho from x counts if a probe ray along -n finds a
/// surface roughly parallel to this one within the band the topological test accepts,
/// |n . (y - x)| < eps |y - x|, i.e. at heights up to eps rho / sqrt(1 - eps^2) above or
/// below the tangent plane. The band is what makes curved surfaces work: a sphere of radius R
/// falls below its tangent plane by rho^2 / 2R, so a probe confined to the plane misses it
/// and the mass falls to its floor, while the estimate itself (same band) still sees those
/// photons. Without a topological test the band is the whole kernel radius.
pub fn kernel_mass_on_surface(
    scene: &Scene,
    x: Vec3,
    n: Vec3,
    r: f32,
    params: &EstimateParams,
) -> f32 {
    if !(r > 0.0 && r.is_finite()) {
        return 1.0;
    }
    let eps = params.topo.unwrap_or(1.0).clamp(0.0, 1.0);
    // Band half-height per unit of tangent distance; at eps = 1 every height passes, so the
    // kernel radius bounds it.
    let slope = if eps < 1.0 {
        eps / (1.0 - eps * eps).sqrt()
    } else {
        f32::INFINITY
    };
    let frame = math::Frame::from_z(n);
    // A floor under the band for flat surfaces: the probe starts safely above the plane.
    let h = 0.01 * r;
    let hits = |ring: usize, a: usize| {
        let t = ((ring as f32 + 0.5) / 4.0).sqrt();
        let rho = t * r;
        let band = (slope * rho).min(r) + h;
        // Offsets keep points off the axes, where walls of an axis-aligned box would cut
        // through them.
        let phi = std::f32::consts::TAU * (a as f32 + 0.25 + 0.5 * (ring % 2) as f32) / 8.0;
        let q = x + frame.to_world(Vec3::new(rho * phi.cos(), rho * phi.sin(), 0.0));
        probe(scene, q + band * n, -n, 2.0 * band, n)
    };
    // The outer ring first: where all of it lies on the surface the disc does too (short of
    // a hole inside it), and the mass is 1 without the inner 24 probes. Most estimates are
    // away from edges, so this saves three quarters of the rays (SPPM probes every pixel
    // every pass).
    let outer: [bool; 8] = std::array::from_fn(|a| hits(3, a));
    if outer.iter().all(|&h| h) {
        return 1.0;
    }
    let (mut on, mut all) = (0.0f64, 0.0f64);
    for ring in 0..4 {
        let t = ((ring as f32 + 0.5) / 4.0).sqrt();
        let w = params.kernel.weight(t as f64);
        for (a, &out) in outer.iter().enumerate() {
            all += w;
            let hit = if ring == 3 { out } else { hits(ring, a) };
            if hit {
                on += w;
            }
        }
    }
    if all > 0.0 { (on / all) as f32 } else { 1.0 }
}

/// Whether a ray from `o` along `d` meets, within `t_max`, a surface roughly parallel to the
/// tangent plane (within 60 degrees; geometric normals carry no orientation, so both faces
/// count): a wall the disc runs into is parallel to the probe and never qualifies.
fn probe(scene: &Scene, o: Vec3, d: Vec3, t_max: f32, n: Vec3) -> bool {
    let ray = geom::Ray { o, d, t_max };
    scene
        .geometry
        .intersect(&ray)
        .is_some_and(|hit| hit.point.n.dot(n).abs() > 0.5)
}
