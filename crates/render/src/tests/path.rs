use crate::methods::path::{MIN_PASSES, next_pass, passes};
use crate::settings::Knob;

/// The passes before time budgets sized them: `passes` (what shards split) and every
/// run without `--time` must keep them, or images change.
fn old_passes(spp: u32) -> Vec<u32> {
    let cap = spp.div_ceil(MIN_PASSES).max(1).next_power_of_two();
    let (mut out, mut done) = (Vec::new(), 0);
    while done < spp {
        let n = done.clamp(1, cap).min(spp - done);
        out.push(n);
        done += n;
    }
    out
}

#[test]
fn passes_without_a_budget_are_unchanged() {
    for spp in (1..=600).chain([1000, 4096, 4097, 65535, 1 << 24]) {
        let new: Vec<u32> = passes(spp)
            .iter()
            .map(|r| (r.end - r.start) as u32)
            .collect();
        assert_eq!(new, old_passes(spp), "spp {spp}");
    }
}

#[test]
fn budget_sized_passes_end_at_every_power_of_two() {
    // A budget allowing 5, then 40, then 3 samples a pass, in a run to render.spp's
    // bound: passes are powers of two within it, and every power of two of samples ends
    // one.
    let end = Knob::RenderSpp.max();
    let mut done = 0;
    let mut ends = Vec::new();
    for at_most in [5; 6].into_iter().chain([40; 8]).chain([3; 8]) {
        let n = next_pass(done, end, at_most);
        assert!(n.is_power_of_two() && n <= at_most, "{n} at {done}");
        done += n;
        ends.push(done);
    }
    assert_eq!(ends[..6], [1, 2, 4, 8, 12, 16]);
    for p in (0..).map(|i| 1u32 << i).take_while(|&p| p <= done) {
        assert!(ends.contains(&p), "{p} samples end no pass: {ends:?}");
    }
}
