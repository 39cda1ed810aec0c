use crate::{Class, Composite, CountKind, Input, LayerMeta, Meta, composite};
use film::Image;

/// SplitMix64: a small fixed-seed generator, enough for test noise.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

use Class::{Caustic, CausticIndirect, Direct, Emitted, Indirect};

const VIEW: &str = "0123456789abcdef";

fn meta(count: f64, kind: CountKind, layers: &[(&str, &[Class])]) -> Meta {
    Meta {
        view_hash: VIEW.into(),
        width: 4,
        height: 3,
        layers: layers
            .iter()
            .map(|&(name, classes)| LayerMeta {
                name: name.into(),
                classes: classes.to_vec(),
                count,
                count_kind: kind,
            })
            .collect(),
        seed: None,
    }
}

fn constant(rgb: [f32; 3]) -> Image {
    Image::from_fn(4, 3, |_, _| rgb)
}

fn random(rng: &mut Rng) -> Image {
    Image::from_fn(4, 3, |_, _| {
        [rng.f64() as f32, rng.f64() as f32, rng.f64() as f32]
    })
}

/// An input whose layers are random images.
fn random_input(label: &str, meta: Meta, rng: &mut Rng) -> Input {
    let layers = meta
        .layers
        .iter()
        .map(|l| (l.name.clone(), random(rng)))
        .collect();
    Input {
        label: label.into(),
        meta,
        layers,
    }
}

const PATH_LAYERS: &[(&str, &[Class])] = &[
    ("emitted", &[Emitted]),
    ("direct", &[Direct]),
    ("indirect", &[Indirect]),
    ("caustic", &[Caustic]),
    ("caustic_indirect", &[CausticIndirect]),
];
const NO_CAUSTICS: &[(&str, &[Class])] = &[
    ("emitted", &[Emitted]),
    ("direct", &[Direct]),
    ("indirect", &[Indirect]),
];
const GLOBAL_DIRECT: &[(&str, &[Class])] = &[
    ("emitted", &[Emitted]),
    ("global", &[Direct, Indirect, Caustic, CausticIndirect]),
];
const SPLATTED_CAUSTIC: &[(&str, &[Class])] = &[("caustic", &[Caustic])];

fn bits(img: &Image) -> Vec<[u32; 3]> {
    img.data
        .iter()
        .map(|p| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()])
        .collect()
}

/// Everything of a composite as bits, for bit-identity checks.
fn fingerprint(c: &Composite) -> String {
    let mut s = format!("{}\n{:?}\n", c.json(), bits(&c.image));
    for l in &c.layers {
        s += &format!(
            "{} {:?} {:x} {:?} {:?}\n",
            l.name,
            l.classes,
            l.count.to_bits(),
            l.inputs,
            bits(&l.image)
        );
    }
    s
}

fn permutations(n: usize) -> Vec<Vec<usize>> {
    if n == 0 {
        return vec![vec![]];
    }
    let mut out = Vec::new();
    for p in permutations(n - 1) {
        for i in 0..=p.len() {
            let mut q = p.clone();
            q.insert(i, n - 1);
            out.push(q);
        }
    }
    out
}

#[test]
fn weighted_average_of_two_constant_images_is_exact() {
    let a = Input {
        label: "a".into(),
        meta: meta(1.0, CountKind::Spp, &[("direct", &[Direct])]),
        layers: vec![("direct".into(), constant([1.0, 2.0, 0.5]))],
    };
    let b = Input {
        label: "b".into(),
        meta: meta(3.0, CountKind::Spp, &[("direct", &[Direct])]),
        layers: vec![("direct".into(), constant([5.0, 6.0, 0.25]))],
    };
    let c = composite(vec![a, b]).unwrap();
    // (1·1 + 3·5) / 4 = 4, (1·2 + 3·6) / 4 = 5, (1·0.5 + 3·0.25) / 4 = 0.3125: exact in f32.
    assert_eq!(c.layers.len(), 1);
    assert_eq!(c.layers[0].count, 4.0);
    assert_eq!(c.layers[0].count_kind, CountKind::Spp);
    assert_eq!(c.layers[0].inputs.len(), 2);
    assert!(
        c.layers[0]
            .image
            .data
            .iter()
            .all(|&p| p == [4.0, 5.0, 0.3125])
    );
    assert!(c.image.data.iter().all(|&p| p == [4.0, 5.0, 0.3125]));
    assert_eq!(c.json()["count"], 4);
    assert_eq!(c.json()["count_kind"], "spp");
}

