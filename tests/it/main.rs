//! The one end-to-end test binary (matklad, "Delete Cargo Integration Tests"). One module per
//! subject:
//!
//! - `cornell`: ray casting on the worksheet scene as loaded from `scenes/` (BVH = brute force,
//!   the light under the ceiling is reachable, camera rays behave).
//! - `photons`: photon flux against the path tracer (caustic flux under the glass sphere) and
//!   against the light power (closed furnace box).

mod cornell;
mod photons;
