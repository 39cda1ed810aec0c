//! The command line's definition: every command's flags and help, by command family, and the
//! `clap::Command` built from them with the method table's help filled in.

mod bench;
mod parse;
mod rendering;
mod studies;
mod tools;

pub(crate) use bench::{
    BenchAccuracy, BenchKnn, BenchLoad, BenchPath, BenchPhotons, BenchRays, BenchSplat, BenchStore,
};
pub(crate) use rendering::{Estimate, ImageArgs, Merge, PhotonArgs, Render, Trace};
pub(crate) use studies::{Evidence, Worksheet};
pub(crate) use tools::{Compare, Composite, Convert, Info};

use clap::{Parser, Subcommand};
use render::settings::Knob;
use scene::Method;

/// Photon-mapping renderer.
///
/// Every parameter of a run lives in its scene file; flags only override it. `cargo xtask
/// <command>` builds this binary with the `release-lto` profile, the one benchmarks measure,
/// and runs it (`cargo xtask bench <what>` runs `bench-<what>` and records its output). `photonflow <command> --help` gives a command's
/// details; docs/commands.md collects them all.
#[derive(Parser)]
#[command(name = "photonflow", version)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
    /// Sets a Mitsuba 3 XML scene's `$NAME` parameter, before its `<default>`s (repeatable;
    /// read by info, convert, render, estimate, trace and worksheet).
    #[arg(short = 'D', global = true, value_name = "NAME=VALUE", value_parser = parse::parse_define)]
    pub(crate) define: Vec<(String, String)>,
}

// The commands in the order `photonflow --help` lists them; each one's help is its struct's
// doc comment (a doc comment here would be clap's too).
#[derive(Subcommand)]
pub(crate) enum Cmd {
    Info(Info),
    Convert(Convert),
    BenchRays(BenchRays),
    BenchPhotons(BenchPhotons),
    BenchStore(BenchStore),
    BenchSplat(BenchSplat),
    BenchAccuracy(BenchAccuracy),
    BenchKnn(BenchKnn),
    BenchLoad(BenchLoad),
    BenchPath(BenchPath),
    Render(Render),
    Estimate(Estimate),
    Worksheet(Worksheet),
    Evidence(Evidence),
    Trace(Trace),
    Merge(Merge),
    Composite(Composite),
    Compare(Compare),
}

/// The widest `--help` gets, however wide the terminal: longer lines are hard to read, and
/// [`long_helps`] renders at this width.
pub const HELP_WIDTH: usize = 100;