#[test]
fn disjoint_layers_are_summed() {
    let mut path = meta(64.0, CountKind::Spp, NO_CAUSTICS);
    path.layers[2].classes = vec![Indirect, CausticIndirect];
    let path = Input {
        label: "path".into(),
        meta: path,
        layers: vec![
            ("emitted".into(), constant([1.0, 0.0, 0.0])),
            ("direct".into(), constant([0.5, 0.25, 0.0])),
            ("indirect".into(), constant([0.125, 0.0, 2.0])),
        ],
    };
    let splat = Input {
        label: "splat".into(),
        meta: meta(1e6, CountKind::PhotonPaths, SPLATTED_CAUSTIC),
        layers: vec![("caustic".into(), constant([0.0, 4.0, 0.0625]))],
    };
    let c = composite(vec![splat, path]).unwrap();
    assert!(c.image.data.iter().all(|&p| p == [1.625, 4.25, 2.0625]));
    assert!(c.missing.is_empty());
    // Layers in canonical class order, each with its own weight.
    let names: Vec<&str> = c.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["emitted", "direct", "indirect", "caustic"]);
    assert_eq!(c.layers[2].classes, [Indirect, CausticIndirect]);
    assert_eq!(
        (c.layers[3].count, c.layers[3].count_kind),
        (1e6, CountKind::PhotonPaths)
    );
    assert_eq!(
        (c.layers[0].count, c.layers[0].count_kind),
        (64.0, CountKind::Spp)
    );
    // Mixed weights: no top-level count, every layer in layer_counts.
    let j = c.json();
    assert!(j.get("count").is_none() && j.get("count_kind").is_none());
    assert_eq!(j["layer_counts"]["caustic"]["count"], 1_000_000);
    assert_eq!(j["layer_counts"]["caustic"]["count_kind"], "photon_paths");
    assert_eq!(j["layer_counts"]["direct"]["count_kind"], "spp");
}

#[test]
fn uncovered_classes_are_reported_missing() {
    let mut rng = Rng(7);
    let c = composite(vec![random_input(
        "path",
        meta(16.0, CountKind::Spp, NO_CAUSTICS),
        &mut rng,
    )])
    .unwrap();
    assert_eq!(c.missing, [Caustic, CausticIndirect]);
    assert_eq!(
        c.json()["missing"],
        serde_json::json!(["caustic", "caustic_indirect"])
    );
    let c = composite(vec![random_input(
        "global",
        meta(16.0, CountKind::Spp, GLOBAL_DIRECT),
        &mut rng,
    )])
    .unwrap();
    assert!(c.missing.is_empty());
    let c = composite(vec![random_input(
        "splat",
        meta(1e5, CountKind::PhotonPaths, SPLATTED_CAUSTIC),
        &mut rng,
    )])
    .unwrap();
    assert_eq!(c.missing, [Emitted, Direct, Indirect, CausticIndirect]);
}

#[test]
fn every_permutation_gives_bit_identical_output() {
    let mut rng = Rng(42);
    let inputs = vec![
        random_input("a", meta(16.0, CountKind::Spp, NO_CAUSTICS), &mut rng),
        random_input("b", meta(64.0, CountKind::Spp, NO_CAUSTICS), &mut rng),
        random_input("c", meta(3.0, CountKind::Spp, NO_CAUSTICS), &mut rng),
        random_input(
            "d",
            meta(1e6, CountKind::PhotonPaths, SPLATTED_CAUSTIC),
            &mut rng,
        ),
    ];
    let reference = fingerprint(&composite(inputs.clone()).unwrap());
    for p in permutations(inputs.len()) {
        let given: Vec<Input> = p.iter().map(|&i| inputs[i].clone()).collect();
        assert_eq!(
            fingerprint(&composite(given).unwrap()),
            reference,
            "order {p:?}"
        );
    }
}

