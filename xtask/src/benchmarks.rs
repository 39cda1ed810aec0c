//! `cargo xtask bench <what>`: runs `photonflow bench-<what>`, echoes its output live and
//! records it as the section `## bench <what>` of `docs/benchmarks.md`, so published numbers
//! always come with the command, date and machine that produced them. Only the section of the
//! benchmark that ran is replaced; the others stay as they were.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};

use crate::flags::Bench;

/// Where the sections live, relative to the project root.
pub const DOC: &str = "docs/benchmarks.md";

/// Start of a fresh file, should `docs/benchmarks.md` be missing.
const NEW_DOC: &str = "# Benchmarks\n\nWritten by `cargo xtask bench <what>`.\n";

pub fn run(root: &Path, exe: &Path, bench: &Bench) -> Result<(), String> {
    let output = run_teed(root, exe, &bench.args)?;
    let section = section(bench, &utc_now(), &machine(), &output);
    let path = root.join(DOC);
    let doc = match std::fs::read_to_string(&path) {
        Ok(doc) => doc,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => NEW_DOC.to_string(),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    write_atomic(&path, &replace_section(&doc, &bench.what, &section))?;
    println!("recorded in {DOC}");
    Ok(())
}

/// Runs `exe args` from `root` and returns its stdout, echoing it as it comes (chunks, not
/// lines, so partial lines show at once); stderr goes straight to the terminal. A failed run
/// is an error, so nothing is recorded.
fn run_teed(root: &Path, exe: &Path, args: &[String]) -> Result<String, String> {
    let mut child = Command::new(exe)
        .current_dir(root)
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    let mut pipe = child.stdout.take().expect("stdout is piped");
    let mut captured = Vec::new();
    let mut echoed = 0;
    let mut buf = [0u8; 4096];
    loop {
        let n = match pipe.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(format!("reading photonflow's output: {e}")),
        };
        captured.extend_from_slice(&buf[..n]);
        // Echo through `print!` (which tests capture), up to the last whole UTF-8 character
        // so a character split between reads is printed once complete.
        let pending = &captured[echoed..];
        let whole = match std::str::from_utf8(pending) {
            Ok(s) => s.len(),
            Err(e) if e.error_len().is_none() => e.valid_up_to(),
            Err(_) => pending.len(), // not UTF-8: echo it mangled, record it lossily
        };
        print!("{}", String::from_utf8_lossy(&pending[..whole]));
        let _ = std::io::stdout().flush();
        echoed += whole;
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!(
            "photonflow {} failed ({status}); {DOC} left as it was",
            args.join(" ")
        ));
    }
    Ok(String::from_utf8_lossy(&captured).into_owned())
}

/// The section for one run: heading, command, date, machine, and the output in fences longer
/// than any run of backticks inside it, but for its markdown tables (runs of lines starting
/// with `|`), which stand outside the fences so that they render as tables.
pub fn section(bench: &Bench, date: &str, machine: &str, output: &str) -> String {
    let longest = output.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest.max(2) + 1);
    let typed = shell_words(&bench.typed);
    let args = shell_words(&bench.args);
    let mut body = String::new();
    let mut lines: Vec<&str> = output.trim_end().lines().collect();
    if lines.is_empty() {
        lines.push("");
    }
    for chunk in lines.chunk_by(|a, b| a.starts_with('|') == b.starts_with('|')) {
        if chunk[0].starts_with('|') {
            body += &format!("{}\n\n", chunk.join("\n"));
        } else {
            // Blank lines around a table belong to no fence.
            let text = chunk.join("\n");
            let text = text.trim_matches('\n');
            if !text.is_empty() || lines.len() == chunk.len() {
                body += &format!("{fence}text\n{text}\n{fence}\n\n");
            }
        }
    }
    format!(
        "## bench {what}\n\n\
         - command: `cargo xtask bench {typed}`\n\
         - runs: `photonflow {args}` (profile `release-lto`)\n\
         - date: {date}\n\
         - machine: {machine}\n\n\
         {body}",
        what = bench.what,
        body = body.trim_end_matches('\n').to_string() + "\n",
    )
}

/// `args` as one shell line, quoting what the shell would split or expand.
fn shell_words(args: &[String]) -> String {
    let plain = |s: &str| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./,:=@%+".contains(c))
    };
    args.iter()
        .map(|a| {
            if plain(a) {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `doc` with the section headed `## bench <what>` replaced by `section` (which holds its own
/// heading), or `section` appended when there is none. A section runs to the next `## `
/// heading; fenced blocks are skipped, since program output may start a line with `## `.
pub fn replace_section(doc: &str, what: &str, section: &str) -> String {
    let heading = format!("## bench {what}");
    let mut start = None;
    let mut end = doc.len();
    let mut fence: Option<usize> = None;
    let mut at = 0;
    for line in doc.split_inclusive('\n') {
        let t = line.trim_end();
        let ticks = t.len() - t.trim_start_matches('`').len();
        match fence {
            Some(n) if ticks >= n && t.len() == ticks => fence = None,
            Some(_) => {}
            None if ticks >= 3 => fence = Some(ticks),
            None if t.starts_with("## ") => {
                if start.is_some() {
                    end = at;
                    break;
                }
                if t == heading || t.starts_with(&format!("{heading} ")) {
                    start = Some(at);
                }
            }
            None => {}
        }
        at += line.len();
    }
    match start {
        Some(start) => {
            let rest = &doc[end..];
            let gap = if rest.is_empty() { "" } else { "\n" };
            format!("{}{section}{gap}{rest}", &doc[..start])
        }
        None => format!("{}\n\n{section}", doc.trim_end()),
    }
}

/// The current time as `YYYY-MM-DD HH:MM UTC`, from the system clock.
fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc(secs)
}

pub fn utc(unix_secs: u64) -> String {
    let (days, secs) = ((unix_secs / 86_400) as i64, unix_secs % 86_400);
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        secs / 3600,
        secs / 60 % 60
    )
}

/// Proleptic Gregorian date of a day count since 1970-01-01 (Howard Hinnant's
/// `civil_from_days`): a date without a date crate.
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // day of the 400-year era
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // day of the year from March 1st
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = (if mp < 10 { mp + 3 } else { mp - 9 }) as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// CPU count (what `nproc` prints: the CPUs this process may use) and model, when the OS
/// says (`/proc/cpuinfo` on Linux).
fn machine() -> String {
    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| cpu_model(&info));
    match model {
        Some(m) => format!("{cpus} CPUs (nproc), {m}"),
        None => format!("{cpus} CPUs (nproc)"),
    }
}

pub fn cpu_model(cpuinfo: &str) -> Option<String> {
    cpuinfo
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, m)| m.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|m| !m.is_empty())
}

/// Temp file and rename, so an interrupted run leaves the old file whole.
fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    let dir = path.parent().expect("a file in a directory");
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let tmp = dir.join(format!(".benchmarks.md.{}.tmp", std::process::id()));
    let result = std::fs::write(&tmp, text).and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("{}: {e}", path.display())
    })
}
