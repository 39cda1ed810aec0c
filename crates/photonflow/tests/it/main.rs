//! The photonflow crate's one integration test binary (matklad, "Delete Cargo Integration
//! Tests"): one link of the renderer for every end-to-end test, not one per file.
//! - `cli`: the binary's contract on bad input, and its commands run end to end;
//! - `commands`: docs/commands.md is the help the code prints;
//! - `faults`: kill -9 at any instant, a full disk, a read-only output place;
//! - `docs`: what README.md and `cargo xtask`'s help spell by hand is the code's.

mod cli;
mod commands;
mod docs;
#[cfg(unix)]
mod faults;
