//! The one transform helper: a mesh's scale, rotation and translation, and an environment
//! map's rotation, both composed here in f64 with near-exact entries snapped.

use crate::file::{MeshDesc, Scale};
use glam::{DMat3, DMat4, DVec3};

/// Rotation about x, then y, then z by `degrees`, built in f64 with entries within 1e-12 of
/// 0 or ±1 snapped there, so a 90- or 180-degree turn keeps axis-aligned walls exact (an
/// f32 `cos 90°` is -4.4e-8, not 0). `None` unless every angle is finite.
pub(super) fn rotation(degrees: [f32; 3]) -> Option<DMat3> {
    let r = DVec3::new(degrees[0] as f64, degrees[1] as f64, degrees[2] as f64);
    if !r.is_finite() {
        return None;
    }
    let rot = DMat3::from_rotation_z(r.z.to_radians())
        * DMat3::from_rotation_y(r.y.to_radians())
        * DMat3::from_rotation_x(r.x.to_radians());
    let snap = |c: DVec3| {
        DVec3::from_array(c.to_array().map(|x| {
            if x.abs() < 1e-12 {
                0.0
            } else if (x.abs() - 1.0).abs() < 1e-12 {
                x.signum()
            } else {
                x
            }
        }))
    };
    Some(DMat3::from_cols(
        snap(rot.x_axis),
        snap(rot.y_axis),
        snap(rot.z_axis),
    ))
}

/// A mesh's transform: scale, then [`rotation`], then translate, then `matrix`. `None`
/// unless finite and invertible.
pub(super) fn transform(d: &MeshDesc) -> Option<DMat4> {
    let s = match d.scale {
        Scale::Uniform(s) => DVec3::splat(s as f64),
        Scale::PerAxis(a) => DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64),
    };
    let t = DVec3::new(
        d.translate[0] as f64,
        d.translate[1] as f64,
        d.translate[2] as f64,
    );
    if !(s.is_finite() && t.is_finite()) || s.x * s.y * s.z == 0.0 {
        return None;
    }
    let rot = rotation(d.rotate)?;
    let trs = DMat4::from_translation(t) * DMat4::from_mat3(rot * DMat3::from_diagonal(s));
    match d.matrix {
        None => Some(trs),
        Some(rows) => {
            let m = DMat4::from_cols_array_2d(&rows).transpose();
            let linear = DMat3::from_mat4(m).determinant();
            // The last row must be (0, 0, 0, 1): a projective matrix places no mesh.
            let affine = rows[3] == [0.0, 0.0, 0.0, 1.0];
            (m.is_finite() && affine && linear != 0.0 && linear.is_finite()).then_some(m * trs)
        }
    }
}
