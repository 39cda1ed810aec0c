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
    // The bytes are the layout the file header names (RECORD_LAYOUT): position, power,
    // direction, surface, in that order, little-endian. Readers cast, so a reordered field
    // would silently misread every file.
    let b = bytemuck::bytes_of(&p);
    let f32_at = |i: usize| f32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    let u32_at = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    assert_eq!([f32_at(0), f32_at(4), f32_at(8)], [1.0, 2.0, 3.0]);
    assert_eq!([f32_at(12), f32_at(16), f32_at(20)], [0.5, 0.25, 0.125]);
    assert_eq!(u32_at(24), p.dir);
    assert_eq!(u32_at(28), 7);
    assert!(crate::RECORD_LAYOUT.starts_with("pos:f32x3,power:f32x3,dir:oct16x2,surface:u32"));
    assert_eq!(p.position(), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(p.power(), Vec3::new(0.5, 0.25, 0.125));
    assert!((p.direction() - -Vec3::Y).length() < 1e-6);
    assert_eq!(p.surface, 7);
}
