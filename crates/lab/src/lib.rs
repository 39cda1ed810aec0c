//! `lab`: the studies built on `render`, which `render` never imports. Worksheet 7's report
//! ([`worksheet`]), the evidence ladders ([`evidence`]) and their lab report ([`report`],
//! [`plots`]), the accuracy benchmark's driver ([`accuracy`]), the speed benchmarks'
//! ([`bench`]) and the path tracer's efficiency against Mitsuba 3 ([`efficiency`]), the regions of an image drawn from the scene's geometry ([`regions`]), and the
//! one cached path-traced reference they share ([`reference`]).

pub mod accuracy;
pub mod bench;
pub mod efficiency;
pub mod evidence;
pub mod plots;
pub mod reference;
pub mod regions;
pub mod report;
pub mod worksheet;

#[cfg(test)]
mod tests;

/// `evidence`: the ladders measured ([`evidence::run`]), then the lab report written beside
/// them ([`report::write`]) in a staging directory, renamed whole into `a.out`.
pub fn evidence(a: &evidence::EvidenceArgs) -> Result<(), String> {
    let m = evidence::run(a)?;
    report::write(m.staged.path(), &m.evidence, &m.scene, &m.regions)
        .map_err(|e| m.staged.named(e))?;
    m.staged.publish()?;
    println!(
        "wrote {} and report.html, evidence.md (tables), evidence.json, maps/, plots/",
        a.out.join("report.md").display()
    );
    Ok(())
}
