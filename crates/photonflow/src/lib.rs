//! `photonflow`: the one renderer binary. Each subcommand is a stage or a tool; `cargo xtask`
//! builds the binary in release and forwards a command to it (`bench <what>` as
//! `bench-<what>`, its output recorded). Errors print one line naming the file and the problem
//! and exit non-zero; nothing here panics on bad input.
//!
//! A command's or flag's help sits in its doc comment (in `cli`): the first paragraph is its
//! line in `-h`, the whole comment its `--help` (ripgrep's short and long help);
//! [`long_helps`] renders every `--help` for docs/commands.md.
//!
//! The command line lives in this library ([`run_args`]) so the end-to-end tests run every
//! command exactly as the binary does, in process; `main.rs` adds only what a process owns
//! (the Ctrl-C handler, printing the error, the exit code).

mod cli;
mod composite;
mod paths;

pub use cli::{HELP_WIDTH, command, long_helps};

use cli::{Cli, Cmd, ImageArgs, PhotonArgs};
use render::{Overrides, Photons, RenderRequest};
use scene::{Method, Scene};
use std::path::{Path, PathBuf};

/// Runs the command line `args` (the program name first) as the binary does. Returns the exit
/// code and, for a failure, the one line the binary prints on stderr (not printed here):
/// 2 for a usage error, 1 for a command that fails. Help and version go to stdout (exit 0).
pub fn run_args<I, T>(args: I) -> (u8, Option<String>)
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let parsed = command()
        .try_get_matches_from(args)
        .and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m));
    let cli = match parsed {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            let code = e.exit_code() as u8;
            // clap's own usage errors span several lines; here they are one.
            return match e.kind() {
                ErrorKind::DisplayHelp
                | ErrorKind::DisplayVersion
                | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    (code, None)
                }
                _ => {
                    let text = e.to_string();
                    let line: Vec<&str> = text
                        .lines()
                        .map(str::trim)
                        .take_while(|l| {
                            !l.starts_with("Usage:") && !l.starts_with("For more information")
                        })
                        .filter(|l| !l.is_empty())
                        .collect();
                    (code, Some(format!("{} (see --help)", line.join(" "))))
                }
            };
        }
    };
    match run(cli.cmd, &cli.define) {
        Ok(()) => (0, None),
        Err(e) => {
            // One line, whatever a library's message holds (a TOML error's excerpt, say).
            let line: Vec<&str> = e.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            (1, Some(format!("error: {}", line.join("; "))))
        }
    }
}

/// `-D` parameters, as `(name, value)`.
type Defines = [(String, String)];

fn run(cmd: Cmd, d: &Defines) -> Result<(), String> {
    let reads_defines = matches!(
        cmd,
        Cmd::Info(_)
            | Cmd::Convert(_)
            | Cmd::Render(_)
            | Cmd::Estimate(_)
            | Cmd::Trace(_)
            | Cmd::Worksheet(_)
    );
    if let (false, Some((name, _))) = (reads_defines, d.first()) {
        return Err(format!(
            "-D {name}=...: only info, convert, render, estimate, trace and worksheet read \
             scene parameters"
        ));
    }
    match cmd {
        Cmd::Info(a) => info(&a.scene, d),
        Cmd::Convert(a) => convert(&a.scene, &a.out, d),
        Cmd::BenchRays(a) => bench_rays(a),
        Cmd::Render(a) => render_command(a, d),
        Cmd::Estimate(a) => estimate(a, d),
        Cmd::Composite(cli::Composite {
            inputs,
            out,
            exposure,
        }) => composite::run(&inputs, &out, exposure),
        Cmd::Compare(a) => compare(a),
        Cmd::BenchPhotons(cli::BenchPhotons {
            scene,
            photons,
            runs,
        }) => lab::bench::photons(&scene, photons, runs),
        Cmd::BenchStore(cli::BenchStore { photons, dir }) => lab::bench::store(photons, &dir),
        Cmd::BenchSplat(cli::BenchSplat {
            scene,
            photons,
            runs,
        }) => lab::bench::splat(&scene, photons, runs),
        Cmd::BenchKnn(cli::BenchKnn { photons, queries }) => lab::bench::knn(photons, queries),
        Cmd::BenchLoad(cli::BenchLoad {
            sizes,
            runs,
            dir,
            child,
        }) => match child {
            Some(scene) => lab::bench::load_child(&scene),
            None => lab::bench::load(&sizes, runs, &dir),
        },
        Cmd::BenchPath(cli::BenchPath {
            scenes,
            spp,
            runs,
            dir,
        }) => lab::efficiency::path(&scenes, &spp, runs, &dir),
        Cmd::BenchAccuracy(a) => bench_accuracy(a),
        Cmd::Evidence(a) => evidence(a),
        Cmd::Worksheet(a) => worksheet(a, d),
        Cmd::Trace(a) => trace(a, d),
        Cmd::Merge(cli::Merge { inputs, out }) => {
            println!("{}", render::shard::merge(&inputs, &out)?);
            Ok(())
        }
    }
}

