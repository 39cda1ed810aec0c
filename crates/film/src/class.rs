//! The light-path classes: the one spelling of which family of light paths a contribution or
//! a layer belongs to, shared by the stages that split light (`eye`) and the ones that put it
//! back together (`composite`).

use std::fmt;
use std::str::FromStr;

/// Which family of light paths a contribution belongs to, in Heckbert's notation read from
/// the light: `L` light, `S` specular (delta) bounce, `D` non-delta (diffuse) bounce, `E` eye.
/// Every path from a light to the eye falls in exactly one class: the classes partition path
/// space, their sum is the full image, and layers over disjoint class sets add up without
/// counting any light twice.
///
/// The order of the variants (that of [`Class::ALL`]) is the canonical order used for sorting
/// classes and layers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Class {
    /// `L S* E`: emission seen directly or through specular chains.
    Emitted,
    /// `L D S* E`: one non-delta bounce, light arriving straight at the first non-delta
    /// vertex from the eye, by NEE or by a BSDF sample hitting the light (MIS-weighted).
    Direct,
    /// `L D (S* D)+ S* E`: two or more non-delta bounces, no specular one before the first
    /// from the light: light arriving without a specular bounce at the second or a later
    /// non-delta vertex from the eye (NEE, or a MIS-weighted BSDF hit of the light).
    Indirect,
    /// `L S+ D S* E`: a caustic, the specular chain from the light ends on the first
    /// non-delta vertex from the eye.
    Caustic,
    /// `L S+ D (S* D)+ S* E`: the specular chain from the light ends on a later non-delta
    /// vertex (caustics seen through at least one more diffuse bounce).
    CausticIndirect,
}

impl Class {
    /// All classes, in canonical order.
    pub const ALL: [Class; 5] = [
        Class::Emitted,
        Class::Direct,
        Class::Indirect,
        Class::Caustic,
        Class::CausticIndirect,
    ];

    /// The name: the film layer name of the eye pass and the class name in `image.json`.
    pub const fn name(self) -> &'static str {
        match self {
            Class::Emitted => "emitted",
            Class::Direct => "direct",
            Class::Indirect => "indirect",
            Class::Caustic => "caustic",
            Class::CausticIndirect => "caustic_indirect",
        }
    }

    /// The class of a [`Class::name`], if it is one.
    pub fn from_name(name: &str) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.name() == name)
    }

    /// True for both caustic classes.
    pub const fn is_caustic(self) -> bool {
        matches!(self, Class::Caustic | Class::CausticIndirect)
    }

    /// The paths of the class as a regular expression over `L`, `D`, `S`, `E`.
    pub const fn paths(self) -> &'static str {
        match self {
            Class::Emitted => "L S* E",
            Class::Direct => "L D S* E",
            Class::Indirect => "L D (S* D)+ S* E",
            Class::Caustic => "L S+ D S* E",
            Class::CausticIndirect => "L S+ D (S* D)+ S* E",
        }
    }
}

impl fmt::Display for Class {
    /// The [`Class::name`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Class {
    type Err = String;

    /// [`Class::from_name`]; the error names the unknown class and lists the valid names.
    fn from_str(s: &str) -> Result<Class, String> {
        Class::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = Class::ALL.iter().map(|c| c.name()).collect();
            format!(
                "unknown class \"{s}\" (expected one of {})",
                names.join(", ")
            )
        })
    }
}