/// The command line, with the help of the flags whose meaning depends on the method drawn
/// from the method table (`--method`'s list and default, where `--spp` and `--passes` go,
/// which counts `--time` only caps), so it never describes another set of methods.
pub fn command() -> clap::Command {
    use clap::CommandFactory;
    use render::methods::{ESTIMATE_DEFAULT, METHODS, MethodRow};
    let names = |rows: &mut dyn Iterator<Item = &MethodRow>| -> Vec<String> {
        rows.map(|r| r.method.name()).collect()
    };
    let lines = |rows: &mut dyn Iterator<Item = &MethodRow>| -> String {
        rows.map(|r| format!("\n  {}: {}", r.method, r.help))
            .collect()
    };
    let render_short = format!(
        "The method (default: the scene's render.method, else {}): {}",
        Method::default(),
        names(&mut METHODS.iter()).join(", ")
    );
    let render_long = format!(
        "The method (default: the scene's render.method, else {}):{}",
        Method::default(),
        lines(&mut METHODS.iter())
    );
    let maps = || METHODS.iter().filter(|r| r.reads_photon_maps());
    let estimate_short = format!(
        "{} (default: the scene's render.method when it is one of these, else \
         {ESTIMATE_DEFAULT})",
        names(&mut maps()).join(" or "),
    );
    let estimate_long = format!(
        "{estimate_short}. Of these, {ESTIMATE_DEFAULT} is the one `bench-accuracy` measured \
         reaching the path tracer's error:{}",
        lines(&mut maps())
    );
    // Where `--spp` and `--passes` go, per method, from the table.
    let knob_help = |what: &str, knob: fn(&MethodRow) -> Option<Knob>| {
        let places: Vec<String> = METHODS
            .iter()
            .map(|r| match knob(r) {
                Some(k) => format!("{}: {}", r.method, k.key()),
                None => format!("{}: refused", r.method),
            })
            .collect();
        let short = format!("{what} (default: the scene file's)");
        let long = format!("{what} (default: the scene file's; {})", places.join(", "));
        (short, long)
    };
    let (spp_short, spp_long) = knob_help("Samples per pixel", |r| r.spp);
    let (passes_short, passes_long) = knob_help("Passes of the progressive methods", |r| r.passes);
    let passes_long = format!("{passes_long}. A run stopped by --time records the passes made.");
    // Which flags give the count that --time then only caps, per progressive method.
    let counts: Vec<String> = METHODS
        .iter()
        .filter(|r| r.passes.is_some())
        .map(|r| {
            let flags: Vec<&str> = [("--spp", r.spp), ("--passes", r.passes)]
                .into_iter()
                .filter(|(_, k)| k.is_some_and(Knob::counts_passes))
                .map(|(f, _)| f)
                .collect();
            format!("{}: {}", r.method, flags.join(" or "))
        })
        .collect();
    let time_short = "Seconds to render for: a budget to use, past the scene file's count; with \
                      the count given too, a cap";
    let time_long = format!(
        "Seconds to render for, a budget to use: the progressive methods' passes go on past \
         the scene file's count until the time is used, and the run stops after the pass that \
         uses it, so the last pass overshoots by at most one pass. With the run's count given \
         too ({}) the time only caps it: the run stops at whichever comes first.\n\n\
         The path tracer's passes under a budget hold at most the samples 1/{:.0} of the \
         budget makes at the rate measured so far, so its last pass overshoots by about that \
         (or by one sample per pixel, if that takes longer); its snapshots are still written \
         at every power of two. A run that reaches the largest count its setting takes stops \
         there, with a warning that the budget was not used up.\n\n\
         The output's scene.toml and image.json record the passes made, so scene.toml renders \
         the same image again. Methods without passes refuse --time.",
        counts.join("; "),
        1.0 / render::passes::BUDGET_SHARE
    );
    let methodwise = |c: clap::Command, short: String, long: String| {
        c.mut_arg("method", |a| a.help(short).long_help(long))
            .mut_arg("spp", |a| {
                a.help(spp_short.clone()).long_help(spp_long.clone())
            })
            .mut_arg("passes", |a| {
                a.help(passes_short.clone()).long_help(passes_long.clone())
            })
            .mut_arg("time", |a| a.help(time_short).long_help(time_long.clone()))
    };
    // `mut_subcommands` keeps the commands' order, which docs/commands.md follows.
    Cli::command()
        .max_term_width(HELP_WIDTH)
        .mut_subcommands(|c| match c.get_name() {
            "render" => methodwise(c, render_short.clone(), render_long.clone()),
            "estimate" => methodwise(c, estimate_short.clone(), estimate_long.clone()),
            _ => c,
        })
}

/// Every command's `--help` as the binary prints it on a terminal [`HELP_WIDTH`] columns wide
/// or wider, as (the command line, the text): `photonflow --help` first, then each command's
/// in the order of `photonflow --help`. docs/commands.md holds these.
pub fn long_helps() -> Vec<(String, String)> {
    let root = command();
    let names: Vec<String> = root
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    let lines = std::iter::once(vec!["photonflow".to_string(), "--help".into()]).chain(
        names
            .into_iter()
            .map(|n| vec!["photonflow".to_string(), n, "--help".into()]),
    );
    lines
        .map(|args| {
            // Parsing `--help` always stops with the help as its "error", as the binary
            // prints it (`to_string` leaves out the terminal's colours).
            let text = match command().term_width(HELP_WIDTH).try_get_matches_from(&args) {
                Ok(_) => String::new(),
                Err(e) => e.render().to_string(),
            };
            (args.join(" "), text)
        })
        .collect()
}
