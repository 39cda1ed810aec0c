//! `photons`: the photon stage. The effects plan decides which photon sets a scene needs;
//! [`cache`] keys them by what they depend on and reuses or traces them through the channel
//! pipeline (`flow`) into photon files ([`sinks`]); [`shard`] traces index ranges of a run on
//! any machine and merges them back, byte for byte. Photon files are the contract with the
//! stages that read them: this crate never sees an estimator or an eye pass.

pub mod cache;
pub mod shard;
pub mod sinks;

pub use cache::{CacheKey, TraceOutput, trace};

#[cfg(test)]
mod tests;
