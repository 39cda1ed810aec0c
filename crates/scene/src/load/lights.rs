//! Lights from the scene: emissive triangles found in the mesh (their material's emission)
//! and the scene file's `[[light]]` tables, each checked and turned into a [`Light`], then
//! the [`LightTable`] over all of them.

use super::{Builder, MAX_COORD};
use crate::envmap::EnvMap;
use crate::error::SceneError;
use crate::file::{EmissionSource, LightDesc, SceneFile};
use crate::lights::{
    AreaLight, Directional, Environment, Light, LightTable, PointLight, Sphere, SpotLight, Sun,
};
use crate::texture::Texture;
use glam::{DVec3, Vec3};
use math::Frame;
use rayon::prelude::*;

/// True for a finite point farther out than any vertex may lie.
fn beyond(p: Vec3) -> bool {
    p.is_finite() && p.abs().max_element() as f64 > MAX_COORD
}

/// Delta lights' power does not depend on the scene's bounding sphere.
const NO_SPHERE: Sphere = Sphere {
    center: Vec3::ZERO,
    radius: 0.0,
};

impl Builder<'_> {
    /// The emissive triangles and the table of every light. Refuses a scene without light,
    /// with an absurd light, or with a light at infinity but no extent to shine on.
    pub(super) fn lights(
        &mut self,
        file: &SceneFile,
    ) -> Result<(Vec<AreaLight>, LightTable), SceneError> {
        let mut lights = Vec::new();
        // The emitting triangles (and any with an unknown material, for its error below) found
        // on every core, in order: a large mesh has few.
        let emits: Vec<bool> = (self.emission.iter())
            .map(|e| e.max_element() > 0.0 || e.max_element().is_nan())
            .collect();
        let found: Vec<(usize, u32)> = (self.mesh.materials.par_iter().enumerate())
            .filter(|&(_, &mat)| emits.get(mat as usize).copied().unwrap_or(true))
            .map(|(t, &mat)| (t, mat))
            .collect();
        for (t, mat) in found {
            let e = *self.of_material(&self.emission, mat)?;
            if e.max_element() <= 0.0 {
                continue;
            }
            let area = self.mesh.area(t);
            // In f64: an f32 cross product of a huge triangle overflows while normalising.
            let [p0, p1, p2] = self.mesh.vertices(t).map(|p| p.as_dvec3());
            let n = (p1 - p0).cross(p2 - p0).normalize_or_zero().as_vec3();
            let name = self.of_material(&self.names, mat)?;
            if area.is_infinite() || !n.is_finite() {
                return Err(self.err(format!(
                    "light triangle {t} (material `{name}`) is too large for f32 (area {area}): \
                     check the mesh's scale"
                )));
            }
            if area.is_nan() || area <= 0.0 || n == Vec3::ZERO {
                return Err(self.err(format!(
                    "zero-area light: triangle {t} (material `{name}`) emits but has no area"
                )));
            }
            let power = (std::f64::consts::PI * area as f64 * e.as_dvec3()).as_vec3();
            if !power.is_finite() {
                return Err(self.err(format!(
                    "light triangle {t} (material `{name}`): power pi * area * Le = {} x {:?} \
                     overflows f32",
                    std::f64::consts::PI * area as f64,
                    e.to_array()
                )));
            }
            lights.push(AreaLight {
                triangle: t as u32,
                area,
                le: e,
                normal: n,
                power,
            });
        }
        let total = lights
            .iter()
            .fold(DVec3::ZERO, |a, l| a + l.power.as_dvec3());
        if !total.as_vec3().is_finite() {
            return Err(self.err(format!(
                "the lights' total power {:?} overflows f32: emission or light size is absurd",
                total.to_array()
            )));
        }
        let mut others = self.delta_lights(&file.lights)?;
        let infinite = self.infinite_lights(&file.lights)?;
        let at_infinity = !infinite.is_empty();
        others.extend(infinite);
        if lights.is_empty() && others.is_empty() {
            let hint = if file
                .meshes
                .iter()
                .any(|m| m.obj.is_some() && m.emission == EmissionSource::Ke)
            {
                " (hint: the course's MTL files keep emission in Ka: set emission = \"ka\" on the mesh)"
            } else {
                ""
            };
            return Err(self.err(format!(
                "the scene has no light: no triangle emits and no [[light]] is given{hint}"
            )));
        }
        for s in &self.spheres {
            if self.of_material(&self.emission, s.material)?.max_element() > 0.0 {
                return Err(self.err("emissive spheres are not supported: lights are triangles"));
            }
        }

        let bounds = self.spheres.iter().fold(self.mesh.bounds(), |b, s| {
            b.union_point(s.center - Vec3::splat(s.radius))
                .union_point(s.center + Vec3::splat(s.radius))
        });
        if at_infinity && (bounds.is_empty() || !(bounds.max - bounds.min).is_finite()) {
            return Err(self
                .err("a light at infinity needs a scene of finite, non-empty extent to shine on"));
        }
        let Some(light_table) = LightTable::new(&self.mesh, &lights, others, bounds) else {
            return Err(self.err("the lights' total power is zero: no light can be sampled"));
        };
        if !light_table.total_power().as_vec3().is_finite() {
            return Err(self.err(
                "the lights' total power overflows f32: a light's value is absurd for the scene's size",
            ));
        }
        Ok((lights, light_table))
    }

    /// The scene file's point and spot lights, checked one by one (Mitsuba 3's `point` and
    /// `spot`; angles in degrees there, radians here).
    fn delta_lights(&self, descs: &[LightDesc]) -> Result<Vec<Light>, SceneError> {
        let mut out = Vec::with_capacity(descs.len());
        for (i, desc) in descs.iter().enumerate() {
            let bad = |what: &str| self.err(format!("light {i} ({}): {what}", desc.kind()));
            let (position, intensity) = match desc {
                LightDesc::Point {
                    position,
                    intensity,
                }
                | LightDesc::Spot {
                    position,
                    intensity,
                    ..
                } => (Vec3::from(*position), Vec3::from(*intensity)),
                LightDesc::Directional { .. } | LightDesc::Environment { .. } => continue,
            };
            if !position.is_finite() {
                return Err(bad("position must be finite"));
            }
            // Past the bound vertices have, a light's irradiance underflows f32: the scene
            // renders black without a word.
            if beyond(position) {
                return Err(bad(&format!(
                    "position {:?} lies beyond the {MAX_COORD:e} scene units photonflow can \
                     trace",
                    position.to_array()
                )));
            }
            if !intensity.is_finite() || intensity.min_element() < 0.0 {
                return Err(bad("intensity must be finite and >= 0"));
            }
            if intensity.max_element() <= 0.0 {
                return Err(bad(
                    "intensity must not be zero: the light would emit nothing",
                ));
            }
            let light = match *desc {
                LightDesc::Point { .. }
                | LightDesc::Directional { .. }
                | LightDesc::Environment { .. } => Light::Point(PointLight {
                    position,
                    intensity,
                }),
                LightDesc::Spot {
                    look_at,
                    cutoff_angle,
                    beam_width,
                    ..
                } => {
                    if beyond(Vec3::from(look_at)) {
                        return Err(bad(&format!(
                            "look_at {look_at:?} lies beyond the {MAX_COORD:e} scene units \
                             photonflow can trace"
                        )));
                    }
                    let axis = (Vec3::from(look_at) - position).normalize_or_zero();
                    if !Vec3::from(look_at).is_finite() || axis == Vec3::ZERO {
                        return Err(bad("look_at must be finite and differ from position"));
                    }
                    if !(cutoff_angle > 0.0 && cutoff_angle <= 90.0) {
                        return Err(bad(&format!(
                            "cutoff_angle = {cutoff_angle} must be in (0, 90] degrees"
                        )));
                    }
                    let beam = beam_width.unwrap_or(cutoff_angle * 0.75);
                    if !(beam >= 0.0 && beam <= cutoff_angle) {
                        return Err(bad(&format!(
                            "beam_width = {beam} must be in [0, cutoff_angle = {cutoff_angle}] degrees"
                        )));
                    }
                    Light::Spot(SpotLight {
                        position,
                        intensity,
                        frame: Frame::from_z(axis),
                        cutoff: cutoff_angle.to_radians(),
                        beam: beam.to_radians(),
                    })
                }
            };
            if !light.power(&NO_SPHERE).as_vec3().is_finite() {
                return Err(bad("power overflows f32: intensity is absurd"));
            }
            out.push(light);
        }
        Ok(out)
    }

    /// The scene file's directional lights and environment maps, checked one by one, numbered
    /// as in the file like the point and spot lights. An environment image is read (and
    /// hashed) here, relative to the scene file.
    fn infinite_lights(&mut self, descs: &[LightDesc]) -> Result<Vec<Light>, SceneError> {
        let mut out = Vec::new();
        for (i, desc) in descs.iter().enumerate() {
            let bad = |b: &Self, what: &str| b.err(format!("light {i} ({}): {what}", desc.kind()));
            match desc {
                LightDesc::Point { .. } | LightDesc::Spot { .. } => {}
                LightDesc::Directional {
                    direction,
                    irradiance,
                    angular_radius,
                } => {
                    let to_light = -Vec3::from(*direction).normalize_or_zero();
                    if !Vec3::from(*direction).is_finite() || to_light == Vec3::ZERO {
                        return Err(bad(self, "direction must be finite and not zero"));
                    }
                    let e = Vec3::from(*irradiance);
                    if !e.is_finite() || e.min_element() < 0.0 {
                        return Err(bad(self, "irradiance must be finite and >= 0"));
                    }
                    if e.max_element() <= 0.0 {
                        return Err(bad(
                            self,
                            "irradiance must not be zero: the light would emit nothing",
                        ));
                    }
                    out.push(match *angular_radius {
                        None => Light::Directional(Directional {
                            to_light,
                            irradiance: e,
                        }),
                        Some(a) if a > 0.0 && a <= 90.0 => {
                            Light::Sun(Sun::new(to_light, e, a.to_radians()))
                        }
                        Some(a) => {
                            return Err(bad(
                                self,
                                &format!("angular_radius = {a} must be in (0, 90] degrees"),
                            ));
                        }
                    });
                }
                LightDesc::Environment {
                    filename,
                    radiance,
                    scale,
                    rotate,
                } => {
                    if !(scale.is_finite() && *scale > 0.0) {
                        return Err(bad(
                            self,
                            &format!("scale = {scale} must be finite and > 0"),
                        ));
                    }
                    let Some(to_world) = super::transform::rotation(*rotate) else {
                        return Err(bad(self, "rotate must be finite"));
                    };
                    let to_world = to_world.as_mat3();
                    let env = match (filename, radiance) {
                        (Some(_), Some(_)) | (None, None) => {
                            return Err(bad(
                                self,
                                "give either filename (an image) or radiance (a constant colour)",
                            ));
                        }
                        (None, Some(c)) => EnvMap::constant(Vec3::from(*c), *scale, to_world)
                            .map_err(|e| bad(self, &e))?,
                        (Some(f), None) => {
                            let path = self.dir.join(f);
                            let bytes = super::read_regular(&path).map_err(|e| {
                                bad(
                                    self,
                                    &format!(
                                        "environment map `{f}` ({}): cannot read it: {e}",
                                        path.display()
                                    ),
                                )
                            })?;
                            self.hash.write(&bytes);
                            let t = Texture::decode(&bytes, &path).map_err(|e| {
                                bad(
                                    self,
                                    &format!("environment map `{f}` ({}): {e}", path.display()),
                                )
                            })?;
                            EnvMap::from_image(t.width, t.height, t.texels, *scale, to_world)
                                .map_err(|e| bad(self, &format!("environment map `{f}`: {e}")))?
                        }
                    };
                    out.push(Light::Environment(Environment {
                        map: Box::new(env),
                        file: filename.clone(),
                    }));
                }
            }
        }
        Ok(out)
    }
}