fn bench_rays(a: cli::BenchRays) -> Result<(), String> {
    let cli::BenchRays {
        scene,
        runs,
        rays,
        compare,
        ray_dir,
        peer,
    } = a;
    let peer = match &peer {
        Some(p) => Some(
            p.split_once('=')
                .ok_or_else(|| format!("--peer {p}: expected NAME=CMD"))?,
        ),
        None => None,
    };
    lab::bench::rays(&scene, runs, rays, compare, ray_dir.as_deref(), peer)
}

/// `render`: the run, or with `--shard` one shard of it.
fn render_command(a: cli::Render, d: &Defines) -> Result<(), String> {
    let cli::Render {
        scene,
        method,
        photon,
        image,
        no_caustics,
        shard,
    } = a;
    let s = load(&scene, photon.seed, d)?;
    let overrides = Overrides {
        caustics: no_caustics.then_some(false),
        ..photon.overrides(method, image.spp)
    };
    if let Some(shard) = shard {
        return render_shard(&s, &overrides, &photon, &image, shard);
    }
    let out = out_dir(&s, &overrides, &photon, image.out);
    render(
        &s,
        RenderRequest {
            overrides,
            cache: &photon.cache,
            photons: Photons::TraceOrReuse,
            threads: image.threads,
            out,
            exposure: image.exposure,
            reference: photon.reference.as_deref(),
            label: photon.label.clone(),
        },
    )
}

fn estimate(a: cli::Estimate, d: &Defines) -> Result<(), String> {
    let cli::Estimate {
        scene,
        method,
        photon,
        image,
    } = a;
    let reads_maps = |m: Method| render::methods::row(m).reads_photon_maps();
    if let Some(m) = method
        && !reads_maps(m)
    {
        return Err(format!(
            "estimate reads photon maps: use `render --method {m}` for `{m}`"
        ));
    }
    let s = load(&scene, photon.seed, d)?;
    // A scene whose method reads no photon maps gets the best photon-map method.
    let method = method.unwrap_or(match s.render().method {
        m if reads_maps(m) => m,
        _ => render::methods::ESTIMATE_DEFAULT,
    });
    let overrides = photon.overrides(Some(method), image.spp);
    let out = out_dir(&s, &overrides, &photon, image.out);
    render(
        &s,
        RenderRequest {
            overrides,
            cache: &photon.cache,
            photons: Photons::CacheOnly,
            threads: image.threads,
            out,
            exposure: image.exposure,
            reference: photon.reference.as_deref(),
            label: photon.label.clone(),
        },
    )
}

fn compare(c: cli::Compare) -> Result<(), String> {
    let cli::Compare { a, b, b2, mask } = c;
    let img = render::output::read_finite(&a, "pixels")?;
    let (text, reference) = match b2 {
        Some(b2) => {
            let (m, mean) = render::output::compare_halves(&a, &b, &b2, mask)?;
            (m.to_string(), mean)
        }
        None => (
            render::output::compare(&a, &b, mask)?.to_string(),
            render::output::read_finite(&b, "pixels")?,
        ),
    };
    let flip = render::output::compare_flip(&img, &reference, mask)
        .map_err(|e| format!("{}: {e}", a.display()))?;
    println!("{text} flip={flip:.5}");
    Ok(())
}

fn bench_accuracy(a: cli::BenchAccuracy) -> Result<(), String> {
    let cli::BenchAccuracy {
        mut case,
        suite,
        refs,
        budgets,
        methods,
        peer,
        threads,
        dir,
    } = a;
    if let Some(suite) = suite {
        case.extend(lab::accuracy::read_suite(&suite, refs.as_deref())?);
    }
    let methods = if methods.is_empty() {
        lab::accuracy::METHODS.to_vec()
    } else {
        methods
    };
    lab::accuracy::accuracy(&case, &budgets, &methods, &peer, threads, &dir)
}

fn evidence(a: cli::Evidence) -> Result<(), String> {
    let cli::Evidence {
        scene,
        reference,
        reference_b,
        reference_spp,
        seeds,
        quick,
        budget_scale,
        only,
        out,
        cache,
        threads,
    } = a;
    lab::evidence(&lab::evidence::EvidenceArgs {
        scene,
        reference,
        reference_b,
        reference_spp: reference_spp.unwrap_or(if quick {
            lab::evidence::QUICK_REFERENCE_SPP
        } else {
            lab::evidence::REFERENCE_SPP
        }),
        seeds: seeds.unwrap_or(if quick {
            lab::evidence::QUICK_SEEDS
        } else {
            lab::evidence::SEEDS
        }),
        quick,
        budget_scale,
        only,
        out,
        cache,
        threads,
    })
}

