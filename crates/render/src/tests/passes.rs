use crate::passes::{BUDGET_SHARE, Pass, Progressive, run_with};
use crate::rendered::{Layer, Rendered};
use crate::settings::Budget;
use std::cell::Cell;
use std::rc::Rc;
use std::time::Duration;

/// A method whose passes advance a simulated clock: `per_pass` seconds each plus
/// `per_unit` per unit in them. `units` makes passes of up to `at_most` units (as the
/// path tracer does); else one unit each (a photon pass).
struct Fake {
    done: u32,
    total: u32,
    limit: u32,
    units: bool,
    per_pass: f64,
    per_unit: f64,
    now: Rc<Cell<f64>>,
    /// Each pass's units and seconds.
    passes: Vec<(u32, f64)>,
}

impl Fake {
    fn new(total: u32, per_pass: f64) -> Fake {
        Fake {
            done: 0,
            total,
            limit: 1 << 20,
            units: false,
            per_pass,
            per_unit: 0.0,
            now: Rc::new(Cell::new(0.0)),
            passes: Vec::new(),
        }
    }
}

impl Progressive for Fake {
    fn done(&self) -> u32 {
        self.done
    }
    fn total(&self) -> u32 {
        self.total
    }
    fn limit(&self) -> (u32, String) {
        (self.limit, format!("fake = {}", self.limit))
    }
    fn step(&mut self, pass: Pass, _: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        assert!(pass.at_most >= 1 && self.done < pass.end);
        let n = match self.units {
            true => pass.at_most.min(pass.end - self.done),
            false => 1,
        };
        let s = self.per_pass + n as f64 * self.per_unit;
        self.now.set(self.now.get() + s);
        self.done += n;
        self.passes.push((n, s));
        Ok(())
    }
    fn layers(&self) -> Vec<Layer> {
        Vec::new()
    }
    fn finish(&self, seconds: f64) -> Rendered {
        let mut info = serde_json::Map::new();
        info.insert("seconds".into(), seconds.into());
        Rendered {
            passes: Some(self.done),
            ..Rendered::new(Vec::new(), info)
        }
    }
}

fn run_fake(f: &mut Fake, budget: Option<Budget>) -> Rendered {
    let now = f.now.clone();
    run_with(f, budget, &|| Duration::from_secs_f64(now.get()), &|_| {}).unwrap()
}

fn budget(seconds: f64) -> Option<Budget> {
    Some(Budget {
        seconds,
        capped: false,
    })
}

fn stopped_by(r: &Rendered) -> &str {
    r.info["time_budget"]["stopped_by"].as_str().unwrap()
}

#[test]
fn a_budget_alone_is_used_past_the_count() {
    // Passes of 1 s, a 10 s budget, the scene's count 16: ten passes, the tenth ending
    // exactly at the budget.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, budget(10.0));
    assert_eq!((f.done, r.passes, stopped_by(&r)), (10, Some(10), "time"));
    // A budget beyond the count: 40 passes, not the scene's 16.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, budget(40.0));
    assert_eq!((f.done, stopped_by(&r)), (40, "time"));
    assert_eq!(r.info["seconds"], 40.0);
    // The last pass ends past the budget by less than a pass, and is snapshotted.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, budget(25.5));
    assert_eq!(f.done, 26);
    assert!(f.now.get() - 25.5 < 1.0);
    let snaps: Vec<u32> = r.snapshots.iter().map(|s| s.passes).collect();
    assert_eq!(snaps, [1, 2, 4, 8, 16, 26]);
}

#[test]
fn passes_of_many_units_take_a_small_share_of_the_budget() {
    // 0.01 s per unit (100 units per second), a 10 s budget: after the first pass the
    // rate is known and no pass takes more than BUDGET_SHARE of the budget, so neither
    // does the overshoot.
    let mut f = Fake::new(16, 0.0);
    f.units = true;
    f.per_unit = 0.01;
    let r = run_fake(&mut f, budget(10.0));
    assert_eq!(stopped_by(&r), "time");
    let most = BUDGET_SHARE * 10.0 + 1e-9;
    assert!(f.passes.iter().all(|&(_, s)| s <= most), "{:?}", f.passes);
    assert!(f.now.get() >= 10.0 && f.now.get() - 10.0 <= most);
    assert!(f.done >= 1000, "{}", f.done);
    // About 1 / BUDGET_SHARE passes, not one per unit.
    assert!(f.passes.len() <= 40, "{} passes", f.passes.len());
}

#[test]
fn with_the_count_given_the_time_only_caps_it() {
    let capped = |seconds| {
        Some(Budget {
            seconds,
            capped: true,
        })
    };
    // The count comes first: 16 passes of a 100 s budget.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, capped(100.0));
    assert_eq!((f.done, stopped_by(&r)), (16, "count"));
    // The time comes first.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, capped(5.0));
    assert_eq!((f.done, stopped_by(&r)), (5, "time"));
    // Without a budget: the count, and nothing recorded of a budget.
    let mut f = Fake::new(16, 1.0);
    let r = run_fake(&mut f, None);
    assert_eq!(f.done, 16);
    assert!(!r.info.contains_key("time_budget"));
}

#[test]
fn a_budget_stops_at_the_largest_count_the_setting_takes() {
    let mut f = Fake::new(16, 1.0);
    f.limit = 20;
    let r = run_fake(&mut f, budget(1000.0));
    assert_eq!((f.done, stopped_by(&r)), (20, "limit"));
}

/// `--time` is a cap only with the flag that gives the loop's count.
#[test]
fn time_caps_only_with_the_runs_count() {
    use crate::settings::{Overrides, Settings};
    use scene::Method;
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/cornell-spheres/analytic.toml");
    let scene = scene::Scene::load(p).unwrap();
    let capped = |method, spp, passes| {
        let o = Overrides {
            method: Some(method),
            spp,
            passes,
            time: Some(10.0),
            ..Overrides::default()
        };
        Settings::new(&scene, &o).unwrap().time.unwrap().capped
    };
    for m in [
        Method::Path,
        Method::Sppm,
        Method::CausticSplat,
        Method::PathSplat,
    ] {
        assert!(!capped(m, None, None), "{m}");
        assert!(capped(m, None, Some(2)), "{m}");
    }
    assert!(capped(Method::Path, Some(2), None));
    assert!(capped(Method::PathSplat, Some(2), None));
    // caustic-splat's --spp is its eye vertices per pixel and pass, not its count.
    assert!(!capped(Method::CausticSplat, Some(2), None));
}
