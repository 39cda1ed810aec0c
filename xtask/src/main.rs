//! `cargo xtask`: project automation in Rust (matklad's cargo-xtask convention).
//!
//! xtask links no renderer crate. It builds the `photonflow` binary once, optimised, through
//! `$CARGO` and runs it, so a change to xtask never rebuilds the renderer and vice versa.
//! Every command builds the binary with `release-lto`, the profile benchmarks measure;
//! benchmarks record their output in `docs/benchmarks.md`.

mod benchmarks;
mod flags;
mod gen_scenes;
mod slurm_demo;
#[cfg(test)]
mod tests;
mod tidy;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &[String]) -> Result<(), String> {
    let cmd = flags::parse(args)?;
    match cmd {
        flags::Cmd::Help => {
            print!("{}", flags::HELP);
            Ok(())
        }
        flags::Cmd::GenScenes => gen_scenes::run(&project_root()),
        flags::Cmd::SlurmDemo => slurm_demo::run(&project_root(), &build(PROFILE)?),
        flags::Cmd::Fuzz(args) => fuzz(&args),
        flags::Cmd::Photonflow(args) => photonflow(&build(PROFILE)?, &args),
        flags::Cmd::Bench(bench) => benchmarks::run(&project_root(), &build(PROFILE)?, &bench),
    }
}

/// The profile every command's binary is built with: the one published numbers measure
/// (`release-lto`, about 7% faster than `release`), so users run what the benchmarks timed.
const PROFILE: &str = "release-lto";

/// The workspace root, from this crate's manifest directory.
pub fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask sits one level below the root")
        .to_path_buf()
}

/// Build the `photonflow` binary with cargo profile `profile`; returns its path.
fn build(profile: &str) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let root = project_root();
    let status = Command::new(&cargo)
        .current_dir(&root)
        .args([
            "build",
            "--quiet",
            "--profile",
            profile,
            "--package",
            "photonflow",
        ])
        .status()
        .map_err(|e| format!("cannot run {cargo}: {e}"))?;
    if !status.success() {
        return Err("building photonflow failed".into());
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    Ok(target
        .join(profile)
        .join(format!("photonflow{}", std::env::consts::EXE_SUFFIX)))
}

/// The fuzz loops, optimised (they run as many cases as the seconds allow).
fn fuzz(args: &[String]) -> Result<(), String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(&cargo)
        .current_dir(project_root())
        .args([
            "run",
            "--quiet",
            "--release",
            "-p",
            "tests",
            "--bin",
            "fuzz",
            "--",
        ])
        .args(args)
        .status()
        .map_err(|e| format!("cannot run {cargo}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("fuzz {} failed ({status})", args.join(" ")))
    }
}

/// Run the built binary `exe` with `args` from the project root.
fn photonflow(exe: &Path, args: &[String]) -> Result<(), String> {
    let status = Command::new(exe)
        .current_dir(project_root())
        .args(args)
        .status()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("photonflow {} failed ({status})", args.join(" ")))
    }
}
