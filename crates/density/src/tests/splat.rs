//! The anisotropic footprint: each splat integrates to its flux, with and without clamping,
//! and its shape follows the differentials.

use crate::splat::Footprint;
use glam::Vec3;
use math::Rng;

/// Σ weight · h² over a square grid of spacing `h` covering the footprint (the midpoint rule
/// of ∫ K(|M y|) |det M| dy, which is 1).
fn grid_integral(f: &Footprint, h: f32) -> f64 {
    let frame = math::Frame::from_z(f.normal);
    let r = f.radius();
    let n = (r / h).ceil() as i32 + 1;
    let mut sum = 0.0f64;
    for i in -n..=n {
        for j in -n..=n {
            let y = f.center + frame.to_world(Vec3::new(i as f32 * h, j as f32 * h, 0.0));
            sum += f.weight(y);
        }
    }
    sum * (h as f64) * (h as f64)
}

fn random_unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

#[test]
fn a_splat_integrates_to_its_flux_with_and_without_clamping() {
    let mut rng = Rng::new(41);
    let mut case = 0;
    while case < 24 {
        let n = random_unit(&mut rng);
        let c = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
        let (a, b) = (
            random_unit(&mut rng) * (0.2 + rng.uniform()),
            random_unit(&mut rng) * (0.2 + rng.uniform()),
        );
        // Unclamped (bounds far outside the axes), then clamped from below (a thin ellipse
        // widened) and from above.
        let raw = Footprint::new(c, n, a, b, 1e-4, 1e4).unwrap();
        if raw.axes[0] > 12.0 * raw.axes[1] {
            continue; // too thin for a fast grid; the clamped cases below cover thin ones
        }
        case += 1;
        for (min, max) in [(1e-4, 1e4), (0.3, 1e4), (1e-4, 0.25)] {
            let f = Footprint::new(c, n, a, b, min, max).unwrap();
            let h = f.axes[1] / 40.0;
            let e = grid_integral(&f, h);
            assert!(
                (e - 1.0).abs() < 1e-3,
                "case {case} min {min} max {max}: integral {e}, axes {:?}",
                f.axes
            );
        }
    }
}

#[test]
fn degenerate_footprints_become_discs_of_the_minimum_radius_and_still_integrate_to_one() {
    let n = Vec3::Y;
    let c = Vec3::new(1.0, 0.0, 2.0);
    for (a, b) in [
        (Vec3::ZERO, Vec3::ZERO),
        (Vec3::X, 2.0 * Vec3::X), // parallel: the focus of a caustic
        (Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z),
        (Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::Z),
        (Vec3::Y, Vec3::Y), // along the normal: nothing in the plane
    ] {
        let f = Footprint::new(c, n, a, b, 0.05, 1.0).unwrap();
        assert!(
            f.axes[0].is_finite() && f.axes[1] >= 0.05,
            "{a} {b}: {:?}",
            f.axes
        );
        let e = grid_integral(&f, f.axes[1] / 40.0);
        assert!((e - 1.0).abs() < 1e-3, "{a} {b}: {e}");
        assert!(f.weight(c).is_finite());
    }
    assert!(Footprint::new(c, Vec3::ZERO, Vec3::X, Vec3::Z, 0.1, 1.0).is_none());
    assert!(Footprint::new(c, n, Vec3::X, Vec3::Z, 0.0, 1.0).is_none());
}

#[test]
fn the_footprint_is_the_ellipse_the_differentials_span() {
    // a = 2 x, b = 0.5 z on the floor: points at the ends of the axes lie on the rim
    // (t = 1); the centre has t = 0; skewed axes give the same ellipse as their principal
    // form (a ± b span the same ellipse as a, b rotated by 45 degrees, scaled by sqrt 2).
    let c = Vec3::new(3.0, 0.0, -1.0);
    let f = Footprint::new(c, Vec3::Y, 2.0 * Vec3::X, 0.5 * Vec3::Z, 1e-3, 10.0).unwrap();
    assert_eq!(f.axes, [2.0, 0.5]);
    for y in [c + 2.0 * Vec3::X, c - 0.5 * Vec3::Z] {
        assert!((f.t(y) - 1.0).abs() < 1e-6, "{}", f.t(y));
    }
    assert_eq!(f.t(c), 0.0);
    assert!((f.det() - 1.0).abs() < 1e-6);
    let (a, b) = (Vec3::new(1.0, 0.0, 1.0), Vec3::new(1.0, 0.0, -1.0));
    let g = Footprint::new(c, Vec3::Y, a, b, 1e-3, 10.0).unwrap();
    let s2 = 2f32.sqrt();
    assert!((g.axes[0] - s2).abs() < 1e-5 && (g.axes[1] - s2).abs() < 1e-5);
    assert!((g.t(c + a) - 1.0).abs() < 1e-5);
}
