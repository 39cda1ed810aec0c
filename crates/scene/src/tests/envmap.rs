//! The environment light against Mitsuba 3's `envmap`, closed forms, and the chi-square
//! harness.

use crate::EnvMap;
use glam::{Mat3, Vec3};
use math::Rng;
use math::chi2::{chi2_test_sidak_sub, sidak_alpha};
use std::f32::consts::{FRAC_PI_2, PI, TAU};

const W: usize = 8;
const H: usize = 5;

/// The map of the Mitsuba reference table: every texel distinct, one bright.
fn reference_texels() -> Vec<Vec3> {
    let mut t: Vec<Vec3> = (0..W * H)
        .map(|k| {
            let (x, y) = ((k % W) as f32, (k / W) as f32);
            Vec3::new(1.0 + x + 10.0 * y, 0.5 + 0.25 * x, 2.0 + y)
        })
        .collect();
    t[W + 2] = Vec3::new(500.0, 400.0, 300.0);
    t
}

fn reference_map(scale: f32, to_world: Mat3) -> EnvMap {
    EnvMap::from_image(W, H, reference_texels(), scale, to_world).unwrap()
}

/// The local direction of texel `(i, j)`'s node: `φ = 2π (i + ½) / W`, `θ = π j / (H - 1)`.
fn texel_dir(i: usize, j: usize, w: usize, h: usize) -> Vec3 {
    let phi = TAU * (i as f32 + 0.5) / w as f32;
    let theta = PI * j as f32 / (h - 1) as f32;
    Vec3::new(
        phi.sin() * theta.sin(),
        theta.cos(),
        -phi.cos() * theta.sin(),
    )
}

fn close(a: Vec3, b: Vec3, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * b.abs().max_element().max(1.0)
}

/// Mitsuba 3.9.1 (`scalar_rgb`), `envmap` loaded by `load_dict` from an `mi.Bitmap` of
/// [`reference_texels`] (an 8 x 5 float32 RGB numpy array, row 0 first); each value is
/// `emitter.eval(si)` with `si.wi = -d`. Columns: `d`; `scale` 1, identity; `scale` 2,
/// `to_world = ScalarTransform4f().rotate([0, 0, 1], 90)`.
#[rustfmt::skip]
const MITSUBA: [([f32; 3], [f32; 3], [f32; 3]); 10] = [
    ([0.6532815, 0.70710677, 0.27059805], [499.99976, 399.99982, 299.99985], [64.05937, 1.982678, 9.812865]),
    ([0.010000375, 0.9999375, 0.0050001875], [9.540334, 6.190427, 5.860979], [45.267406, 1.7531834, 8.025467]),
    ([-0.6532815, -0.70710677, 0.27059805], [36.000004, 1.7500001, 5.0], [33.94063, 3.5173218, 6.1871343]),
    ([-0.38268343, 6.123234e-17, -0.9238795], [28.0, 2.25, 4.0], [39.0, 2.75, 7.0]),
    ([4.6865205e-17, -1.0, -1.1314261e-16], [41.000004, 0.5000006, 6.0], [53.0, 3.75, 8.0]),
    ([0.30304575, 0.5050763, -0.80812204], [14.56097, 0.5755988, 3.3258576], [50.26274, 1.1056156, 8.784028]),
    ([-0.970495, -0.10783277, 0.21566555], [27.597227, 1.8053955, 4.1375647], [16.381882, 3.045167, 4.6201215]),
    ([0.0, 0.0, -1.0], [24.5, 1.375, 4.0], [49.0, 2.75, 8.0]),
    ([1.0, 0.0, 0.0], [22.5, 0.875, 4.0], [93.0, 3.75, 12.0]),
    ([0.24077171, -0.84270096, 0.48154342], [36.671097, 1.2274163, 5.276143], [57.870045, 3.4195013, 8.619204]),
];

#[test]
fn envmap_eval_matches_mitsuba_3() {
    let plain = reference_map(1.0, Mat3::IDENTITY);
    let turned = reference_map(2.0, Mat3::from_rotation_z(FRAC_PI_2));
    for (d, want, want_turned) in MITSUBA {
        let d = Vec3::from_array(d);
        let (got, got_turned) = (plain.eval(d), turned.eval(d));
        assert!(
            close(got, want.into(), 1e-5),
            "{d}: {got} against Mitsuba's {want:?}"
        );
        assert!(
            close(got_turned, want_turned.into(), 1e-5),
            "{d} turned: {got_turned} against Mitsuba's {want_turned:?}"
        );
    }
}

