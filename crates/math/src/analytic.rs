//! Closed forms the tests check estimates against.

use glam::DVec3;

/// Irradiance at `p` (unit normal `n`) from a uniform Lambertian polygon of radiance `le`,
/// fully visible and above the tangent plane: Lambert's formula
/// `E = le/2 * sum_i theta_i (n . g_i)`, `theta_i` the angle subtended by edge `i` and `g_i`
/// the unit normal of the plane through `p` and that edge (Arvo 1994, eq. 2; Baum et al.
/// 1989).
pub fn polygon_irradiance(p: DVec3, n: DVec3, polygon: &[DVec3], le: f64) -> f64 {
    let mut s = 0.0;
    for i in 0..polygon.len() {
        let a = (polygon[i] - p).normalize();
        let b = (polygon[(i + 1) % polygon.len()] - p).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        s += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * le * s.abs()
}
