//! What every pass asks of a surface, decided once when the scene loads: its BSDF (or that
//! it absorbs), whether it is diffuse, which side of it a pair of directions lies on, and the
//! id a photon records for it. The eye pass and the photon pass read these, so they cannot
//! disagree about a material.

use crate::material::Material;
use crate::scene::Scene;
use bsdf::{
    Bsdf, Conductor, Dielectric, Glossy, Lambertian, Metal, Mirror, Plastic, RoughConductor,
    RoughDielectric, RoughPlastic, ThinDielectric,
};
use geom::{Hit, Prim, Ray};
use glam::{Vec2, Vec3};

/// Set in a surface id for a sphere; clear for a triangle.
pub const SPHERE_BIT: u32 = 0x8000_0000;

/// The scattering model of a material; `None` for a black Lambertian surface, which absorbs
/// everything: the eye pass ends its path there and photons are neither stored nor bounced.
pub fn bsdf_of(m: &Material) -> Option<Bsdf> {
    match *m {
        Material::Lambertian { albedo } => {
            (albedo.max_element() > 0.0).then_some(Lambertian { albedo }.into())
        }
        Material::Mirror { reflectance } => Some(Mirror { reflectance }.into()),
        Material::Metal { reflectance } => Some(Metal { reflectance }.into()),
        Material::Dielectric {
            ior, transmittance, ..
        } => Some(
            Dielectric {
                eta: ior,
                transmittance,
            }
            .into(),
        ),
        Material::Glossy {
            albedo,
            specular,
            alpha,
        } => Some(
            Glossy {
                albedo,
                specular,
                alpha,
            }
            .into(),
        ),
        Material::RoughConductor {
            reflectance,
            alpha,
            eta,
        } => Some(
            RoughConductor {
                alpha,
                reflectance,
                eta,
            }
            .into(),
        ),
        Material::Conductor { reflectance, eta } => {
            // No index: Mitsuba 3's `none`, `eta + i k = i`, whose Fresnel term is 1.
            let (eta, k) = eta.unwrap_or((Vec3::ZERO, Vec3::ONE));
            Some(
                Conductor {
                    eta,
                    k,
                    reflectance,
                }
                .into(),
            )
        }
        Material::Plastic {
            diffuse,
            specular,
            ior,
            nonlinear,
        } => Some(Plastic::new(diffuse, specular, ior, nonlinear).into()),
        Material::RoughPlastic {
            diffuse,
            specular,
            ior,
            alpha,
            nonlinear,
        } => Some(RoughPlastic::new(diffuse, specular, ior, alpha, nonlinear).into()),
        Material::ThinDielectric {
            ior,
            reflectance,
            transmittance,
        } => Some(
            ThinDielectric {
                eta: ior,
                reflectance,
                transmittance,
            }
            .into(),
        ),
        Material::RoughDielectric {
            ior,
            alpha,
            transmittance,
            ..
        } => Some(
            RoughDielectric {
                eta: ior,
                alpha,
                transmittance,
            }
            .into(),
        ),
    }
}

/// The surface id of a primitive: the triangle index, or the sphere index with
/// [`SPHERE_BIT`] set.
pub fn surface_id(prim: Prim) -> u32 {
    match prim {
        Prim::Triangle(i) => i,
        Prim::Sphere(i) => i | SPHERE_BIT,
    }
}

/// The shading-normal guard against light leaks (pbrt-v4 §10.1.1; Veach 1997 §5.3): a pair
/// of directions counts as reflection (or transmission) for the BSDF, which reads the
/// shading normal, only if the geometric normal `ng` agrees. Otherwise the pair would carry
/// light through the surface (or stop it at the surface) where the true geometry does the
/// opposite. `wo_l`, `wi_l` are the same directions in the shading frame.
#[inline]
pub fn sides_agree(wo: Vec3, wi: Vec3, ng: Vec3, wo_l: Vec3, wi_l: Vec3) -> bool {
    let geometric_reflection = wo.dot(ng) * wi.dot(ng) > 0.0;
    let shading_reflection = wo_l.z * wi_l.z > 0.0;
    geometric_reflection == shading_reflection
}