/// f64 sums round differently in different orders; after the division the f32 rounding
/// usually hides that, but not at a tie. Pixel (0, 0) is built so that its exact mean is an
/// f32 tie, `1 + 2^-24`, and two tiny terms `3·2^-53` vanish or not depending on whether
/// they are added before or after the large ones. A composite that accumulates in the
/// given order fails here.
#[test]
fn every_permutation_gives_bit_identical_output_at_a_rounding_tie() {
    let tiny = 3.0 * 2f32.powi(-53);
    let pixel0 = [2.0 + 2f32.powi(-22), 2.0, tiny, tiny];
    let mut rng = Rng(3);
    let inputs: Vec<Input> = (0..4)
        .map(|k| {
            let mut img = random(&mut rng);
            img.data[0] = [pixel0[k]; 3];
            Input {
                label: format!("run{k}"),
                meta: meta(1.0, CountKind::Spp, &[("direct", &[Direct])]),
                layers: vec![("direct".into(), img)],
            }
        })
        .collect();
    // The case is sensitive: accumulating in the given order depends on the order.
    let naive: std::collections::BTreeSet<u32> = permutations(4)
        .iter()
        .map(|p| {
            let s = p.iter().fold(0.0f64, |acc, &i| acc + f64::from(pixel0[i]));
            ((s / 4.0) as f32).to_bits()
        })
        .collect();
    assert!(naive.len() > 1, "the test case does not expose the order");

    let reference = fingerprint(&composite(inputs.clone()).unwrap());
    for p in permutations(inputs.len()) {
        let given: Vec<Input> = p.iter().map(|&i| inputs[i].clone()).collect();
        assert_eq!(
            fingerprint(&composite(given).unwrap()),
            reference,
            "order {p:?}"
        );
    }
}

/// An estimate from `samples` samples: per element the mean of `samples` draws of
/// `truth + u - 1/2` (variance `1/(12 samples)`).
fn noisy(rng: &mut Rng, w: usize, h: usize, truth: f64, samples: u32) -> Image {
    Image::from_fn(w, h, |_, _| {
        let mut p = [0.0f32; 3];
        for v in &mut p {
            let s: f64 = (0..samples).map(|_| rng.f64() - 0.5).sum();
            *v = (truth + s / f64::from(samples)) as f32;
        }
        p
    })
}

fn mse(img: &Image, truth: f64) -> f64 {
    let n = img.data.len() * 3;
    img.data
        .iter()
        .flatten()
        .map(|&v| (f64::from(v) - truth).powi(2))
        .sum::<f64>()
        / n as f64
}

/// Averages estimates of `counts[i]` samples each; returns (MSE of the composite, MSE of
/// the first input, number of elements).
fn averaged_mse(seed: u64, counts: &[u32]) -> (f64, f64, usize) {
    let (w, h, truth) = (64, 64, 1.0);
    let mut rng = Rng(seed);
    let inputs: Vec<Input> = counts
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let mut m = meta(f64::from(c), CountKind::Spp, &[("indirect", &[Indirect])]);
            (m.width, m.height) = (w, h);
            Input {
                label: format!("run{k}"),
                meta: m,
                layers: vec![("indirect".into(), noisy(&mut rng, w, h, truth, c))],
            }
        })
        .collect();
    let first = mse(&inputs[0].layers[0].1, truth);
    let c = composite(inputs).unwrap();
    (mse(&c.image, truth), first, w * h * 3)
}

#[test]
fn averaging_k_estimates_divides_the_variance_by_k() {
    const K: usize = 8;
    let sigma2 = 1.0 / 12.0;
    let (avg, single, n) = averaged_mse(11, &[1; K]);
    // The MSE over n elements has a relative standard error of at most sqrt(2/n) (kurtosis
    // <= 3 for means of uniforms); allow 4 of them.
    let tol = 4.0 * (2.0 / n as f64).sqrt();
    let ratio = avg / (sigma2 / K as f64);
    assert!(
        (ratio - 1.0).abs() < tol,
        "variance ratio {ratio}, tolerance {tol}"
    );
    let reduction = single / avg;
    assert!(
        (reduction / K as f64 - 1.0).abs() < 1.5 * tol,
        "variance reduced {reduction}x by {K} estimates"
    );
}

