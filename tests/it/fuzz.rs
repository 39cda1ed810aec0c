//! The fuzz loops of `tests::fuzz` at the size `cargo test` affords: 3,000 mutated inputs per
//! loader (OBJ, MTL, PLY binary and ASCII, scene file, photon file, EXR), each one answered
//! without a panic, a hang or an allocation sized by an unchecked field. `cargo xtask fuzz --seconds N` runs more.

use crate::kit::TempDir;
use tests::fuzz::{Budget, Target, run};

/// Enough that the EXR loop finds a header-sized allocation when the reader's size check is
/// removed (its first such case is number 2058 with this seed).
const CASES: u64 = 3000;

fn fuzz(t: Target) {
    let dir = TempDir::new(&format!("fuzz-{}", t.name()));
    let s = run(t, 0x5EED, Budget::Cases(CASES), dir.path()).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}: {s:?}", t.name());
    assert_eq!(s.cases, CASES);
    // The mutations reach past the first check: some inputs still load, most are refused.
    assert!(s.accepted > 0 && s.accepted < s.cases, "{s:?}");
}

#[test]
fn obj_loader_survives_mutations() {
    fuzz(Target::Obj);
}

#[test]
fn mtl_reader_survives_mutations() {
    fuzz(Target::Mtl);
}

#[test]
fn ply_reader_survives_binary_mutations() {
    fuzz(Target::Ply);
}

#[test]
fn ply_reader_survives_text_mutations() {
    fuzz(Target::PlyAscii);
}

#[test]
fn scene_file_parser_survives_mutations() {
    fuzz(Target::Scene);
}

#[test]
fn photon_file_readers_survive_mutations() {
    fuzz(Target::Photons);
}

#[test]
fn exr_reader_survives_mutations() {
    fuzz(Target::Exr);
}
