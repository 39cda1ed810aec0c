use crate::{Frame, Rng, warp::sample_uniform_sphere};
use glam::Vec3;

fn normals() -> Vec<Vec3> {
    // Random normals plus the poles and near-poles, where naive constructions break.
    let mut rng = Rng::new(11);
    let mut ns: Vec<Vec3> = (0..1000)
        .map(|_| sample_uniform_sphere(rng.uniform2()))
        .collect();
    ns.extend([
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(0.0, 0.0, -0.0),
        Vec3::new(1e-4, -1e-4, -1.0).normalize(),
        Vec3::new(-1e-4, 1e-4, 1.0).normalize(),
        Vec3::X,
        Vec3::Y,
    ]);
    ns.retain(|n| n.length() > 0.5);
    ns
}

#[test]
fn frame_is_orthonormal_and_right_handed() {
    for n in normals() {
        let f = Frame::from_z(n);
        for (a, b) in [(f.s, f.t), (f.t, f.n), (f.n, f.s)] {
            assert!(a.dot(b).abs() < 1e-5, "n = {n}: {a} · {b}");
        }
        for v in [f.s, f.t, f.n] {
            assert!((v.length() - 1.0).abs() < 1e-5, "n = {n}: |{v}|");
        }
        assert!(f.s.cross(f.t).distance(f.n) < 1e-5, "n = {n}: left-handed");
    }
}

#[test]
fn frame_round_trips_and_maps_normal_to_z() {
    let mut rng = Rng::new(12);
    for n in normals() {
        let f = Frame::from_z(n);
        assert!(f.to_local(n).distance(Vec3::Z) < 1e-5, "n = {n}");
        let v = sample_uniform_sphere(rng.uniform2()) * 3.0;
        assert!(
            f.to_world(f.to_local(v)).distance(v) < 1e-5,
            "n = {n}, v = {v}"
        );
        assert!(
            f.to_local(f.to_world(v)).distance(v) < 1e-5,
            "n = {n}, v = {v}"
        );
    }
}