fn worksheet(a: cli::Worksheet, d: &Defines) -> Result<(), String> {
    let cli::Worksheet {
        scene,
        photons,
        k,
        topo,
        reference_spp,
        out,
        cache,
        threads,
    } = a;
    let s = load(&scene, None, d)?;
    lab::worksheet::run(
        &s,
        &lab::worksheet::WorksheetArgs {
            scene,
            photons,
            k,
            topo,
            reference_spp,
            out,
            cache,
            threads,
        },
    )
}

/// `trace`: the photon sets into the cache, or with `--shard` one shard of them.
fn trace(a: cli::Trace, d: &Defines) -> Result<(), String> {
    let cli::Trace {
        scene,
        seed,
        photons,
        cache,
        threads,
        force,
        shard,
        out,
    } = a;
    let s = load(&scene, seed, d)?;
    let overrides = Overrides {
        photons,
        ..Overrides::default()
    };
    if let Some(shard) = shard {
        let out = out.unwrap_or_else(|| paths::shard_out(&scene, "trace", shard));
        let m = render::trace_shard(&s, &overrides, shard, &out, threads)?;
        println!(
            "traced shard {shard}: photon paths {}..{} of {} in {:.2} s into {}",
            m.range[0],
            m.range[1],
            m.total,
            m.seconds,
            out.display()
        );
        return Ok(());
    }
    render::trace(&s, &overrides, &cache, threads, force).map(|_| ())
}

/// `--out`, or `out/<scene dir>-<scene stem>-<label or method>`.
fn out_dir(scene: &Scene, o: &Overrides, photon: &PhotonArgs, out: Option<PathBuf>) -> PathBuf {
    out.unwrap_or_else(|| {
        let method = o.method.unwrap_or(scene.render().method);
        let label = photon.label.clone().unwrap_or_else(|| method.name());
        paths::run_out(&scene.path, &label)
    })
}

/// `render --shard`: the shard's blocks of the run into a shard directory.
fn render_shard(
    scene: &Scene,
    overrides: &Overrides,
    photon: &PhotonArgs,
    image: &ImageArgs,
    shard: render::shard::ShardId,
) -> Result<(), String> {
    let settings = render::Settings::new(scene, overrides)?;
    let label = photon
        .label
        .clone()
        .unwrap_or_else(|| settings.method.name());
    let out = image
        .out
        .clone()
        .unwrap_or_else(|| paths::shard_out(&scene.path, &label, shard));
    let run = render::Run {
        scene,
        settings: &settings,
        cache: &photon.cache,
        photons: Photons::TraceOrReuse,
        threads: image.threads,
    };
    let m = render::shard::render(&run, shard, &out)?;
    println!(
        "rendered shard {shard} of {}: {} {} in {:.2} s into {}",
        settings.method,
        m.count,
        m.unit,
        m.seconds,
        out.display()
    );
    Ok(())
}

fn info(path: &Path, d: &Defines) -> Result<(), String> {
    print!("{}", render::describe(&load(path, None, d)?));
    Ok(())
}

/// `convert`: the scene file a Mitsuba 3 XML scene means, written whole or not at all, its
/// file names made relative to where it goes.
fn convert(xml: &Path, out: &Path, d: &Defines) -> Result<(), String> {
    if !scene::is_xml(xml) {
        return Err(format!(
            "{}: convert reads Mitsuba 3 XML scenes (.xml)",
            xml.display()
        ));
    }
    let x = scene::read_xml(xml, d).map_err(|e| e.to_string())?;
    for w in &x.warnings {
        eprintln!("warning: {w}");
    }
    let mut file = x.file;
    let from = xml.parent().unwrap_or(Path::new(""));
    let to = out.parent().unwrap_or(Path::new(""));
    // Every file name, relative to the new file.
    for name in file.file_names_mut() {
        *name = paths::relative_to(&from.join(&*name), to)?;
    }
    let text = toml::to_string(&file).map_err(|e| format!("internal error: {e}"))?;
    let text = format!(
        "# Converted by `photonflow convert` from {}: the scene file it means.\n{text}",
        xml.file_name().map_or("?".into(), |n| n.to_string_lossy())
    );
    paths::write_whole(out, text.as_bytes())?;
    println!("wrote {}", out.display());
    Ok(())
}

/// The one load of a command's scene, with `--seed` and `-D` applied.
fn load(path: &Path, seed: Option<u64>, d: &Defines) -> Result<Scene, String> {
    let scene = Scene::load_defined(path, d, |f| {
        if let Some(s) = seed {
            f.seed = s;
        }
    })
    .map_err(|e| e.to_string())?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// `render` and `estimate`: the one path through the library, then a summary line.
fn render(scene: &Scene, req: RenderRequest) -> Result<(), String> {
    let r = render::render(scene, &req)?;
    println!(
        "rendered {} in {:.2} s; wrote {}/image.{{exr,png,json}}, layers/, scene.toml",
        r.settings.method,
        r.seconds,
        r.out.display()
    );
    if let Some(m) = &r.metrics {
        println!("against the reference: {m}");
    }
    Ok(())
}
