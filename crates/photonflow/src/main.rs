//! The `photonflow` binary: the command line is the library's ([`photonflow::run_args`]);
//! this adds what belongs to a process.

use std::process::ExitCode;

fn main() -> ExitCode {
    // Ctrl-C (or a termination signal) removes the photon files being written before it
    // ends the process, as the default action would, with the shell's code for SIGINT.
    // Files already published are complete (they are renamed into place whole).
    let _ = ctrlc::set_handler(|| {
        let n = store::remove_live_temp_files();
        eprintln!("interrupted: removed {n} unfinished photon file(s)");
        std::process::exit(130);
    });
    let (code, error) = photonflow::run_args(std::env::args_os());
    if let Some(e) = error {
        eprintln!("{e}");
    }
    ExitCode::from(code)
}
