//! The one end-to-end test binary (matklad, "Delete Cargo Integration Tests"). One module per
//! subject:
//!
//! - `bad_input`: tables of broken or hostile inputs, one file per kind of input (scene files,
//!   their lights, OBJ and MTL, images, flags, photon files, shards and runs read back, temp
//!   files), each run through the command line in process: exit code and a one-line message
//!   naming the file and the problem, or the output a valid input must give.
//! - `convert`: a Mitsuba XML scene converted to a scene file elsewhere is the same scene
//!   (its image, bit for bit).
//! - `cornell`: ray casting on the worksheet scene as loaded from `scenes/` (BVH = brute force,
//!   the light under the ceiling is reachable, camera rays behave).
//! - `evidence`: bias^2 and variance apart from independent runs: zero bias for the path
//!   tracer, a fixed-k estimate's bias growing with k at the caustic.
//! - `glass`: coloured glass colours the light through it as `τ²` in the path tracer and
//!   each photon method alike (a slab between a white light and a grey floor).
//! - `hard_cases`: one table of numerically hard scenes (camera inside the glass sphere, the
//!   light just under the ceiling, grazing rays, total internal reflection, caustic focus,
//!   coincident photons, k above the photon count, the scene scaled by 1e-3 and 1e4,
//!   degenerate triangles, a sphere of radius 1e-4 (also seen up close), light power near the
//!   f32 limit): every image finite, closed forms, flux and invariances where the scene
//!   allows a check.
//! - `infinite_lights`: directional, sun disc and environment lights against closed forms
//!   (`ρ/π E cos θ` on a plane in the path tracer and the photon methods, a sun disc's
//!   irradiance and radiance, a diffuse sphere under a constant environment, colour or image,
//!   at `ρ L` with the background at `L`).
//! - `isa`: the vector path (AVX2, 8-wide BVH) against the baseline (4-wide BVH) on one
//!   machine: the path tracer's means region by region within the baseline's standard
//!   errors, and nearly every pixel bit-identical.
//! - `point_lights`: point and spot lights against closed forms (`ρ/π I cos θ / r²` over a
//!   plane in the path tracer and SPPM, a spot's beam, ramp and cutoff), and a point light in
//!   the glass sphere whose light only photons find.
//! - `ply`: a scene of PLY meshes (ASCII, little- and big-endian; texture coordinates, flat
//!   and smooth normals, polygons) renders the image of the same meshes as one OBJ, bit for
//!   bit, through `photonflow render` (the path tracer and SPPM).
//! - `light_tracing`: light paths joined to the camera (`--method light`): the worksheet's
//!   area light seen directly at its radiance.
//! - `references`: every method's images of the reference scenes against Mitsuba 3's
//!   (`tests/references/`, two halves), region by region, with each method's known bias and
//!   measured noise, and negative controls that must fail; one file per scene (the worksheet,
//!   its glass sphere close up, a glossy floor, rough spheres, coloured glass, a textured
//!   floor, a point light's caustic, a spot-lit box, an environment map, McGuire's box).
//! - `photons`: photon flux against the path tracer (caustic flux under the glass sphere) and
//!   against the light power (closed furnace box).
//! - `photon_maps`: the photon-map methods through the pipeline library, trace to image: the
//!   furnace against `Le / (1 - rho)` with the predicted k-NN bias, boundary correction on a
//!   square and a sphere.
//! - `splat`: photon differential splatting through the pipeline library: the splatted
//!   caustic and `path+splat` against the path tracer on the worksheet scene, bounded chunks
//!   in flight, a hostile scene (finite pixels, flux kept), the same bits on 1 and 2 threads.
//! - `fuzz`: the fuzz loops of `tests::fuzz` over every loader (mutated OBJ, MTL, scene,
//!   photon and EXR files: no panic, hang or header-sized allocation).
//! - `shards`: `trace --shard` and `render --shard` (path, caustic-splat) with 1, 3 and 7
//!   shards merged give the one-machine run's photon files and images byte for byte.
//! - `sppm`: progressive photon mapping converging to closed forms (square light, furnace) at
//!   the rate its radius schedule predicts; snapshots, time budget, thread-count invariance.
//! - `textures`: a constant texture draws its colour to the bit in every method (the albedo is
//!   read from the texture wherever it is used).
//! - `kit`: the helpers the modules share (scenes at a test's resolution and seed, methods run
//!   as the binary runs them, layers, pixels and regions of images, means with standard
//!   errors, scratch directories, the command line in process).

// Per-thread largest allocation, for the fuzz loops' check.
#[global_allocator]
static ALLOC: tests::alloc::Tracking = tests::alloc::Tracking;

mod bad_input;
mod convert;
mod cornell;
mod evidence;
mod fuzz;
mod glass;
mod hard_cases;
mod infinite_lights;
mod isa;
mod kit;
mod light_tracing;
mod photon_maps;
mod photons;
mod ply;
mod point_lights;
mod references;
mod shards;
mod splat;
mod sppm;
mod textures;
mod vcm;
