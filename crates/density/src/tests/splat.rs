//! The anisotropic footprint: each splat integrates to its flux, with and without clamping,
//! and its shape follows the differentials. Splatting onto receivers: a grid of them sums a
//! photon to its flux at every spacing level, and only receivers on the photon's surface and
//! side read it.

use crate::splat::{
    DEFAULT_SAME_SIDE_COS, DEFAULT_TOPO_EPS, Footprint, Receiver, Receivers, Scratch, SplatParams,
    SplatPhoton, footprint, splat,
};
use glam::{DVec3, Vec3};
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

/// Receivers of weight 1 and spacing `h` at (x0 + i h, y, z0 + j h), i < nx, j < nz, normal
/// `ng`, pixels numbered from `pixel0`.
fn floor_grid(
    (x0, z0): (f32, f32),
    h: f32,
    (nx, nz): (u32, u32),
    y: f32,
    ng: Vec3,
    pixel0: u32,
) -> Vec<Receiver> {
    (0..nx * nz)
        .map(|k| Receiver {
            pixel: pixel0 + k,
            p: Vec3::new(x0 + (k % nx) as f32 * h, y, z0 + (k / nx) as f32 * h),
            ng,
            weight: Vec3::ONE,
            spacing: h,
        })
        .collect()
}

/// Σ value · h² over the splat's pairs whose pixel lies in `pixels`: a grid's integral of
/// the irradiance the photon deposits.
fn grid_sum(out: &[(u32, DVec3)], pixels: std::ops::Range<u32>, h: f32) -> DVec3 {
    let sum: DVec3 = out
        .iter()
        .filter(|(p, _)| pixels.contains(p))
        .map(|(_, v)| *v)
        .sum();
    sum * (h as f64).powi(2)
}

/// |Σ_grid K h² − 1| for a footprint of minor semi-axis σ on a square grid of spacing
/// h <= σ/5, at any offset and orientation. By Poisson summation the error is
/// Σ_{m≠0} ĝ(m/h), and for Silverman's kernel ĝ(ω) = 6 J₃(2π|Aᵀω|) / (π³ |Aᵀω|³), A the
/// semi-axes (the transform of (1 − |x|²)₊², Stein and Weiss 1971, "Introduction to Fourier
/// Analysis on Euclidean Spaces", ch. IV; Poisson summation, ch. VII). With
/// |Aᵀω| >= σ|ω|, √x |J₃(x)| <= 0.8 for x >= 10π and Σ_{m≠0} |m|^-3.5 = 4 ζ(1.75)
/// β(1.75) = 7.010: the error is at most 6 · 0.8 · 7.010 / (π³ √(2π)) (h/σ)^3.5
/// = 0.433 (h/σ)^3.5. The 1e-5 covers f32 positions and weights.
fn lattice_bound(h: f32, sigma: f32) -> f64 {
    assert!(h <= sigma / 5.0);
    0.433 * (h as f64 / sigma as f64).powf(3.5) + 1e-5
}

fn assert_flux(got: DVec3, flux: Vec3, tol: f64, what: &str) {
    let rel = (got / flux.as_dvec3() - DVec3::ONE).abs().max_element();
    assert!(
        rel <= tol,
        "{what}: {got} for flux {flux}, error {rel:e} > {tol:e}"
    );
}

#[test]
fn a_photon_splatted_on_a_dense_grid_of_receivers_deposits_its_flux() {
    let photon = SplatPhoton {
        position: Vec3::new(0.013, 0.0, -0.007),
        normal: Vec3::Y,
        flux: Vec3::new(1.0, 2.0, 0.5),
        a: Vec3::new(0.3, 0.0, 0.1),
        b: Vec3::new(0.05, 0.0, -0.15),
    };
    let max_r = 1.0;
    let sigma = footprint(&photon, 0.0, max_r).unwrap().axes[1];
    let h = sigma / 20.0;
    let n = (0.8 / h) as u32;
    let rx = Receivers::new(floor_grid((-0.4, -0.4), h, (n, n), 0.0, Vec3::Y, 0));
    let mut scratch = Scratch::default();
    // The differentials' ellipse, then a disc of radius 0.2.
    for (iso, sigma) in [(0.0, sigma), (0.2, 0.2)] {
        let mut out = Vec::new();
        let params = SplatParams::new(max_r, iso);
        splat(&rx, [photon], &params, &mut scratch, &mut out);
        let tol = lattice_bound(h, sigma);
        assert_flux(grid_sum(&out, 0..n * n, h), photon.flux, tol, "dense");
    }
}