#[test]
fn envmap_eval_at_a_texel_node_is_that_texel() {
    // Every texel a different colour; the poles (rows 0 and H-1) are one point each.
    let texels: Vec<Vec3> = (0..16 * 9)
        .map(|k| Vec3::new(k as f32, (k * 7 % 13) as f32, 1.0 + (k % 5) as f32))
        .collect();
    let map = EnvMap::from_image(16, 9, texels.clone(), 1.0, Mat3::IDENTITY).unwrap();
    for j in 1..8 {
        for i in 0..16 {
            let got = map.eval(texel_dir(i, j, 16, 9));
            assert!(
                close(got, texels[j * 16 + i], 1e-4),
                "texel ({i}, {j}): {got}"
            );
        }
    }
    // The bright texel of the reference map: column 2, row 1 lies at φ = 5π/8, θ = π/4.
    let map = reference_map(3.0, Mat3::IDENTITY);
    let d = texel_dir(2, 1, W, H);
    assert!((d - Vec3::new(0.6532815, 0.70710677, 0.27059805)).length() < 1e-6);
    assert!(close(map.eval(d), Vec3::new(1500.0, 1200.0, 900.0), 1e-5));
}

#[test]
fn envmap_sample_matches_pdf_chi2() {
    let family = 2;
    let mut rng = Rng::new(41);
    // Squared uniforms: a 1000:1 spread, and some near-black texels.
    let random: Vec<Vec3> = (0..16 * 9)
        .map(|_| {
            let [a, b] = rng.uniform2();
            Vec3::new(a * a, b * b, 0.2 * a)
        })
        .collect();
    let cases = [
        // Local +Y onto world +Z: the map's rows are the harness's bands.
        reference_map(1.0, Mat3::from_rotation_x(FRAC_PI_2)),
        EnvMap::from_image(16, 9, random, 0.5, Mat3::IDENTITY).unwrap(),
    ];
    for (k, map) in cases.iter().enumerate() {
        chi2_test_sidak_sub(
            family,
            51,
            96,
            8,
            300_000,
            42 + k as u64,
            |rng| Some(map.sample(rng.uniform2()).0),
            |w| map.pdf(w) as f64,
        )
        .unwrap_or_else(|e| panic!("case {k}: {e} (alpha {})", sidak_alpha(family)));
    }
}

/// `∫ f dω` over the sphere by the midpoint rule on an `n x 2n` grid in `(z, φ)`.
fn sphere_integral(n: usize, f: impl Fn(Vec3) -> [f64; 3]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for a in 0..n {
        let z = 1.0 - (a as f64 + 0.5) * 2.0 / n as f64;
        let r = (1.0 - z * z).sqrt();
        for b in 0..2 * n {
            let phi = (b as f64 + 0.5) * std::f64::consts::PI / n as f64;
            let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            let v = f(w);
            for k in 0..3 {
                sum[k] += v[k];
            }
        }
    }
    let cell = 2.0 / n as f64 * std::f64::consts::PI / n as f64;
    sum.map(|s| s * cell)
}

#[test]
fn envmap_pdf_integrates_to_one_and_agrees_with_sample() {
    let turn = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let map = reference_map(1.0, turn);
    let integral = sphere_integral(600, |w| [map.pdf(w) as f64; 3])[0];
    assert!(
        (integral - 1.0).abs() < 2e-3,
        "pdf integrates to {integral}"
    );
    let mut rng = Rng::new(43);
    for _ in 0..20_000 {
        let (d, radiance, pdf) = map.sample(rng.uniform2());
        assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
        assert!(
            pdf > 0.0 && (pdf - map.pdf(d)).abs() <= 1e-3 * pdf,
            "{d}: {pdf}"
        );
        // Rotating to world and back moves d by an ulp or so, which near the poles turns
        // the azimuth, and row 0 changes fast with it: compare away from them.
        if (turn.transpose() * d).y.abs() < 0.99 {
            assert!(close(radiance, map.eval(d), 1e-4), "{d}: {radiance}");
        }
    }
}

