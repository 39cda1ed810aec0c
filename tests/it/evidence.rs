//! The evidence command's pieces on a small worksheet image: bias and variance
//! apart from independent runs against a long path-traced reference.

use crate::kit::{TempDir, worksheet, write_worksheet};
use film::Image;
use lab::evidence::{Budget, Technique, Traces, render_image, rung};
use lab::regions::regions;
use render::Overrides;
use scene::{Method, Scene};
use std::path::{Path, PathBuf};

const RES: u32 = 48;

/// The worksheet scene at [`RES`] pixels square with seed `seed`, as the studies take it.
fn at_seed(seed: u64) -> Result<Scene, String> {
    Ok(worksheet(RES, seed))
}

fn reference(cache: &Path) -> Image {
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(4096),
        ..Overrides::default()
    };
    render_image(&worksheet(RES, 1000), &o, cache, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

#[test]
fn bias_is_zero_for_the_path_tracer_and_grows_with_k_at_the_caustic() {
    let dir = TempDir::new("evidence");
    let traces = Traces::new(dir.path().join("cache"));
    let reference = reference(traces.dir());
    let scene = worksheet(RES, 1);
    let regions = regions(&scene);
    let region = |r: &lab::evidence::RungResult, name: &str| {
        r.region(name)
            .map(|x| (x.errors, x.sums))
            .unwrap_or_else(|| panic!("no region {name}"))
    };
    let seeds = 8;
    // The path tracer is unbiased: its bias^2 estimate is what noise alone leaves after the
    // clamp at zero, plus the reference's own noise, below s^2 / K.
    let path = Technique {
        name: "path",
        overrides: Overrides {
            method: Some(Method::Path),
            ..Overrides::default()
        },
        budget: Budget::Spp,
        ladder: vec![64],
        layer: None,
    };
    let r = rung(
        &at_seed, &path, 64, seeds, &reference, &regions, &traces, None,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let (e, s) = region(&r, "image");
    eprintln!("path: {e:?} {s:?}");
    // Measured: bias^2 0.0066 against s^2 / K = 0.0105 over the image (0.63 s^2 / K).
    assert!(s.bias2 < s.variance / seeds as f64, "{s:?}");
    // bias^2 + variance is one run's error.
    assert!((s.bias2 + s.variance - s.mse).abs() < 0.1 * s.mse, "{s:?}");
    // The global map shown directly with a fixed k: at the caustic under the glass sphere
    // the disc of k photons reaches over the caustic's edge, more so the larger k.
    let gd = |k| Technique {
        name: "global map",
        overrides: Overrides {
            method: Some(Method::GlobalDirect),
            k: Some(k),
            ..Overrides::default()
        },
        budget: Budget::Photons,
        ladder: vec![200_000],
        layer: None,
    };
    let bias = |k| {
        let r = rung(
            &at_seed,
            &gd(k),
            200_000,
            4,
            &reference,
            &regions,
            &traces,
            None,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let (e, s) = region(&r, "caustic");
        eprintln!("global map k = {k}: caustic {e:?} {s:?}");
        assert!(s.pixels >= 5, "{s:?}");
        s
    };
    // Measured (relative, over the 68 caustic pixels at 48 x 48, 4 runs each): bias^2 0.026
    // at k = 50, 0.155 at k = 1000.
    let (small, large) = (bias(50), bias(1000));
    assert!(
        large.bias2 > 2.0 * small.bias2,
        "k = 50: {small:?}, k = 1000: {large:?}"
    );
}

/// The relative links of a report: `src="..."` and `href="..."` in HTML, `](...)` in Markdown.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for open in ["src=\"", "href=\"", "]("] {
        let close = if open == "](" { ')' } else { '"' };
        for (i, _) in text.match_indices(open) {
            let rest = &text[i + open.len()..];
            if let Some(end) = rest.find(close) {
                out.push(rest[..end].to_string());
            }
        }
    }
    out
}

/// Files `links` names that are missing or do not decode (PNG) or are not SVG documents.
fn broken(dir: &Path, links: &[String]) -> Vec<String> {
    links
        .iter()
        .filter(|l| {
            let p = dir.join(l);
            let ok = if l.ends_with(".png") {
                image::open(&p).is_ok_and(|i| i.width() > 0)
            } else if l.ends_with(".svg") {
                std::fs::read_to_string(&p)
                    .is_ok_and(|s| s.contains("<svg") && s.contains("</svg>"))
            } else {
                p.is_file()
            };
            // Offline and self-contained: no absolute path, no scheme, no parent directory.
            !ok || l.contains("://") || l.starts_with('/') || l.contains("..")
        })
        .cloned()
        .collect()
}

/// Chromium, if installed (`apt-get install chromium` on Debian; or set `CHROMIUM`).
fn chromium() -> Option<PathBuf> {
    std::env::var_os("CHROMIUM").map(PathBuf::from).or_else(|| {
        ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
            .iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
    })
}

/// Runs headless Chromium with `args` (the flags a sandboxed, offline machine needs), killed
/// after a minute; its standard output.
fn run_chromium(exe: &Path, profile: &Path, args: &[String]) -> String {
    let mut child = std::process::Command::new(exe)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--allow-file-access-from-files",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("{}: {e}", exe.display()));
    let t0 = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed().as_secs() > 60 {
            let _ = child.kill();
            panic!("chromium did not finish in 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let mut out = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut out).unwrap();
    out
}

#[test]
fn the_report_links_resolve_and_a_browser_shows_its_images() {
    let dir = TempDir::new("evidence-report");
    // The worksheet scene at 64 x 64, its meshes named by absolute paths.
    let scene = write_worksheet(dir.path(), "small.toml", 64, "");
    let out = dir.path().join("evidence");
    lab::evidence(&lab::evidence::EvidenceArgs {
        scene,
        reference: None,
        reference_b: None,
        reference_spp: 64,
        seeds: 2,
        quick: true,
        budget_scale: 0.02,
        only: Vec::new(),
        out: out.clone(),
        cache: dir.path().join("cache"),
        threads: None,
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let (hl, ml) = (links(&html), links(&md));
    // The reference, and per technique its image, crops and two maps; the plots.
    assert!(
        hl.len() > 60 && ml.len() > 30,
        "{} and {} links",
        hl.len(),
        ml.len()
    );
    for plot in ["error-vs-time", "regions", "k-caustic", "caustic-vs-time"] {
        assert!(
            hl.iter().any(|l| l == &format!("plots/{plot}.svg")),
            "no {plot}"
        );
    }
    assert_eq!(broken(&out, &hl), Vec::<String>::new());
    assert_eq!(broken(&out, &ml), Vec::<String>::new());
    // The check sees a missing image.
    std::fs::rename(out.join("images/reference.png"), out.join("moved.png")).unwrap();
    assert_eq!(
        broken(&out, &hl),
        vec!["images/reference.png".to_string(); 2]
    );
    std::fs::rename(out.join("moved.png"), out.join("images/reference.png")).unwrap();

    let Some(exe) = chromium() else {
        // CI sets this: there the check must run, so a missing Chromium fails it.
        assert!(
            std::env::var_os("PHOTONFLOW_REQUIRE_CHROMIUM").is_none(),
            "PHOTONFLOW_REQUIRE_CHROMIUM is set but Chromium is not installed (apt-get install \
             chromium, or set CHROMIUM): the report's browser check cannot run"
        );
        eprintln!("Chromium not installed (apt-get install chromium): browser check skipped");
        return;
    };
    // Every <img> loaded in a real browser: a copy of the page that writes the count of
    // decoded images into its title once the page has loaded.
    let probe = html.replace(
        "</body>",
        "<script>addEventListener('load', () => { const i = [...document.images]; \
         document.title = 'loaded ' + i.filter(x => x.complete && x.naturalWidth > 0).length \
         + ' of ' + i.length; });</script></body>",
    );
    std::fs::write(out.join("probe.html"), probe).unwrap();
    let profile = dir.path().join("chromium");
    let dom = run_chromium(
        &exe,
        &profile,
        &[
            "--virtual-time-budget=10000".into(),
            "--dump-dom".into(),
            format!("file://{}", out.join("probe.html").display()),
        ],
    );
    let images = html.matches("<img ").count();
    assert!(
        dom.contains(&format!("<title>loaded {images} of {images}</title>")),
        "{images} images; the page says {:?}",
        dom.lines().find(|l| l.contains("<title>"))
    );
    // And a screenshot shows them: far from a white page.
    let shot = dir.path().join("shot.png");
    run_chromium(
        &exe,
        &profile,
        &[
            "--window-size=1280,2000".into(),
            format!("--screenshot={}", shot.display()),
            format!("file://{}", out.join("report.html").display()),
        ],
    );
    let img = image::open(&shot).unwrap().to_rgb8();
    let dark = img
        .pixels()
        .filter(|p| p.0.iter().all(|&c| c < 200))
        .count();
    let share = dark as f64 / (img.width() * img.height()) as f64;
    assert!(share > 0.05, "{share} of the screenshot is dark");
}
