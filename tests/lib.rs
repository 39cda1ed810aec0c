//! What the end-to-end tests (`it/`) share with the `fuzz` binary (`bin/fuzz.rs`): the fuzz
//! loops over every loader and the allocation tracker they check with. The helpers only `it`
//! uses are its test kit, `it/kit.rs`.

pub mod alloc;
pub mod fuzz;
