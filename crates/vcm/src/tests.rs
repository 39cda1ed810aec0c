//! The MIS weights of every strategy that can make a path sum to one: on random paths of
//! every length from 2 to 8 segments between the pinhole and a light, over Lambertian
//! vertices, at eight merging radii from 1e-4 to 1 (the box is 4 wide), for an area light and for a point light (direct light,
//! 2 segments, between NEE and BSDF sampling alone). The weights
//! are the functions the renderer calls ([`crate::weights`]), fed the partial sums the
//! subpaths build on their way ([`SubPath::arrive`], [`SubPath::scatter`]) and the densities
//! at the vertices each strategy joins. With bidirectional connections switched off
//! ([`Options::bidirectional`]) the strategies left still sum to one, and the weights of the
//! full set do not (so the sums really leave the connections out).

use crate::weights;
use crate::{Options, Pass, Strategies, SubPath, mis};
use bsdf::{BsdfSample, Flags};
use glam::Vec3;
use math::Rng;

const PI: f32 = std::f32::consts::PI;

/// Light subpaths per pass: a 256 x 256 image's.
const N: u64 = 65_536;

/// The camera's density per solid angle of the first segment (any positive value: the eye
/// subpath's start and the light tracer's connection read the same one).
const CAMERA_PDF_W: f32 = 3.0;

/// A path `x[0]` (the pinhole) .. `x[k]` (the light) with a normal at each vertex.
struct Path {
    x: Vec<Vec3>,
    n: Vec<Vec3>,
}

impl Path {
    /// `|cos|` at vertex `i` towards vertex `j`.
    fn cos(&self, i: usize, j: usize) -> f32 {
        self.n[i].dot((self.x[j] - self.x[i]).normalize()).abs()
    }
    fn dist2(&self, i: usize, j: usize) -> f32 {
        (self.x[j] - self.x[i]).length_squared()
    }
    /// The Lambertian density at vertex `i` of sampling the direction to `j`.
    fn pdf(&self, i: usize, j: usize) -> f32 {
        self.cos(i, j) / PI
    }
}

/// A random path of `k` segments whose every vertex sees both neighbours at a cosine of at
/// least 0.1 (each normal near the bisector of its two directions).
fn random_path(rng: &mut Rng, k: usize) -> Path {
    loop {
        let x: Vec<Vec3> = (0..=k)
            .map(|_| {
                let [a, b] = rng.uniform2();
                Vec3::new(a, b, rng.uniform()) * 4.0 - 2.0
            })
            .collect();
        let jitter = |rng: &mut Rng| {
            let [a, b] = rng.uniform2();
            Vec3::new(a - 0.5, b - 0.5, rng.uniform() - 0.5) * 0.4
        };
        let mut n = Vec::with_capacity(k + 1);
        for i in 0..=k {
            let mut d = Vec3::ZERO;
            if i > 0 {
                d += (x[i - 1] - x[i]).normalize();
            }
            if i < k {
                d += (x[i + 1] - x[i]).normalize();
            }
            n.push((d.normalize() + jitter(rng)).normalize());
        }
        let p = Path { x, n };
        let ok = (0..k).all(|i| p.cos(i, i + 1) > 0.1 && p.cos(i + 1, i) > 0.1);
        if ok && p.x.iter().all(|v| v.is_finite()) && p.n.iter().all(|v| v.is_finite()) {
            return p;
        }
    }
}

/// A Lambertian sample leaving at `cos_out` with density `pdf`.
fn sample(cos_out: f32, pdf: f32) -> BsdfSample {
    BsdfSample {
        f: Vec3::splat(1.0 / PI),
        wi: Vec3::new((1.0 - cos_out * cos_out).max(0.0).sqrt(), 0.0, cos_out),
        pdf,
        flags: Flags::DIFFUSE_REFLECTION,
        eta: 1.0,
    }
}

/// The light at `x[k]`: an area light of area `area`, or a point light (`None`).
#[derive(Clone, Copy)]
enum Light {
    Area(f32),
    Point,
}

/// The sum of the weights of every strategy of `pass` that makes `p`.
fn weight_sum(p: &Path, pass: &Pass, light: Light) -> f32 {
    weight_sum_of(p, pass, light, pass.opts.bidirectional)
}

/// The sums of `pass` with its connections left out of the total: what switching them off
/// would give if the weights still counted them.
fn weight_sum_mixed(p: &Path, pass: &Pass, light: Light) -> f32 {
    weight_sum_of(p, pass, light, false)
}

