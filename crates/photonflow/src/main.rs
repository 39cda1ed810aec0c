//! The `photonflow` binary: the command line is the library's ([`photonflow::run_args`]);
//! this adds what belongs to a process.

use std::process::ExitCode;

fn main() -> ExitCode {
    // Ctrl-C (or a termination signal) removes the files and staging directories being
    // written (photon files, images, shards) before it ends the process, as the default
    // action would, with the shell's code for SIGINT. What is already published is complete
    // (renamed into place whole).
    let _ = ctrlc::set_handler(|| {
        let removed = temps::remove_live_before_exit();
        eprintln!("interrupted: removed {removed}");
        std::process::exit(130);
    });
    // Rust ignores SIGPIPE, so once a reader closes our stdout (`photonflow ... | head`) every
    // `println!` panics. End as a C tool killed by SIGPIPE would instead: no message, the
    // status a shell reports for it (128 + 13), and no unfinished file left behind.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info.payload_as_str().unwrap_or("");
        if msg.starts_with("failed printing to stdout") && msg.contains("Broken pipe") {
            temps::remove_live_before_exit();
            std::process::exit(141);
        }
        default_hook(info);
    }));
    // The instruction set of ray casting, for the process (README, ARCHITECTURE.md).
    if let Some(name) = std::env::var_os("PHOTONFLOW_ISA") {
        let name = name.to_string_lossy();
        match geom::Isa::from_name(&name) {
            Ok(isa) => geom::Isa::set_active(isa),
            Err(e) => eprintln!(
                "warning: PHOTONFLOW_ISA={name}: {e}; using {:?}",
                geom::Isa::best()
            ),
        }
    }
    let (code, error) = photonflow::run_args(std::env::args_os());
    if let Some(e) = error {
        eprintln!("{e}");
    }
    ExitCode::from(code)
}
