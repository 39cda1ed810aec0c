//! The photonflow crate's one integration test binary (matklad, "Delete Cargo Integration
//! Tests"): one link of the renderer for every end-to-end test, not one per file.

mod cli;
mod docs;
