//! Hand-rolled argument parsing: xtask keeps no dependencies so it compiles in seconds.

pub const HELP: &str = "\
cargo xtask <command>   (the photonflow commands build the `photonflow` binary with the
                         release-lto profile, the one benchmarks measure, and run it;
                         `photonflow <command> --help` has every option and the details)

  render SCENE [--method path|global-direct|final-gather|caustic-splat|path+splat|sppm|light|vcm]
               [--spp N] [--passes N] [--time S] [--threads N] [--out DIR]
                      render with a progress bar; writes image.exr, image.png, layers/, image.json
                      and scene.toml (the resolved scene: renders the same image again).
                      path: the path-traced reference (--no-caustics leaves out L S+ D light);
                      the photon methods chain trace (or reuse the cache) -> estimate -> composite;
                      sppm, light, vcm and the splatting methods run in passes (--passes, --time) and
                      write snapshots at 1, 2, 4, ... passes;
                      without --method: the scene's render.method (default vcm)
  trace SCENE [--photons N] [--cache DIR] [--threads N] [--force]
                      trace the photon sets the scene's effects plan asks for into the cache,
                      or reuse them when the scene and parameters are unchanged
  estimate SCENE [--method global-direct|final-gather] [--k N] [--kernel K] [--topo EPS]
                 [--boundary] [--drop-kth] [--reference EXR]
                      estimate from the cached photon sets only (never traces);
                      without --method: the scene's render.method when it reads photon
                      maps, else the best of them (default final-gather)
  worksheet [--photons N] [--k N] [--topo EPS] [--reference-spp N]
                      worksheet 7's images (box kernel, Silverman, + topological test,
                      + boundary correction) with errors against a path-traced reference,
                      summarised in out/worksheet/README.md
  evidence [SCENE] [--quick] [--seeds K] [--budget-scale F] [--only NAME]... [--reference EXR]
           [--reference-spp N]
                      each technique over a ladder of budgets, K seeds each, against a
                      reference: relMSE (two conventions), RMSE, mean ratio, FLIP, bias^2 and
                      variance per region (caustic, edges and corners, outer rim, glass sphere,
                      open walls), the k sweep; the lab report out/evidence/report.html and
                      report.md with images, crops, maps and SVG plots; evidence.md, evidence.json;
                      --quick: about 2 minutes, at most 256 pixels on a side, 4 seeds, a 512-spp
                      reference, two budgets per technique, k in {50, 250, 1000}
  composite RUN... --out DIR
                      combine runs of one view: layers of one name averaged by their counts,
                      disjoint layers summed (independent runs: other --seed)
  merge SHARD... --out DIR
                      put the shards of one run (trace/render --shard I/N --out SHARD) back
                      together: the one-machine photon files (DIR: a cache) or image, byte
                      for byte; refuses missing, duplicated, overlapping or foreign shards
  compare A.exr B.exr [B2.exr] [--mask x0,y0,x1,y1]
                      RMSE, relative MSE, mean absolute error and FLIP of A against reference B;
                      B2, the reference's second independent half, takes its noise out
  info SCENE          load a scene and print what it holds
  convert SCENE.xml --out SCENE.toml
                      the scene file a Mitsuba 3 XML scene means (files referenced)
  bench ...           updates docs/benchmarks.md: each benchmark builds with the release-lto
                      profile, echoes its output and records it (command, date, machine) as
                      its own section, replacing that section's previous run
  bench rays [SCENE] [--runs N] [--compare] [--ray-dir DIR] [--peer NAME=CMD]
                      single-thread rays/s: 1M coherent camera rays and 1M incoherent rays
                      (default scene: scenes/cornell-spheres/tessellated.toml);
                      --compare also measures obvhs' CwBvh next to the default BVH4;
                      --ray-dir casts a peer's saved rays, --peer times the peer alternately
                      (run under `taskset -c N` so both share one core)
  bench photons [SCENE] [--photons N] [--runs N]
                      photon paths/s on 1 and 2 threads (tracing alone and into photon files)
  bench store [--photons N]
                      write/read GB/s of a 10M-photon file; plain records against bincode
  bench splat [SCENE] [--photons N] [--runs N]
                      caustic photons splatted per second on 1 and 2 threads, eye vertices,
                      peak memory (default scene: scenes/cornell-spheres/analytic.toml)
  bench accuracy [--case SCENE.toml,REF_A.exr,REF_B.exr]... [--suite FILE] [--refs DIR]
                 [--budgets 2,5,15,60] [--methods M,...] [--threads N]
                 [--peer NAME | --peer NAME=CMD]...
                      photonflow's sppm, vcm, path+splat, path and light and the peers at fixed
                      time budgets, in one run: the relative MSE of each image against the
                      scene's two reference halves, the reference's noise taken out; per
                      budget the best of each side, the error ratio and photonflow's time to
                      the best peer's error over the peer's time. Without --case, the suite
                      scenes/bench-accuracy.toml (its references under --refs DIR). Peers:
                      tests/references/peer.sh's mitsuba, mitsuba-ptracer, luxcore, cycles,
                      smallvcm-ppm, smallvcm-bpt, smallvcm-vcm (set PEERS, PEERS_VENV, BPY_VENV), or shell
                      commands writing an EXR to $OUT (also given $SCENE, $BUDGET)
  bench load [--sizes 100000,1000000,4000000] [--runs N] [--dir DIR]
                      load time (parse, BVH) and peak memory of generated meshes, each load a
                      fresh process; Mitsuba 3 beside it in the same run when PEERS_VENV is set
  bench path [--scenes A.toml,B.toml] [--spp 64,256] [--runs N] [--dir DIR]
                      the path tracer's efficiency 1/(relMSE x seconds) against Mitsuba 3's
                      at equal spp (worksheet and McGuire's Original box by default): runs
                      alternating, each a fresh process, the noise measured between runs
                      (Mitsuba beside it when PEERS and PEERS_VENV are set)
  bench knn [--photons N] [--queries N]
                      k-NN queries/s for k = 50, 250, 1000 per index (kd-tree, kiddo, brute),
                      and pixel-order irradiance queries with radius hints
  slurm-demo          as root: install Slurm (Debian's slurm-wlm, munge) if missing, start a
                      one-node cluster in a temporary directory, render an array of 4 shards
                      and their merge (deploy/slurm/), check the result against a one-machine
                      run byte for byte, stop the daemons
  gen-scenes          rewrite the generated OBJ/MTL files of scenes/cornell-spheres
  fuzz [--seconds N] [--target obj|mtl|ply|ply-ascii|scene|photons|exr] [--seed S]
                      mutate valid files and feed them to each loader for N seconds per target
                      (default 60; `cargo test` runs 3000 cases each): any panic, hang or
                      allocation sized by a header field fails, with the input saved
";

pub enum Cmd {
    Help,
    GenScenes,
    /// Slurm on this machine: shards, merge, checked against a one-machine run.
    SlurmDemo,
    /// The fuzz loops (`tests/bin/fuzz.rs`), with these arguments.
    Fuzz(Vec<String>),
    /// Arguments passed straight to the photonflow binary (`release-lto` build).
    Photonflow(Vec<String>),
    /// A benchmark: built with the `release-lto` profile, its output recorded in
    /// docs/benchmarks.md.
    Bench(Bench),
}

pub struct Bench {
    /// `rays`, `photons`, `store` or `knn`: names the section of docs/benchmarks.md.
    pub what: String,
    /// The arguments after `cargo xtask bench`, as typed, for the record.
    pub typed: Vec<String>,
    /// The photonflow command line: `bench-<what>`, the default scene if none was given, and
    /// the rest.
    pub args: Vec<String>,
}

/// The commands passed to the photonflow binary under their own name.
pub const FORWARDED: &[&str] = &[
    "info",
    "convert",
    "render",
    "compare",
    "composite",
    "trace",
    "estimate",
    "worksheet",
    "evidence",
    "merge",
];

/// `bench <what>`: the binary's `bench-<what>`, its output recorded in docs/benchmarks.md.
pub const BENCHES: &[&str] = &[
    "rays", "photons", "store", "knn", "splat", "accuracy", "load", "path",
];

/// The commands xtask runs itself. `parse` matches each by name, so only the tests read the
/// list: its own test holds it to `parse` and the help, photonflow's to README's table.
#[cfg(test)]
pub const OWN: &[&str] = &["gen-scenes", "slurm-demo", "fuzz"];

pub const DEFAULT_SCENE: &str = "scenes/cornell-spheres/tessellated.toml";
pub const SPLAT_SCENE: &str = "scenes/cornell-spheres/analytic.toml";
pub const ACCURACY_SUITE: &str = "scenes/bench-accuracy.toml";

pub fn parse(args: &[String]) -> Result<Cmd, String> {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    match a.as_slice() {
        [] | ["help" | "-h" | "--help", ..] => Ok(Cmd::Help),
        // xtask's own commands and `bench` alone: the help, which lists them.
        [
            "gen-scenes" | "slurm-demo" | "fuzz" | "bench",
            "-h" | "--help",
            ..,
        ] => Ok(Cmd::Help),
        ["gen-scenes"] => Ok(Cmd::GenScenes),
        ["slurm-demo"] => Ok(Cmd::SlurmDemo),
        ["fuzz", rest @ ..] => Ok(Cmd::Fuzz(rest.iter().map(|s| s.to_string()).collect())),
        [cmd, rest @ ..] if FORWARDED.contains(cmd) => Ok(Cmd::Photonflow(
            std::iter::once(*cmd)
                .chain(rest.iter().copied())
                .map(String::from)
                .collect(),
        )),
        // A benchmark's own help: photonflow's, with nothing recorded.
        ["bench", what, rest @ ..]
            if BENCHES.contains(what) && rest.iter().any(|s| matches!(*s, "-h" | "--help")) =>
        {
            Ok(Cmd::Photonflow(
                std::iter::once(format!("bench-{what}"))
                    .chain(rest.iter().map(|s| s.to_string()))
                    .collect(),
            ))
        }
        ["bench", what, rest @ ..] if BENCHES.contains(what) => {
            let mut out = vec![format!("bench-{what}")];
            // The scene benchmarks take a scene first; without one, the worksheet's.
            if rest.first().is_none_or(|s| s.starts_with("--")) {
                match *what {
                    "rays" | "photons" => out.push(DEFAULT_SCENE.into()),
                    // Splatting measures the worksheet scene with exact spheres.
                    "splat" => out.push(SPLAT_SCENE.into()),
                    _ => {}
                }
            }
            // Accuracy takes cases; without any, the committed suite's.
            let given = |f: &str| {
                rest.iter()
                    .any(|s| *s == f || s.starts_with(&format!("{f}=")))
            };
            if *what == "accuracy" && !given("--case") && !given("--suite") {
                out.extend(["--suite".into(), ACCURACY_SUITE.into()]);
            }
            out.extend(rest.iter().map(|s| s.to_string()));
            Ok(Cmd::Bench(Bench {
                what: what.to_string(),
                typed: args[1..].to_vec(),
                args: out,
            }))
        }
        ["bench", rest @ ..] => Err(format!(
            "bench: {}; name one of {}\n\n{HELP}",
            rest.first()
                .map_or("which benchmark?".to_string(), |w| format!(
                    "`{w}` is not a benchmark"
                )),
            BENCHES.join(", ")
        )),
        [other, ..] => Err(format!("unknown command `{other}`\n\n{HELP}")),
    }
}