#[test]
fn receivers_behind_or_off_the_photons_tangent_plane_read_nothing() {
    let photon = SplatPhoton {
        position: Vec3::new(0.01, 0.0, 0.02),
        normal: Vec3::Y,
        flux: Vec3::ONE,
        a: 0.3 * Vec3::X,
        b: 0.2 * Vec3::Z,
    };
    let max_r = 1.0;
    let f = footprint(&photon, 0.0, max_r).unwrap();
    let (h, n) = (0.01, 71);
    let g = |y: f32, ng: Vec3, k: u32| floor_grid((-0.35, -0.35), h, (n, n), y, ng, k * n * n);
    // The floor seen from above, the same points from below, and a parallel plane 0.06 up:
    // every point of it within the footprint's reach (0.3) is at least asin(0.2) above the
    // tangent plane, beyond asin(0.1).
    let lift = 0.06;
    let mut all = [g(0.0, Vec3::Y, 0), g(0.0, -Vec3::Y, 1), g(lift, Vec3::Y, 2)].concat();
    // Single receivers either side of each test's threshold, at t < 1.
    let c = photon.position;
    let tilt = |cos: f32| Vec3::new((1.0 - cos * cos).sqrt(), cos, 0.0);
    let single = [
        (
            c + Vec3::new(0.1, 0.5 * DEFAULT_TOPO_EPS * 0.1, 0.0),
            Vec3::Y,
            true,
        ),
        (
            c + Vec3::new(-0.1, 1.5 * DEFAULT_TOPO_EPS * 0.1, 0.0),
            Vec3::Y,
            false,
        ),
        (c + 0.1 * Vec3::Z, tilt(DEFAULT_SAME_SIDE_COS + 0.05), true),
        (c - 0.1 * Vec3::Z, tilt(DEFAULT_SAME_SIDE_COS - 0.05), false),
    ];
    let first = 3 * n * n;
    for (k, &(p, ng, _)) in single.iter().enumerate() {
        all.push(Receiver {
            pixel: first + k as u32,
            p,
            ng,
            weight: Vec3::ONE,
            spacing: h,
        });
    }
    let rx = Receivers::new(all);
    let mut out = Vec::new();
    let params = SplatParams::new(max_r, 0.0);
    splat(&rx, [photon], &params, &mut Scratch::default(), &mut out);

    let sum = |k: u32| grid_sum(&out, k * n * n..(k + 1) * n * n, h);
    assert_flux(sum(0), photon.flux, lattice_bound(h, 0.2), "floor");
    assert_eq!(sum(1), DVec3::ZERO, "the floor's underside");
    assert_eq!(sum(2), DVec3::ZERO, "a plane above the floor");
    // Not vacuous: without the tests, the plane above would read most of the flux (the
    // footprint's weight ignores the offset along the normal).
    let reach: f64 = rx.receivers()[(2 * n * n) as usize..first as usize]
        .iter()
        .filter(|v| (v.p - c).length() <= f.radius())
        .map(|v| f.weight(v.p))
        .sum();
    assert!(reach * (h as f64).powi(2) > 0.5, "{reach}");
    for (k, &(p, _, kept)) in single.iter().enumerate() {
        let got: Vec<DVec3> = out
            .iter()
            .filter(|(q, _)| *q == first + k as u32)
            .map(|(_, v)| *v)
            .collect();
        let want = if kept {
            vec![photon.flux.as_dvec3() * f.weight(p)]
        } else {
            vec![]
        };
        assert!(f.weight(p) > 0.1, "receiver {k} inside the footprint");
        assert_eq!(got, want, "receiver {k} at {p}");
    }
}

#[test]
fn each_spacing_level_integrates_a_photon_thinner_than_its_spacing() {
    // Fine receivers (spacing 0.005) read the photon's own footprint (semi-axes 0.5 and
    // 0.1); coarse ones (spacing 0.25, rows at z = 0.25 j) read it widened to 0.25. The
    // photon lies between two coarse rows, which its own footprint (z in [0.025, 0.225])
    // does not reach.
    let photon = SplatPhoton {
        position: Vec3::new(0.03, 0.0, 0.125),
        normal: Vec3::Y,
        flux: Vec3::new(0.5, 1.0, 2.0),
        a: 0.5 * Vec3::X,
        b: 0.1 * Vec3::Z,
    };
    let (hf, nf) = (0.005, (251, 71));
    let (hc, nc) = (0.25, (9, 6));
    let fine = floor_grid((-0.6, -0.05), hf, nf, 0.0, Vec3::Y, 0);
    let n_fine = nf.0 * nf.1;
    let coarse = floor_grid((-1.0, -0.5), hc, nc, 0.0, Vec3::Y, n_fine);
    let rx = Receivers::new([fine, coarse].concat());
    let mut out = Vec::new();
    let params = SplatParams::new(1.0, 0.0);
    splat(&rx, [photon], &params, &mut Scratch::default(), &mut out);
    let fine_sum = grid_sum(&out, 0..n_fine, hf);
    assert_flux(fine_sum, photon.flux, lattice_bound(hf, 0.1), "fine level");
    // The coarse level's footprint has semi-axes 0.5 and 0.25 along the grid's axes at
    // spacing 0.25: the Poisson sum of `lattice_bound` taken term by term,
    // Σ_{m≠0} 6 |J₃(2πρ)| / (π³ ρ³) with ρ = |(2 m₁, m₂)|, is 0.0523.
    let coarse_sum = grid_sum(&out, n_fine..n_fine + nc.0 * nc.1, hc);
    assert_flux(coarse_sum, photon.flux, 0.0523 + 1e-5, "coarse level");
}