/// Estimates of unequal counts: weighting by count gives variance `σ²/Σc`; an unweighted
/// mean would give `σ²/K² · Σ 1/c`, 45% more here.
#[test]
fn weighting_by_count_gives_the_variance_of_all_samples() {
    let counts = [1, 2, 3, 4, 6];
    let total: u32 = counts.iter().sum();
    let (avg, _, n) = averaged_mse(12, &counts);
    let tol = 4.0 * (2.0 / n as f64).sqrt();
    let ratio = avg / (1.0 / 12.0 / f64::from(total));
    assert!(
        (ratio - 1.0).abs() < tol,
        "variance ratio {ratio}, tolerance {tol}"
    );
}

/// The expected refusal: an error of one line that names `label` and contains `problem`,
/// whatever the order of the inputs.
fn refused(inputs: Vec<Input>, label: &str, problem: &str) {
    let forward = composite(inputs.clone()).expect_err(problem);
    let mut reversed = inputs;
    reversed.reverse();
    let backward = composite(reversed).expect_err(problem);
    assert_eq!(
        forward, backward,
        "the error depends on the order of the inputs"
    );
    assert!(!forward.contains('\n'), "{forward}");
    assert!(
        forward.contains(label) && forward.contains(problem),
        "expected `{label}` and `{problem}` in: {forward}"
    );
}

fn direct(label: &str, count: f64, rgb: [f32; 3]) -> Input {
    Input {
        label: label.into(),
        meta: meta(count, CountKind::Spp, &[("direct", &[Direct])]),
        layers: vec![("direct".into(), constant(rgb))],
    }
}