impl Scene {
    /// The BSDF of material `material` (`None`: it absorbs); see [`bsdf_of`].
    #[inline]
    pub fn bsdf(&self, material: u32) -> Option<Bsdf> {
        self.bsdfs[material as usize]
    }

    /// The BSDF at a surface point: [`Scene::bsdf`], its diffuse albedo read from the
    /// material's texture where it has one. Every pass asks this of its hits, so the eye
    /// pass, photon scattering, the estimates at receivers and splats see one albedo.
    #[inline]
    pub fn bsdf_at(&self, hit: &Hit) -> Option<Bsdf> {
        let b = self.bsdfs[hit.material as usize];
        match self.albedo_maps[hit.material as usize] {
            None => b,
            Some(map) => {
                let t = &self.textures[map.texture as usize];
                b.map(|b| b.with_diffuse_albedo(map.scale * t.eval(self.texcoord(hit))))
            }
        }
    }

    /// Texture coordinate of a hit: interpolated OBJ `vt` on triangles that have them, else
    /// the hit's own parameterisation (a triangle's barycentrics `(b1, b2)`, as Mitsuba 3
    /// reads a mesh without `vt`; a sphere's `(phi / 2pi, theta / pi)`).
    pub fn texcoord(&self, hit: &Hit) -> Vec2 {
        let own = Vec2::from(hit.uv);
        match hit.prim {
            Prim::Triangle(t) => self
                .geometry
                .mesh()
                .texcoord(t as usize, hit.uv)
                .unwrap_or(own),
            Prim::Sphere(_) => own,
        }
    }

    /// Diffuse: a BSDF with a diffuse lobe (Lambertian, or the Glossy model's Lambertian
    /// part) that reflects something. Photons are stored on diffuse surfaces, and photon-map
    /// eye passes estimate there; black, specular and purely glossy surfaces are not diffuse.
    #[inline]
    pub fn is_diffuse(&self, material: u32) -> bool {
        self.bsdfs[material as usize]
            .and_then(|b| b.diffuse_albedo())
            .is_some_and(|a| a.max_element() > 0.0)
    }

    /// Beer-Lambert transmittance of the segment of `ray` that ends at `hit` (pbrt-v4
    /// §11.1, Beer's law: `exp(-σa t)` per channel, `t` the segment's length): not 1 only when the
    /// segment ends on an absorbing glass from its inside, i.e. `ray.d` points along the
    /// geometric normal, which faces outwards (spheres) or to the shading normal's side
    /// (triangles), the side the dielectric BSDFs take as outside.
    ///
    /// Media are bounded by their glass surfaces and read from the surface a segment ends
    /// on, with no medium carried along the path (pbrt-v4's medium interfaces, without the
    /// medium a ray carries): every pass calls this one function at every hit, so the path
    /// tracer, the eye vertices and the photon tracers agree. Limitation: light travelling
    /// inside glass to something else inside it (an object or a light within the glass, or a
    /// second glass touching it) is not attenuated on that segment, and a camera inside
    /// glass sees the first segment unattenuated unless it ends on that glass.
    #[inline]
    pub fn transmittance_to(&self, hit: &Hit, ray: &Ray) -> Vec3 {
        let sigma = self.absorption[hit.material as usize];
        if sigma == Vec3::ZERO || ray.d.dot(hit.point.n) <= 0.0 {
            return Vec3::ONE;
        }
        (-sigma * (hit.t * ray.d.length())).exp()
    }

    /// Unit geometric normal of surface `id` (see [`surface_id`]) at a point `p` on it, or
    /// `None` for an id the scene does not have.
    pub fn surface_normal(&self, id: u32, p: Vec3) -> Option<Vec3> {
        let n = if id & SPHERE_BIT != 0 {
            let s = self.geometry.spheres().get((id & !SPHERE_BIT) as usize)?;
            (p - s.center).normalize_or_zero()
        } else {
            let t = id as usize;
            if t >= self.geometry.mesh().len() {
                return None;
            }
            self.geometry.mesh().face_normal(t).normalize_or_zero()
        };
        (n != Vec3::ZERO).then_some(n)
    }
}
