//! What the end-to-end tests (`it/`) share with the `fuzz` binary (`bin/fuzz.rs`): the fuzz
//! loops over every loader, the allocation tracker they check with, and the PLY writer of
//! their corpus. The helpers only `it` uses are its test kit, `it/kit.rs`.

pub mod alloc;
pub mod fuzz;
pub mod ply;
