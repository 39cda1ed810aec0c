//! The effects plan: which photon sets a run needs, decided from the scene before tracing.

use crate::EmitParams;
use scene::{Material, Scene};
use serde::Serialize;
use std::fmt;

/// Which photon sets a run traces, and why. Printed before a run and saved with its outputs
/// (it is `Serialize`), so a missing caustic map is explained, not discovered.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plan {
    /// Trace the global set (photons at every diffuse hit).
    pub global: bool,
    /// Trace the caustic set (photons at the first diffuse hit of L S+ D paths).
    pub caustic: bool,
    /// One line per set: traced or skipped, and the reason.
    pub reasons: Vec<String>,
    /// Number of emitting triangles.
    pub lights: usize,
    /// Total emitted power, RGB.
    pub power: [f64; 3],
    /// Photon paths to emit.
    pub photons: u64,
}

/// A run that cannot be planned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlanError {
    /// `photons = 0`: the flux `Φ / N` is undefined.
    NoPhotons,
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::NoPhotons => write!(f, "photons = 0: emit at least one photon path"),
        }
    }
}

impl std::error::Error for PlanError {}

impl Plan {
    /// Decide the photon sets from the materials the scene's primitives actually use.
    /// Specular: mirror, metal or dielectric. Diffuse: Lambertian with a non-zero albedo (a
    /// black surface reflects nothing, so photons stored there could never be seen).
    /// - no diffuse surface → no global set, and no caustic set (nowhere to store it);
    /// - no specular surface → no caustic set (no path can be L S+ D).
    ///
    /// A loaded scene always has a light with positive power (its `light_table`).
    pub fn for_scene(scene: &Scene, params: &EmitParams) -> Result<Plan, PlanError> {
        let power = scene.light_table.total_power();
        if params.photons == 0 {
            return Err(PlanError::NoPhotons);
        }

        let geometry = &scene.geometry;
        let mut used = vec![false; scene.materials.len()];
        for &m in &geometry.mesh().materials {
            used[m as usize] = true;
        }
        for s in geometry.spheres() {
            used[s.material as usize] = true;
        }
        let names = |pred: &dyn Fn(u32, &Material) -> bool| -> Vec<&str> {
            (0..scene.materials.len())
                .filter(|&m| used[m] && pred(m as u32, &scene.materials[m]))
                .map(|m| scene.material_names[m].as_str())
                .collect()
        };
        let diffuse = names(&|m, _| scene.is_diffuse(m));
        let specular = names(&|_, m| m.is_specular());

        let mut reasons = Vec::new();
        let global = params.global && !diffuse.is_empty();
        reasons.push(if !params.global {
            "global photons: skipped (not requested)".to_string()
        } else if diffuse.is_empty() {
            "global photons: skipped (no diffuse surface in the scene)".to_string()
        } else {
            format!(
                "global photons: traced (diffuse surfaces: {}; direct hits {})",
                diffuse.join(", "),
                if params.store_direct {
                    "stored"
                } else {
                    "not stored"
                }
            )
        });
        let caustic = params.caustic && !specular.is_empty() && !diffuse.is_empty();
        reasons.push(if !params.caustic {
            "caustic photons: skipped (not requested)".to_string()
        } else if specular.is_empty() {
            "caustic photons: skipped (no specular surface in the scene)".to_string()
        } else if diffuse.is_empty() {
            "caustic photons: skipped (no diffuse surface to store them on)".to_string()
        } else {
            format!(
                "caustic photons: traced (specular surfaces: {})",
                specular.join(", ")
            )
        });
        // Each light says what the methods do with it (delta lights: only photons find
        // their caustics; lights at infinity: photons from a disc).
        reasons.extend(
            scene
                .light_table
                .lights()
                .filter_map(scene::Light::plan_line),
        );
        let glossy = names(&|m, _| scene.bsdf(m).is_some_and(|b| b.is_glossy()));
        if !glossy.is_empty() {
            reasons.push(format!(
                "glossy surfaces ({}): photons scatter off them by sampling the BSDF and are \
                 stored only where there is a diffuse lobe; eye paths follow their GGX lobes \
                 as paths (a glossy bounce ends a caustic chain: light it passes on is the \
                 global map's and the path tracer's, not the caustic map's or the splats')",
                glossy.join(", ")
            ));
        }
        let tinted = names(&|_, m| m.is_tinted());
        if !tinted.is_empty() {
            reasons.push(format!(
                "coloured or absorbing glass ({}): light crossing it is scaled by its \
                 transmittance at each crossing and by exp(-absorption x distance) inside, for \
                 photons and eye paths alike (caustics behind it take its colour)",
                tinted.join(", ")
            ));
        }
        let textured = names(&|m, _| scene.albedo_maps[m as usize].is_some());
        if !textured.is_empty() {
            reasons.push(format!(
                "textured surfaces ({}): every method reads the albedo from the texture where \
                 light meets them: eye paths, photons scattering off them, the estimates and \
                 splats at their eye vertices",
                textured.join(", ")
            ));
        }
        if !global && !caustic {
            reasons.push("photon tracing: skipped (no photon set to fill)".to_string());
        }
        if diffuse.is_empty() {
            // A valid scene, and its image is well defined: say what it holds.
            reasons.push(
                "image: no surface is diffuse (all black or specular), so direct light, \
                 caustics and indirect light are black everywhere; only emitters, seen directly \
                 or through specular surfaces, show"
                    .to_string(),
            );
        }
        Ok(Plan {
            global,
            caustic,
            reasons,
            lights: scene.lights.len(),
            power: power.to_array(),
            photons: params.photons,
        })
    }

    /// True when no photon set is traced at all.
    pub fn is_empty(&self) -> bool {
        !self.global && !self.caustic
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [r, g, b] = self.power;
        writeln!(
            f,
            "effects plan: {} photon paths from {} light triangle(s), total power ({r:.4}, {g:.4}, {b:.4})",
            self.photons, self.lights
        )?;
        for line in &self.reasons {
            writeln!(f, "  {line}")?;
        }
        Ok(())
    }
}