#[test]
fn envmap_uniform_maps_are_uniform_in_solid_angle() {
    let c = Vec3::new(0.3, 0.6, 0.9);
    let turn = Mat3::from_rotation_y(0.4);
    let image = EnvMap::from_image(8, 5, vec![c; 40], 2.0, turn).unwrap();
    let constant = EnvMap::constant(c, 2.0, turn).unwrap();
    let uniform = 0.25 / PI;
    let mut rng = Rng::new(44);
    for _ in 0..10_000 {
        let u = rng.uniform2();
        for map in [&image, &constant] {
            let (d, radiance, pdf) = map.sample(u);
            assert!((pdf - uniform).abs() < 1e-5 * uniform, "{d}: pdf {pdf}");
            assert!(close(radiance, 2.0 * c, 1e-6));
            let w = math::warp::sample_uniform_sphere(rng.uniform2());
            assert!(close(map.eval(w), 2.0 * c, 1e-6), "{w}");
            assert!((map.pdf(w) - uniform).abs() < 1e-5 * uniform, "{w}");
        }
    }
}

#[test]
fn envmap_power_is_pi_r2_times_the_radiance_integral() {
    // Closed form for uniform radiance L: Φ = π r² · 4π L.
    let c = Vec3::new(1.0, 2.0, 3.0);
    let want = PI * 2.0 * 2.0 * 4.0 * PI * 1.5 * c;
    for map in [
        EnvMap::constant(c, 1.5, Mat3::IDENTITY).unwrap(),
        EnvMap::from_image(6, 4, vec![c; 24], 1.5, Mat3::IDENTITY).unwrap(),
    ] {
        assert!(close(map.power(2.0), want, 1e-6), "{}", map.power(2.0));
    }
    // A varied map: the closed-form patch integrals against quadrature of eval itself.
    let map = reference_map(0.5, Mat3::from_rotation_x(0.3));
    let quad = sphere_integral(1000, |w| map.eval(w).to_array().map(|c| c as f64));
    let want = Vec3::from_array(quad.map(|q| (std::f64::consts::PI * 9.0 * q) as f32));
    let got = map.power(3.0);
    assert!(close(got, want, 1e-3), "power {got}, quadrature {want}");
}

#[test]
fn envmap_refuses_bad_input_in_one_line() {
    let ok = vec![Vec3::ONE; 6];
    let id = Mat3::IDENTITY;
    let cases: [(Result<EnvMap, String>, &str); 10] = [
        (
            EnvMap::from_image(0, 3, vec![], 1.0, id),
            "smaller than 2x3",
        ),
        (
            EnvMap::from_image(2, 0, vec![], 1.0, id),
            "smaller than 2x3",
        ),
        (
            EnvMap::from_image(2, 3, vec![Vec3::ONE; 5], 1.0, id),
            "needs 6 texels",
        ),
        (
            EnvMap::from_image(2, 3, vec![Vec3::ZERO; 6], 1.0, id),
            "black",
        ),
        (
            EnvMap::from_image(
                2,
                3,
                {
                    let mut t = ok.clone();
                    t[3].y = -1.0;
                    t
                },
                1.0,
                id,
            ),
            "texel (1, 1)",
        ),
        (
            EnvMap::from_image(
                2,
                3,
                {
                    let mut t = ok.clone();
                    t[4].x = f32::NAN;
                    t
                },
                1.0,
                id,
            ),
            "finite",
        ),
        (EnvMap::from_image(2, 3, ok.clone(), 0.0, id), "scale 0"),
        (
            EnvMap::from_image(2, 3, ok.clone(), 1.0, 2.0 * id),
            "not a rotation",
        ),
        (EnvMap::constant(Vec3::ZERO, 1.0, id), "black"),
        (
            EnvMap::constant(Vec3::new(1.0, f32::INFINITY, 1.0), 1.0, id),
            "finite",
        ),
    ];
    for (i, (r, want)) in cases.into_iter().enumerate() {
        let e = r.err().unwrap_or_else(|| panic!("case {i} was accepted"));
        assert!(e.contains(want) && !e.contains('\n'), "case {i}: {e}");
    }
}