/// The sum of the weights `pass` gives the strategies that make `p`, the bidirectional
/// connections included only if `connections`.
fn weight_sum_of(p: &Path, pass: &Pass, light: Light, connections: bool) -> f32 {
    let k = p.x.len() - 1;
    // The light's densities of emitting towards `x[k - 1]` and of NEE choosing its point.
    let (emit, direct, cos_l, delta) = match light {
        Light::Area(area) => (
            p.cos(k, k - 1) / PI / area,
            1.0 / area,
            p.cos(k, k - 1),
            false,
        ),
        Light::Point => (0.25 / PI, 1.0, 1.0, true),
    };
    let zero = SubPath::start(pass, 0.0, 0.0, 0.0).sums();
    // The eye subpath's sums on arrival at each vertex.
    let mut eye = vec![zero; k + 1];
    let mut e = SubPath::start(pass, mis(pass.light_paths as f32 / CAMERA_PDF_W), 0.0, 0.0);
    for (i, sums) in eye.iter_mut().enumerate().skip(1) {
        // Segments from the pinhole, as the eye pass counts them at vertex `i`.
        e.length = i as u32;
        e.arrive(p.dist2(i - 1, i), p.cos(i, i - 1), true);
        *sums = e.sums();
        if i < k {
            e.scatter(
                &sample(p.cos(i, i + 1), p.pdf(i, i + 1)),
                p.pdf(i, i - 1),
                pass,
            );
        }
    }
    // The light subpath's, from `x[k]` back to `x[1]`.
    let mut lights = vec![zero; k + 1];
    let d_vc = if delta { 0.0 } else { mis(cos_l / emit) };
    let mut l = SubPath::start(pass, mis(direct / emit), d_vc, d_vc * pass.vc_factor);
    for j in (1..k).rev() {
        l.length = (k - j) as u32;
        l.arrive(p.dist2(j + 1, j), p.cos(j, j + 1), true);
        lights[j] = l.sums();
        if j > 1 {
            l.scatter(
                &sample(p.cos(j, j - 1), p.pdf(j, j - 1)),
                p.pdf(j, j + 1),
                pass,
            );
        }
    }
    // `E D L`, direct light at the first surface seen: NEE and BSDF sampling alone.
    let first = k == 2;
    let mut sum = 0.0;
    // The eye path hits the light.
    if !delta {
        sum += weights::hit(eye[k], direct, emit, first);
    }
    // Next-event estimation at `x[k - 1]`.
    let direct_w = direct * p.dist2(k - 1, k) / cos_l;
    let bsdf_dir = if delta { 0.0 } else { p.pdf(k - 1, k) };
    sum += weights::nee(
        pass,
        eye[k - 1],
        bsdf_dir,
        p.pdf(k - 1, k - 2),
        p.cos(k - 1, k),
        direct_w,
        emit,
        cos_l,
        first,
    );
    // Connections `x[i]` to `x[i + 1]`, where the pass has them.
    for i in (1..k - 1).filter(|_| connections) {
        let d2 = p.dist2(i, i + 1);
        sum += weights::connect(
            pass,
            eye[i],
            p.pdf(i, i + 1) * p.cos(i + 1, i) / d2,
            p.pdf(i, i - 1),
            lights[i + 1],
            p.pdf(i + 1, i) * p.cos(i, i + 1) / d2,
            p.pdf(i + 1, i + 2),
        );
    }
    if first {
        return sum;
    }
    // The light subpath joined to the camera at `x[1]`.
    let camera_pdf_a = CAMERA_PDF_W * p.cos(1, 0) / p.dist2(0, 1);
    sum += weights::camera(pass, lights[1], camera_pdf_a, p.pdf(1, 2));
    // Merging at every eye vertex but the light.
    for i in 1..k {
        sum += weights::merge(pass, eye[i], p.pdf(i, i + 1), p.pdf(i, i - 1), lights[i]);
    }
    sum
}

