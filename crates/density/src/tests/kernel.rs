use crate::{EstimateParams, Kernel, jensen_gaussian_mass};
use std::f64::consts::PI;

/// ∫ over the unit disc of K(|p|): a 2-D product rule in polar coordinates, midpoint in
/// angle and composite Simpson in radius (Jacobian r). Every kernel is smooth on [0, 1]
/// in t, so Simpson is accurate to ~1e-12 here; the angular rule is exact in principle
/// but K is evaluated at genuine 2-D points.
fn disc_integral(k: Kernel) -> f64 {
    let (nr, na) = (2000, 64);
    let h = 1.0 / nr as f64;
    let mut sum = 0.0;
    for j in 0..na {
        let a = (j as f64 + 0.5) * 2.0 * PI / na as f64;
        let mut ring = 0.0;
        for i in 0..=nr {
            let r = i as f64 * h;
            let (x, y) = (r * a.cos(), r * a.sin());
            let w = if i == 0 || i == nr {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            // Radius 1 is inside the (closed) support; clamp rounding just above it.
            let t = (x * x + y * y).sqrt().min(1.0);
            ring += w * k.weight(t) * r;
        }
        sum += ring * h / 3.0 * (2.0 * PI / na as f64);
    }
    sum
}

#[test]
fn every_kernel_integrates_to_one_over_the_unit_disc() {
    let kernels = Kernel::ALL
        .into_iter()
        .filter(|k| *k != Kernel::GaussianJensen)
        .chain([Kernel::Cone { k: 2.0 }, Kernel::Cone { k: 1.3 }]);
    for k in kernels {
        let i = disc_integral(k);
        assert!((i - 1.0).abs() < 1e-4, "{k:?}: ∫ = {i}");
    }
}

#[test]
fn jensens_gaussian_integrates_to_0_531_so_it_underestimates_by_47_percent() {
    let i = disc_integral(Kernel::GaussianJensen);
    assert!(
        (i - jensen_gaussian_mass()).abs() < 1e-6,
        "{i} vs {}",
        jensen_gaussian_mass()
    );
    assert!((i - 0.5311).abs() < 1e-4, "{i}");
    let under = 1.0 - i;
    assert!((under - 0.469).abs() < 1e-3, "underestimate {under}");
}

#[test]
fn kernels_vanish_outside_the_disc_and_polynomials_at_its_edge() {
    for k in Kernel::ALL {
        assert_eq!(k.weight(1.0 + 1e-9), 0.0, "{k:?}");
        assert!(k.weight(0.0) > 0.0 && k.weight(0.5) > 0.0, "{k:?}");
    }
    for k in [
        Kernel::Cone { k: 1.0 },
        Kernel::Epanechnikov,
        Kernel::Silverman,
        Kernel::Triweight,
    ] {
        assert_eq!(k.weight(1.0), 0.0, "{k:?}");
    }
    // The worksheet's Silverman kernel: 3/π at the centre.
    assert!((Kernel::Silverman.weight(0.0) - 3.0 / PI).abs() < 1e-15);
    // A cone slope below 1 would go negative: it is clamped to 1.
    assert_eq!(Kernel::Cone { k: 0.5 }.weight(1.0), 0.0);
}

#[test]
fn estimate_params_round_trip_through_toml() {
    let params = [
        EstimateParams::default(),
        EstimateParams {
            k: 250,
            r_max: 0.5,
            kernel: Kernel::Cone { k: 1.1 },
            same_side: false,
            topo: Some(0.1),
            drop_kth: true,
        },
    ];
    for p in params {
        let text = toml::to_string(&p).unwrap();
        let back: EstimateParams = toml::from_str(&text).unwrap();
        assert_eq!(back, p, "{text}");
    }
    let p: EstimateParams = toml::from_str("kernel = { kind = \"silverman\" }").unwrap();
    assert_eq!(p.kernel, Kernel::Silverman);
    assert_eq!(p.k, 50);
}

#[test]
fn kernel_names_round_trip_and_are_the_serde_kind_tags() {
    let cone = Kernel::Cone { k: 2.5 };
    for k in Kernel::ALL.into_iter().chain([cone]) {
        let name = k.to_string();
        assert_eq!(name.parse::<Kernel>(), Ok(k), "{name}");
        // The tag scene files spell: `kernel = { kind = "..." }`.
        let table = toml::Table::try_from(k).unwrap();
        let tag = table["kind"].as_str().unwrap();
        if k == cone {
            assert_eq!(name, "cone:2.5");
            assert_eq!(tag, "cone");
        } else {
            assert_eq!(name, tag, "{k:?}");
        }
    }
    assert_eq!(Kernel::Cone { k: 1.0 }.to_string(), "cone");
    assert_eq!("cone:1".parse(), Ok(Kernel::Cone { k: 1.0 }));
    assert_eq!("box".parse(), Ok(Kernel::Uniform));
    assert_eq!("simpson".parse(), Ok(Kernel::Silverman));
}

#[test]
fn unknown_kernel_names_are_refused_with_the_valid_ones_listed() {
    for bad in [
        "",
        "gauss",
        "gaussian-jensen",
        "Uniform",
        "cone:",
        "cone:0.5",
        "cone:inf",
        "cone:NaN",
        "cone:x",
        "uniform:2",
    ] {
        let err = bad.parse::<Kernel>().unwrap_err();
        for k in Kernel::ALL {
            assert!(err.contains(&k.to_string()), "{bad}: {err}");
        }
        assert!(err.contains("cone:K"), "{bad}: {err}");
    }
}
