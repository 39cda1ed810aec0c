//! The one progressive pass loop that `path`, `caustic-splat`, `path+splat` and `sppm` run
//! in: passes until the run's count, or under a time budget (`--time`) until the time is
//! used; a snapshot of the image whenever the passes made (samples per pixel for the path
//! tracer) reach a power of two, and after the last, so one run gives an error-against-time
//! series.
//!
//! A budget alone is a budget to use, not a cap: the passes go on past the scene file's
//! count until the time is used, up to the largest count its setting takes (then a warning
//! says the budget was not used up). With the count given as a flag too, the time only caps
//! it. The loop stops after the pass that uses the time, so that pass's length is the
//! overshoot: a pass of several units (the path tracer's samples per pixel) is sized from
//! the rate measured so far to take at most [`BUDGET_SHARE`] of the budget.

use crate::rendered::{Layer, Rendered, Snapshot};
use crate::settings::Budget;
use std::time::Duration;

/// Under a time budget a pass of several units holds at most the units this share of the
/// budget makes at the rate measured so far: the last pass overshoots by about that much.
pub const BUDGET_SHARE: f64 = 1.0 / 32.0;

/// What the loop asks of the next pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pass {
    /// The count the run goes to: the settings', or under a budget alone the largest its
    /// setting takes ([`Progressive::limit`]). A pass never goes past it.
    pub end: u32,
    /// Most units the pass should hold (at least 1; `u32::MAX` without a budget). Methods
    /// whose pass is one unit (a photon pass) make one whatever it says.
    pub at_most: u32,
}

/// A method's image being made pass by pass.
pub trait Progressive {
    /// What is counted so far: samples per pixel (`path`, `path+splat`) or passes.
    fn done(&self) -> u32;
    /// The count of the run the settings give.
    fn total(&self) -> u32;
    /// The largest count the run may reach, and the setting at its bound that makes it so
    /// (`Knob::at_max`): a run records its count in settings, which must stay valid.
    fn limit(&self) -> (u32, String);
    /// Renders one more pass (within `pass`) and adds it.
    fn step(&mut self, pass: Pass, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String>;
    /// The layers so far.
    fn layers(&self) -> Vec<Layer>;
    /// The run as it stands, `seconds` after its first pass began (no snapshots).
    fn finish(&self, seconds: f64) -> Rendered;
}

/// Runs `p`'s passes on the wall clock; see the module docs.
pub fn run(
    p: &mut dyn Progressive,
    budget: Option<Budget>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, String> {
    let t0 = std::time::Instant::now();
    run_with(p, budget, &|| t0.elapsed(), progress)
}

/// What ended a run, for `image.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stop {
    Count,
    Time,
    Limit,
}

/// [`run`] with `clock` giving the time since the loop began (tests pass a simulated one).
pub fn run_with(
    p: &mut dyn Progressive,
    budget: Option<Budget>,
    clock: &dyn Fn() -> Duration,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, String> {
    let (limit, why) = p.limit();
    let open = budget.is_some_and(|b| !b.capped);
    let end = if open { limit } else { p.total().min(limit) };
    let mut snapshots = Vec::new();
    let mut elapsed = 0.0;
    let mut stop = Stop::Count;
    while p.done() < end {
        let at_most = budget.map_or(u32::MAX, |b| pass_size(p.done(), elapsed, b.seconds));
        p.step(Pass { end, at_most }, progress)?;
        elapsed = clock().as_secs_f64();
        let done = p.done();
        let timed_out = budget.is_some_and(|b| elapsed >= b.seconds);
        if done.is_power_of_two() || done >= end || timed_out {
            snapshots.push(Snapshot {
                passes: done,
                seconds: elapsed,
                layers: p.layers(),
            });
        }
        if timed_out {
            stop = Stop::Time;
            break;
        }
    }
    if let Some(b) = budget
        && open
        && stop == Stop::Count
    {
        stop = Stop::Limit;
        eprintln!(
            "warning: --time {}: stopped after {elapsed:.2} s at {why}, the largest count it \
             takes, so the budget was not used up",
            b.seconds
        );
    }
    let mut r = p.finish(clock().as_secs_f64());
    r.snapshots = snapshots;
    if let Some(b) = budget {
        r.info.insert(
            "time_budget".into(),
            serde_json::json!({
                "seconds": b.seconds,
                "capped": b.capped,
                "stopped_by": match stop {
                    Stop::Count => "count",
                    Stop::Time => "time",
                    Stop::Limit => "limit",
                },
            }),
        );
    }
    Ok(r)
}

/// Most units the next pass may hold under a budget of `budget` seconds, `done` units having
/// taken `elapsed`: [`BUDGET_SHARE`] of the budget at that rate, at least one unit (before
/// any rate is known, one).
fn pass_size(done: u32, elapsed: f64, budget: f64) -> u32 {
    if done == 0 {
        return 1;
    }
    if elapsed <= 0.0 {
        return u32::MAX;
    }
    // `as` saturates: an unmeasurably fast pass allows any size.
    ((done as f64 / elapsed * budget * BUDGET_SHARE) as u32).max(1)
}