#[test]
fn refusals_name_the_input_and_the_problem() {
    let good = || direct("good/run", 4.0, [1.0; 3]);
    let bad = |f: &dyn Fn(&mut Input)| {
        let mut i = direct("bad/run", 2.0, [0.5; 3]);
        f(&mut i);
        i
    };

    assert_eq!(composite(vec![]).unwrap_err(), "composite: no inputs");

    let cases: Vec<(&str, Input)> = vec![
        (
            "not the same view",
            bad(&|i| i.meta.view_hash = "fedcba9876543210".into()),
        ),
        (
            "x3 differs from ",
            bad(&|i| {
                i.meta.width = 5;
                i.layers[0].1 = Image::new(5, 3);
            }),
        ),
        (
            "layer 'direct' is 4x2 but image.json says 4x3",
            bad(&|i| i.layers[0].1 = Image::new(4, 2)),
        ),
        (
            "holds 11 pixels",
            bad(&|i| {
                i.layers[0].1.data.pop();
            }),
        ),
        (
            "pixel (1, 2) is NaN",
            bad(&|i| i.layers[0].1.set(1, 2, [0.0, f32::NAN, 0.0])),
        ),
        (
            "pixel (3, 0) is infinite",
            bad(&|i| i.layers[0].1.set(3, 0, [f32::INFINITY, 0.0, 0.0])),
        ),
        (
            "count 0 must be positive",
            bad(&|i| i.meta.layers[0].count = 0.0),
        ),
        (
            "count -1 must be positive",
            bad(&|i| i.meta.layers[0].count = -1.0),
        ),
        (
            "count inf must be positive and finite",
            bad(&|i| i.meta.layers[0].count = f64::INFINITY),
        ),
        (
            "count NaN must be positive and finite",
            bad(&|i| i.meta.layers[0].count = f64::NAN),
        ),
        (
            "count 1e300 exceeds 2^53",
            bad(&|i| i.meta.layers[0].count = 1e300),
        ),
        (
            "cannot weigh them together",
            bad(&|i| i.meta.layers[0].count_kind = CountKind::PhotonPaths),
        ),
        (
            "estimates [direct",
            bad(&|i| i.meta.layers[0].classes = vec![Direct, Indirect]),
        ),
        (
            "estimates too: double counting",
            bad(&|i| {
                i.meta.layers[0].name = "global".into();
                i.meta.layers[0].classes = vec![Indirect, Direct];
                i.layers[0].0 = "global".into();
            }),
        ),
        (
            "both estimate class direct: double counting",
            bad(&|i| {
                i.meta.layers.push(LayerMeta {
                    name: "global".into(),
                    classes: vec![Direct, Indirect],
                    count: 2.0,
                    count_kind: CountKind::Spp,
                });
                i.layers.push(("global".into(), constant([0.0; 3])));
            }),
        ),
        ("layer 'direct' has no image", bad(&|i| i.layers.clear())),
        (
            "layer image 'extra' is not listed",
            bad(&|i| i.layers.push(("extra".into(), constant([0.0; 3])))),
        ),
        (
            "layer image 'direct' is given twice",
            bad(&|i| i.layers.push(("direct".into(), constant([0.0; 3])))),
        ),
        (
            "layer 'direct' estimates no class",
            bad(&|i| i.meta.layers[0].classes.clear()),
        ),
        (
            "lists class direct twice",
            bad(&|i| i.meta.layers[0].classes.push(Direct)),
        ),
        (
            "layer name '../x' is not a file name",
            bad(&|i| {
                i.meta.layers[0].name = "../x".into();
                i.layers[0].0 = "../x".into();
            }),
        ),
        ("view_hash is empty", bad(&|i| i.meta.view_hash.clear())),
        ("no layers", bad(&|i| i.meta.layers.clear())),
        (
            "are bit-identical to those of",
            bad(&|i| {
                *i = Input {
                    label: "bad/run".into(),
                    ..good()
                }
            }),
        ),
    ];
    for (problem, input) in cases {
        refused(vec![good(), input], "bad/run", problem);
    }
    // Each count within bounds, their sum not: the composite's own image.json could not be
    // read back (2^53 + 2^53 = 2^54).
    let big = |label: &str, v: f32| direct(label, 9_007_199_254_740_992.0, [v; 3]);
    let e = composite(vec![big("a/run", 1.0), big("b/run", 2.0)]).unwrap_err();
    assert!(
        e.contains("layer 'direct': the counts sum to 18014398509481984, beyond 2^53"),
        "{e}"
    );
}

const EXAMPLE: &str = r#"{ "view_hash": "0123456789abcdef",
  "width": 4, "height": 3, "method": "path", "time_s": 1.5,
  "count": 64, "count_kind": "spp",
  "layers": { "emitted": ["emitted"], "direct": ["direct"],
              "indirect": ["indirect", "caustic_indirect"], "caustic": ["caustic"] } }"#;

#[test]
fn meta_reads_the_image_json_contract() {
    let m = Meta::from_json(EXAMPLE).unwrap();
    assert_eq!(m.view_hash, VIEW);
    assert_eq!((m.width, m.height), (4, 3));
    let layers: Vec<(&str, &[Class], f64, CountKind)> = m
        .layers
        .iter()
        .map(|l| (l.name.as_str(), &l.classes[..], l.count, l.count_kind))
        .collect();
    assert_eq!(
        layers,
        [
            ("caustic", &[Caustic][..], 64.0, CountKind::Spp),
            ("direct", &[Direct][..], 64.0, CountKind::Spp),
            ("emitted", &[Emitted][..], 64.0, CountKind::Spp),
            (
                "indirect",
                &[Indirect, CausticIndirect][..],
                64.0,
                CountKind::Spp
            ),
        ]
    );
    // layer_counts overrides the top-level weight per layer.
    let m = Meta::from_json(
        r#"{"view_hash":"ab","width":1,"height":1,"layers":{"caustic":["caustic"]},
            "layer_counts":{"caustic":{"count":1000000,"count_kind":"photon_paths"}}}"#,
    )
    .unwrap();
    assert_eq!(m.layers[0].count, 1e6);
    assert_eq!(m.layers[0].count_kind, CountKind::PhotonPaths);
}

