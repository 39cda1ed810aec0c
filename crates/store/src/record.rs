use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

/// Which photon map a set belongs to (Jensen 2001, ch. 6): global photons are stored at every
/// diffuse hit; caustic photons only at the first diffuse hit after one or more specular
/// bounces (paths L S+ D).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum MapKind {
    Global = 1,
    Caustic = 2,
}

impl MapKind {
    /// Every kind, in slot order.
    pub const ALL: [MapKind; 2] = [MapKind::Global, MapKind::Caustic];

    /// Position in [`MapKind::ALL`] and in a [`PerKind`].
    pub const fn slot(self) -> usize {
        self as usize - 1
    }

    /// Lower-case name, as in cache file names and messages.
    pub const fn name(self) -> &'static str {
        match self {
            MapKind::Global => "global",
            MapKind::Caustic => "caustic",
        }
    }
}

/// One value per photon map kind, indexed by [`MapKind`]: photon sets are keyed by kind, so
/// a new kind is one enum arm, not a new field in every struct that carries sets.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PerKind<T>(pub [T; 2]);

impl<T> PerKind<T> {
    /// `(kind, value)` in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (MapKind, &T)> {
        MapKind::ALL.into_iter().zip(self.0.iter())
    }
}

impl<T> std::ops::Index<MapKind> for PerKind<T> {
    type Output = T;
    fn index(&self, k: MapKind) -> &T {
        &self.0[k.slot()]
    }
}

impl<T> std::ops::IndexMut<MapKind> for PerKind<T> {
    fn index_mut(&mut self, k: MapKind) -> &mut T {
        &mut self.0[k.slot()]
    }
}

/// One stored photon: 32 bytes, `#[repr(C)]` with no padding, so a file's payload is read by
/// casting bytes (bytemuck) instead of decoding them.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Photon {
    /// Position on the surface.
    pub pos: [f32; 3],
    /// Flux (power) carried, RGB, in watts of the scene's units.
    pub power: [f32; 3],
    /// Direction the photon travelled *towards* the surface, octahedral-encoded (unit vector
    /// in 2 x 16 bits; error below 1e-4 rad; Cigolle et al. 2014, "A Survey of Efficient
    /// Representations for Independent Unit Vectors", JCGT 3(2)).
    pub dir: u32,
    /// Primitive the photon landed on (triangle id, or sphere id with the top bit set): lets
    /// an estimator keep photons from one surface only.
    pub surface: u32,
}

const _: () = assert!(std::mem::size_of::<Photon>() == 32);

impl Photon {
    pub fn new(pos: Vec3, power: Vec3, dir: Vec3, surface: u32) -> Photon {
        Photon {
            pos: pos.to_array(),
            power: power.to_array(),
            dir: oct_encode(dir),
            surface,
        }
    }

    pub fn position(&self) -> Vec3 {
        Vec3::from(self.pos)
    }

    pub fn power(&self) -> Vec3 {
        Vec3::from(self.power)
    }

    /// Unit direction of travel (towards the surface).
    pub fn direction(&self) -> Vec3 {
        oct_decode(self.dir)
    }
}

fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 { 1.0 } else { -1.0 }
}

/// Octahedral encoding of a unit vector into 2 x 16-bit snorm values.
pub fn oct_encode(v: Vec3) -> u32 {
    let v = v / (v.x.abs() + v.y.abs() + v.z.abs());
    let p = if v.z >= 0.0 {
        Vec2::new(v.x, v.y)
    } else {
        Vec2::new(
            (1.0 - v.y.abs()) * sign_not_zero(v.x),
            (1.0 - v.x.abs()) * sign_not_zero(v.y),
        )
    };
    let q = |x: f32| ((x.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    q(p.x) | (q(p.y) << 16)
}

/// Inverse of [`oct_encode`].
pub fn oct_decode(e: u32) -> Vec3 {
    let f = |b: u32| (b as u16 as i16) as f32 / 32767.0;
    let (x, y) = (f(e & 0xffff), f(e >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        (
            (1.0 - y.abs()) * sign_not_zero(x),
            (1.0 - x.abs()) * sign_not_zero(y),
        )
    } else {
        (x, y)
    };
    Vec3::new(x, y, z).normalize()
}