/// The weight sums of 50 random paths of each length and light, at each radius, for a
/// 256 x 256 image's light paths and for one (where light tracing no longer outweighs the
/// connections), with or without bidirectional connections; the largest |sum - 1|.
fn worst_sum(bidirectional: bool) -> f32 {
    let mut rng = Rng::for_index(7, 0);
    let mut worst = 0.0f32;
    let cases = [1e-4, 1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1.0]
        .into_iter()
        .flat_map(|r| [(r, N), (r, 1)]);
    for (radius, light_paths) in cases {
        let opts = Options {
            max_depth: 64,
            rr_depth: 64,
            light_paths,
            radius,
            alpha: 0.75,
            strategies: Strategies::ALL,
            bidirectional,
        };
        let pass = Pass::with(1, light_paths, opts, 0);
        for k in 2..=8 {
            for light in [Light::Area(0.5), Light::Point] {
                for _ in 0..50 {
                    let p = random_path(&mut rng, k);
                    let s = weight_sum(&p, &pass, light);
                    worst = worst.max((s - 1.0).abs());
                }
            }
        }
    }
    worst
}

#[test]
fn the_weights_of_every_strategy_sum_to_one() {
    // Measured: 1.2e-6 with connections, 1.2e-6 without (f32 rounding).
    for bidirectional in [true, false] {
        let worst = worst_sum(bidirectional);
        eprintln!("bidirectional {bidirectional}: worst |sum - 1| over 11200 paths: {worst:.2e}");
        assert!(
            worst < 1e-4,
            "bidirectional {bidirectional}: a sum is {worst} off one"
        );
    }
}

/// Without bidirectional connections, weights that still counted them (the sums built as
/// with them) would leave the connections' share out: the test above sees the difference.
/// One light path per pass and a tiny radius, so that neither light tracing (its weight
/// grows with the light paths) nor merging leaves the connections a negligible share.
#[test]
fn weights_without_connections_leave_them_out_of_the_sums() {
    let mut rng = Rng::for_index(3, 0);
    let opts = Options {
        max_depth: 64,
        rr_depth: 64,
        light_paths: 1,
        radius: 1e-4,
        alpha: 0.75,
        strategies: Strategies::ALL,
        bidirectional: true,
    };
    let with = Pass::with(1, 1, opts, 0);
    let without = Pass::with(
        1,
        1,
        Options {
            bidirectional: false,
            ..opts
        },
        0,
    );
    // Paths of 4 segments and more have bidirectional connections; with them counted in
    // the sums but not made, a path's weights fall short of one.
    let (mut short, mut lowest) = (0, 1.0f32);
    for _ in 0..200 {
        let p = random_path(&mut rng, 5);
        let full = weight_sum(&p, &with, Light::Area(0.5));
        let left = weight_sum(&p, &without, Light::Area(0.5));
        assert!((full - 1.0).abs() < 1e-4 && (left - 1.0).abs() < 1e-4);
        let mixed = weight_sum_mixed(&p, &with, Light::Area(0.5));
        short += (mixed < 1.0 - 1e-3) as u32;
        lowest = lowest.min(mixed);
    }
    eprintln!("{short} of 200 paths short of one by more than 1e-3, the lowest {lowest}");
    assert!(short > 150, "only {short} of 200 paths missed a share");
}

/// The grid's query visits exactly the points a brute-force scan finds within the radius,
/// each once: clustered points (many per cell and per bucket), and a handful whose eight
/// buckets make the cells around a query collide, at radii from far below to far above their
/// spacing, queried at points, near them and far.
#[test]
fn the_grid_finds_every_point_within_the_radius_once() {
    let mut rng = Rng::for_index(11, 0);
    let mut pt = |scale: f32| {
        let [a, b] = rng.uniform2();
        Vec3::new(a, b, rng.uniform()) * scale
    };
    let points: Vec<Vec3> = (0..3000)
        .map(|i| if i % 3 == 0 { pt(4.0) } else { pt(0.3) })
        .collect();
    let queries: Vec<Vec3> = (0..300).map(|_| pt(5.0) - Vec3::splat(0.5)).collect();
    for (points, radius) in [&points[..], &points[1..7]]
        .into_iter()
        .flat_map(|p| [1e-3f32, 0.02, 0.1, 0.5, 3.0].map(|r| (p, r)))
    {
        let grid = crate::Grid::build(points.iter().copied().zip(0..points.len()), radius);
        for &q in queries.iter().chain(&points[..6]) {
            let mut found = Vec::new();
            grid.query(q, |&i| found.push(i));
            let mut sorted = found.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(
                sorted.len(),
                found.len(),
                "a point visited twice at r {radius}"
            );
            let brute: Vec<usize> = (0..points.len())
                .filter(|&i| (points[i] - q).length_squared() <= radius * radius)
                .collect();
            assert_eq!(sorted, brute, "r {radius}, query {q}");
        }
    }
}