#[test]
fn meta_refuses_bad_image_json() {
    let with = |from: &str, to: &str| {
        assert!(EXAMPLE.contains(from));
        EXAMPLE.replace(from, to)
    };
    let cases = [
        (
            with(r#""caustic"]"#, r#""caustics"]"#),
            "unknown class \"caustics\"",
        ),
        (
            with(r#""spp""#, r#""samples""#),
            "count_kind \"samples\" is unknown",
        ),
        (
            with(r#", "count_kind": "spp""#, ""),
            "count_kind is missing",
        ),
        (
            with(r#""count": 64"#, r#""count": 0"#),
            "count 0 must be positive",
        ),
        (
            with(r#""count": 64"#, r#""count": -2"#),
            "count -2 must be positive",
        ),
        (
            with(r#""count": 64"#, r#""count": "64""#),
            "count \"64\" is not a number",
        ),
        (with(r#""count": 64"#, r#""count": 1e999"#), "invalid JSON"),
        // Finite, but it would weigh every other run of its layers down to 1e-300.
        (
            with(r#""count": 64"#, r#""count": 1e300"#),
            "count 1e300 exceeds 2^53 = 9007199254740992",
        ),
        (
            with(r#""count": 64"#, r#""count": 9007199254740993.0"#),
            "exceeds 2^53",
        ),
        (
            with(r#""count": 64, "count_kind": "spp","#, ""),
            "count and count_kind are missing",
        ),
        (
            with(r#""view_hash": "0123456789abcdef","#, ""),
            "view_hash is missing",
        ),
        (
            with(r#""width": 4"#, r#""width": 4.5"#),
            "width 4.5 is not a non-negative integer",
        ),
        (
            with(r#""height": 3"#, r#""height": 0"#),
            "size 4x0 is empty",
        ),
        (
            with(
                r#""caustic": ["caustic"]"#,
                r#""caustic": ["caustic", "direct"]"#,
            ),
            "both estimate class direct: double counting",
        ),
        (
            with(r#""caustic": ["caustic"]"#, r#""caustic": []"#),
            "estimates no class",
        ),
        (
            with(r#""caustic": ["caustic"]"#, r#""caustic": "caustic""#),
            "are not a list",
        ),
        ("[1, 2]".to_string(), "not a JSON object"),
    ];
    for (text, problem) in cases {
        let e = Meta::from_json(&text).expect_err(problem);
        assert!(
            e.contains(problem) && !e.contains('\n'),
            "expected `{problem}` in: {e}"
        );
        // Input::new names the input.
        let e = Input::new("runs/x/image.json", &text, vec![]).expect_err(problem);
        assert!(e.starts_with("runs/x/image.json: "), "{e}");
    }
}

#[test]
fn a_composite_can_be_composited_again() {
    let mut rng = Rng(5);
    let a = random_input("a", meta(16.0, CountKind::Spp, PATH_LAYERS), &mut rng);
    let b = random_input("b", meta(48.0, CountKind::Spp, PATH_LAYERS), &mut rng);
    let c = random_input("c", meta(64.0, CountKind::Spp, PATH_LAYERS), &mut rng);
    let all = composite(vec![a.clone(), b.clone(), c.clone()]).unwrap();
    let ab = composite(vec![a, b]).unwrap();
    // Its image.json reads back as its meta.
    let text = serde_json::to_string_pretty(&ab.json()).unwrap();
    assert_eq!(Meta::from_json(&text).unwrap(), ab.meta());
    assert_eq!(ab.json()["count"], 64);
    let again = composite(vec![ab.into_input("ab"), c]).unwrap();
    assert_eq!(again.meta(), all.meta());
    for (x, y) in again.layers.iter().zip(&all.layers) {
        assert_eq!(x.name, y.name);
        for (p, q) in x.image.data.iter().zip(&y.image.data) {
            for k in 0..3 {
                // One extra f32 rounding of the partial average.
                assert!(
                    (p[k] - q[k]).abs() <= 2.0 * f32::EPSILON * q[k].abs(),
                    "{p:?} {q:?}"
                );
            }
        }
    }
}

#[test]
fn runs_sharing_a_seed_are_not_averaged() {
    let seeded = |label: &str, seed: u64, rgb: [f32; 3]| {
        let mut i = direct(label, 2.0, rgb);
        i.meta.seed = Some(seed);
        i
    };
    // The message names both runs, whichever sorts first.
    let both = vec![
        seeded("first/run", 7, [1.0; 3]),
        seeded("second/run", 7, [2.0; 3]),
    ];
    refused(both.clone(), "first/run", "seed 7");
    refused(both, "second/run", "seed 7");
    // Distinct seeds are independent runs: averaged.
    let c = composite(vec![seeded("a", 7, [1.0; 3]), seeded("b", 8, [2.0; 3])]).unwrap();
    assert_eq!(c.image.get(0, 0), [1.5; 3]);
    // One seed on disjoint layers is fine: nothing is averaged.
    let mut e = seeded("e", 7, [1.0; 3]);
    e.meta.layers[0].name = "emitted".into();
    e.meta.layers[0].classes = vec![Emitted];
    e.layers[0].0 = "emitted".into();
    composite(vec![seeded("a", 7, [1.0; 3]), e]).unwrap();
}

#[test]
fn shard_ranges_partition_the_indices_and_blocks_stay_whole() {
    use crate::shards::ShardId;
    for total in [0u64, 1, 7, 30_000, u64::MAX / 3] {
        for n in 1..=9 {
            let mut end = 0;
            for i in 0..n {
                let r = ShardId { index: i, count: n }.range(total);
                assert_eq!(r.start, end, "{i}/{n} of {total}");
                assert!(r.end - r.start <= total / n as u64 + 1);
                end = r.end;
            }
            assert_eq!(end, total);
        }
    }
    // The path tracer's passes of 16 samples: 1, 1, 2, 2, ... Seven shards own disjoint,
    // consecutive runs of whole blocks covering all of them.
    let starts = [0u64, 1, 2, 4, 6, 8, 10, 12, 14, 16];
    let blocks: Vec<_> = starts.windows(2).map(|w| w[0]..w[1]).collect();
    let mut next = 0;
    for i in 0..7 {
        let b = ShardId { index: i, count: 7 }.blocks(&blocks, 16);
        assert_eq!(b.start, next);
        next = b.end;
    }
    assert_eq!(next, blocks.len());
    assert_eq!(ShardId::parse("2/7"), Ok(ShardId { index: 2, count: 7 }));
    for bad in ["7/7", "1", "-1/3", "a/b", "0/0"] {
        assert!(ShardId::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn a_shard_set_is_refused_unless_it_covers_every_index_once() {
    use crate::shards::{Part, ShardId, cover};
    let part = |label: &str, index, count| {
        let shard = ShardId { index, count };
        Part {
            label: label.into(),
            shard,
            range: shard.range(100),
        }
    };
    let expect = |s: ShardId| s.range(100);
    let order = cover(
        &[part("c", 2, 3), part("a", 0, 3), part("b", 1, 3)],
        100,
        &expect,
    );
    assert_eq!(order, Ok(vec![1, 2, 0]));
    let refusal = |parts: &[Part]| cover(parts, 100, &expect).unwrap_err();
    let e = refusal(&[part("a", 0, 3), part("c", 2, 3)]);
    assert!(e.starts_with("c: ") && e.contains("missing (1/3)"), "{e}");
    let e = refusal(&[part("a", 0, 3), part("b", 1, 3)]);
    assert!(e.starts_with("b: ") && e.contains("missing (2/3)"), "{e}");
    let e = refusal(&[part("a", 0, 2), part("b", 1, 2), part("b2", 1, 2)]);
    assert!(e.starts_with("b2: ") && e.contains("duplicates b"), "{e}");
    let e = refusal(&[part("a", 0, 2), part("x", 1, 3), part("y", 2, 3)]);
    assert!(e.starts_with("x: ") && e.contains("overlaps a"), "{e}");
    let mut forged = part("f", 1, 2);
    forged.range = 40..100;
    let e = refusal(&[part("a", 0, 2), forged]);
    assert!(
        e.starts_with("f: ") && e.contains("should cover 50..100"),
        "{e}"
    );
}
