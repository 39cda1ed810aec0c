//! `cargo xtask fuzz --seconds N [--target T] [--seed S]`: the fuzz loops of `tests::fuzz`
//! for longer than `cargo test` runs them, each target for N seconds.

#[global_allocator]
static ALLOC: tests::alloc::Tracking = tests::alloc::Tracking;

use tests::fuzz::{Budget, Target, run};

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut seconds = 60.0;
    let mut seed = 1u64;
    let mut targets: Vec<Target> = Target::ALL.to_vec();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let value = it.next();
        let parsed = match (a.as_str(), value) {
            ("--seconds", Some(v)) => v.parse().map(|s| seconds = s).is_ok() && seconds > 0.0,
            ("--seed", Some(v)) => v.parse().map(|s| seed = s).is_ok(),
            ("--target", Some(v)) => match Target::ALL.iter().find(|t| t.name() == v) {
                Some(&t) => {
                    targets = vec![t];
                    true
                }
                None => false,
            },
            _ => false,
        };
        if !parsed {
            eprintln!(
                "fuzz: bad argument `{a}`: usage: fuzz [--seconds N] [--seed S] \
                 [--target obj|mtl|ply|ply-ascii|scene|photons|exr]"
            );
            return std::process::ExitCode::FAILURE;
        }
    }
    let dir = std::env::temp_dir().join(format!("photonflow-fuzz-{}", std::process::id()));
    for t in targets {
        let d = dir.join(t.name());
        match run(t, seed, Budget::Seconds(seconds), &d) {
            Ok(s) => {
                println!(
                    "fuzz {:<8} {:>9} cases in {seconds} s, {:>7} accepted, largest allocation {} bytes",
                    t.name(),
                    s.cases,
                    s.accepted,
                    s.largest_alloc
                );
                let _ = std::fs::remove_dir_all(&d);
            }
            Err(e) => {
                eprintln!("{e}");
                return std::process::ExitCode::FAILURE;
            }
        }
    }
    std::process::ExitCode::SUCCESS
}
