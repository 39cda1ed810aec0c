use crate::{Photon, oct_decode, oct_encode};
use glam::Vec3;

#[test]
fn octahedral_directions_round_trip_within_1e_4_radians() {
    // A Fibonacci sphere plus the axes and octant seams.
    let n = 20_000;
    let mut dirs: Vec<Vec3> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - z * z).sqrt();
            let phi = i as f32 * 2.399_963;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    for a in [Vec3::X, Vec3::Y, Vec3::Z] {
        dirs.extend([a, -a]);
    }
    dirs.push(Vec3::new(1.0, -1.0, 0.0).normalize());
    for d in dirs {
        let e = oct_decode(oct_encode(d));
        // Chord-based angle: acos of a dot product near 1 loses everything in f32.
        let angle = 2.0 * (0.5 * (d - e).length()).asin();
        assert!(angle < 1e-4, "{d:?} -> {e:?}: {angle} rad");
    }
}

#[test]
fn a_photon_is_32_bytes_and_keeps_its_fields() {
    let p = Photon::new(
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(0.5, 0.25, 0.125),
        -Vec3::Y,
        7,
    );
    assert_eq!(bytemuck::bytes_of(&p).len(), 32);
    assert_eq!(p.position(), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(p.power(), Vec3::new(0.5, 0.25, 0.125));
    assert!((p.direction() - -Vec3::Y).length() < 1e-6);
    assert_eq!(p.surface, 7);
}
