use geom::Ray;
use glam::Vec3;

/// The course framework's pinhole camera: eye, look-at point, up vector and vertical field of
/// view. With 53.13 degrees the image plane spans [-0.5, 0.5] at focal distance 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    pub vfov_deg: f32,
    pub width: u32,
    pub height: u32,
    // Derived frame.
    forward: Vec3,
    right: Vec3,
    up_ortho: Vec3,
    half_h: f32,
    half_w: f32,
}

impl Camera {
    /// Returns `None` for a degenerate frame (eye on the look-at point, up parallel to the view
    /// direction) or a field of view outside (0, 180) degrees.
    pub fn new(
        eye: Vec3,
        look_at: Vec3,
        up: Vec3,
        vfov_deg: f32,
        width: u32,
        height: u32,
    ) -> Option<Camera> {
        let forward = (look_at - eye).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up_ortho = right.cross(forward);
        if !(vfov_deg > 0.0 && vfov_deg < 180.0) || width == 0 || height == 0 {
            return None;
        }
        let half_h = (0.5 * vfov_deg.to_radians()).tan();
        let half_w = half_h * width as f32 / height as f32;
        Some(Camera {
            eye,
            look_at,
            up,
            vfov_deg,
            width,
            height,
            forward,
            right,
            up_ortho,
            half_h,
            half_w,
        })
    }

    /// Primary ray through the film point `(x, y)` in pixel units: `(0, 0)` is the top-left
    /// corner of the image, `(width, height)` the bottom-right. Direction is unit length.
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let sx = (2.0 * x / self.width as f32 - 1.0) * self.half_w;
        let sy = (1.0 - 2.0 * y / self.height as f32) * self.half_h;
        let d = (self.forward + sx * self.right + sy * self.up_ortho).normalize();
        Ray::new(self.eye, d)
    }

    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Where the ray from the eye to `p` crosses the film, in [`Camera::ray`]'s pixel units,
    /// with that ray's unit direction and length; `None` when `p` is behind the eye or its
    /// ray leaves the film. The inverse of `ray`: a light path's vertex connected to the
    /// camera lands on this point.
    pub fn project(&self, p: Vec3) -> Option<Projection> {
        let to = p - self.eye;
        let dist = to.length();
        let z = to.dot(self.forward);
        if !(z > 0.0 && dist.is_finite()) {
            return None;
        }
        let sx = to.dot(self.right) / z / self.half_w;
        let sy = to.dot(self.up_ortho) / z / self.half_h;
        let x = 0.5 * (sx + 1.0) * self.width as f32;
        let y = 0.5 * (1.0 - sy) * self.height as f32;
        if !(x >= 0.0 && x < self.width as f32 && y >= 0.0 && y < self.height as f32) {
            return None;
        }
        let dir = to / dist;
        Some(Projection {
            pixel: (y as u32).min(self.height - 1) * self.width + (x as u32).min(self.width - 1),
            dir,
            dist,
            cos: dir.dot(self.forward),
        })
    }

    /// The importance `W_e` of a pixel for a ray leaving the eye at `cos` to the view axis,
    /// per unit of the ray's solid angle: `1 / (A cos^4 θ)`, `A` a pixel's area on the image
    /// plane at distance 1 (pbrt-v4 §5.4.1's `We` for a pinhole, normalised per pixel so a
    /// pixel's value is the mean radiance over it).
    pub fn importance(&self, cos: f32) -> f32 {
        let area = 4.0 * self.half_w * self.half_h / (self.width as f32 * self.height as f32);
        1.0 / (area * (cos * cos) * (cos * cos))
    }
}

/// A point seen by the camera ([`Camera::project`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Index of the pixel, `y * width + x`.
    pub pixel: u32,
    /// Unit direction from the eye to the point.
    pub dir: Vec3,
    /// Distance from the eye to the point.
    pub dist: f32,
    /// Cosine between `dir` and the view axis.
    pub cos: f32,
}
