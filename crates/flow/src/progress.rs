//! Progress for long work: an indicatif bar with rate and ETA on a terminal; on a pipe (CI
//! logs) one plain line per tenth of the work, so progress is visible there too.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

pub struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    unit: &'static str,
    label: String,
    start: Instant,
    plain: Mutex<(u64, u64)>, // (done, next tenth to print)
}

impl Progress {
    pub fn new(label: &str, total: u64, unit: &'static str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(&format!(
                    "{label} {{bar:40}} {{percent:>3}}% {{human_pos}}/{{human_len}} {unit} \
                     [{{per_sec}}, {{elapsed}} elapsed, ETA {{eta}}]"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b
        });
        Progress {
            bar,
            total: total.max(1),
            unit,
            label: label.to_string(),
            start: Instant::now(),
            plain: Mutex::new((0, 1)),
        }
    }

    /// Work of no known total (a time budget ends it): on a terminal the count and its rate,
    /// on a pipe nothing (the work reports per pass on its own lines).
    pub fn unbounded(label: &str, unit: &'static str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(&format!(
                    "{label} {{spinner}} {{human_pos}} {unit} [{{per_sec}}, {{elapsed}} elapsed]"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            b
        });
        Progress {
            bar,
            ..Progress::hidden()
        }
    }

    /// No output at all (benchmarks time the work, not the printing).
    pub fn hidden() -> Progress {
        Progress {
            bar: None,
            total: u64::MAX,
            unit: "",
            label: String::new(),
            start: Instant::now(),
            plain: Mutex::new((0, 11)),
        }
    }

    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
            return;
        }
        let mut g = self.plain.lock().unwrap_or_else(|e| e.into_inner());
        g.0 += n;
        while g.1 <= 10 && g.0 * 10 >= g.1 * self.total {
            let secs = self.start.elapsed().as_secs_f64();
            let rate = g.0 as f64 / secs.max(1e-9);
            let eta = (self.total - g.0.min(self.total)) as f64 / rate.max(1e-9);
            eprintln!(
                "{} {:>3}% {}/{} {} [{:.3e} {}/s, {:.1} s elapsed, ETA {:.1} s]",
                self.label,
                g.1 * 10,
                g.0,
                self.total,
                self.unit,
                rate,
                self.unit,
                secs,
                eta
            );
            g.1 += 1;
        }
    }

    /// Finish and return the elapsed seconds.
    pub fn finish(self) -> f64 {
        if let Some(b) = &self.bar {
            b.finish();
        }
        self.start.elapsed().as_secs_f64()
    }
}
