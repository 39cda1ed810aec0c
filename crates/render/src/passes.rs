//! The one progressive pass loop that `path`, `caustic-splat`, `path+splat` and `sppm` run
//! in: passes until the run's count, or until a time budget (`--time`) is used once a pass has
//! been made; a snapshot of the image whenever the passes made (samples per pixel for the
//! path tracer) reach a power of two, and after the last, so one run gives an
//! error-against-time series.

use crate::rendered::{Layer, Rendered, Snapshot};

/// A method's image being made pass by pass.
pub trait Progressive {
    /// What is counted so far: samples per pixel (`path`, `path+splat`) or passes.
    fn done(&self) -> u32;
    /// The count of the whole run.
    fn total(&self) -> u32;
    /// Renders one more pass and adds it.
    fn step(&mut self, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String>;
    /// The layers so far.
    fn layers(&self) -> Vec<Layer>;
    /// The run as it stands, `seconds` after its first pass began (no snapshots).
    fn finish(&self, seconds: f64) -> Rendered;
}

/// Runs `p`'s passes; see the module docs.
pub fn run(
    p: &mut dyn Progressive,
    time: Option<f64>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, String> {
    let t0 = std::time::Instant::now();
    let mut snapshots = Vec::new();
    while p.done() < p.total() {
        p.step(progress)?;
        let elapsed = t0.elapsed().as_secs_f64();
        let done = p.done();
        if done.is_power_of_two() || done == p.total() {
            snapshots.push(Snapshot {
                passes: done,
                seconds: elapsed,
                layers: p.layers(),
            });
        }
        if time.is_some_and(|t| elapsed >= t) {
            break;
        }
    }
    let mut r = p.finish(t0.elapsed().as_secs_f64());
    r.snapshots = snapshots;
    Ok(r)
}
