//! A vertex as both subpaths use it: the BSDF towards a direction with its densities both
//! ways (every strategy's weight reads them), and the way on sampled. Sides are decided by
//! the geometric normal, as in the photon tracer, so no path leaks through a surface.

use bsdf::{Bsdf, BsdfSample, TransportMode};
use glam::Vec3;
use math::Frame;
use scene::sides_agree;

/// A vertex a subpath reached along `-wo`.
pub(crate) struct Surface {
    pub bsdf: Bsdf,
    pub frame: Frame,
    /// Geometric normal.
    pub ng: Vec3,
    /// Unit direction back the way the subpath came, in the world and in the shading frame.
    pub wo: Vec3,
    pub wo_l: Vec3,
    /// Radiance for eye subpaths, importance for light subpaths.
    pub mode: TransportMode,
}

/// [`Surface::eval`]'s answer.
pub(crate) struct Eval {
    pub f: Vec3,
    /// Density of sampling `wi` given `wo`, and of sampling `wo` given `wi`.
    pub dir: f32,
    pub rev: f32,
    /// `|cos|` at `wi` (shading normal).
    pub cos: f32,
}

impl Surface {
    pub fn new(bsdf: Bsdf, ns: Vec3, ng: Vec3, wo: Vec3, mode: TransportMode) -> Surface {
        let frame = Frame::from_z(ns);
        Surface {
            bsdf,
            frame,
            ng,
            wo,
            wo_l: frame.to_local(wo),
            mode,
        }
    }

    /// The BSDF towards unit `wi`; `None` where no light passes.
    pub fn eval(&self, wi: Vec3) -> Option<Eval> {
        let wi_l = self.frame.to_local(wi);
        if !sides_agree(self.wo, wi, self.ng, self.wo_l, wi_l) {
            return None;
        }
        let f = self.bsdf.f(self.wo_l, wi_l, self.mode);
        if f == Vec3::ZERO {
            return None;
        }
        Some(Eval {
            f,
            dir: self.bsdf.pdf(self.wo_l, wi_l),
            rev: self.bsdf.pdf(wi_l, self.wo_l),
            cos: wi_l.z.abs(),
        })
    }

    /// The way on, from uniforms `uc`, `u`: the unit world direction, the sample and the
    /// reverse density (of sampling `wo` given it; a delta lobe's equals its own). `None`
    /// when the path ends here (absorbed, or the normals disagree about a side).
    pub fn sample(&self, uc: f32, u: [f32; 2]) -> Option<(Vec3, BsdfSample, f32)> {
        if self.wo_l.z * self.wo.dot(self.ng) <= 0.0 {
            return None;
        }
        let s = self.bsdf.sample(self.wo_l, uc, u, self.mode)?;
        let wi = self.frame.to_world(s.wi).normalize();
        if !sides_agree(self.wo, wi, self.ng, self.wo_l, s.wi) {
            return None;
        }
        let rev = if s.is_specular() {
            s.pdf
        } else {
            self.bsdf.pdf(s.wi, self.wo_l)
        };
        Some((wi, s, rev))
    }
}
