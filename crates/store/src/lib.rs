//! `store`: the photon record and, around it, the photon file. **API boundary**: the record
//! layout and the file format are versioned; nothing else in photonflow knows their bytes.

mod record;

pub use record::{MapKind, Photon, oct_decode, oct_encode};

#[cfg(test)]
mod tests;
