//! MTL materials: the MTL spec's `illum` models, the course framework's `illum 11` metal and
//! `Ka` emission, turned into [`crate::Material`]s. This table is the one statement of the
//! mapping (README.md repeats it, held to it by a test):
//!
//! OBJ meshes take their materials from MTL files by this table. What photonflow cannot draw is
//! refused with one line naming the MTL file, the material and the key; what it approximates
//! prints one `warning:` line per material and key.
//!
//! | MTL | drawn as |
//! |---|---|
//! | `illum 0`, `1`, no `illum` | Lambertian `Kd` (a `Ks` there is not drawn: warning) |
//! | `illum 2` | Lambertian `Kd`, plus with `Ks > 0` a GGX lobe of constant reflectance `Ks` (no Fresnel) of roughness α = √(2 / (`Ns` + 2)) (Walter et al. 2007); where `Kd + Ks` exceeds 1 in a channel both are scaled there to sum to 1 (warning) |
//! | `illum 3`, `5`, `8` | mirror of reflectance `Ks` (1 where `Ks` is absent or black); illum 5's Fresnel term and illum 8's "ray trace off" are not modelled, nor a `Kd` beside the mirror (warnings) |
//! | `illum 4`, `6`, `7`, `9` | glass of index `Ni` and transmittance `Tf`, exact Fresnel reflection and refraction (index 1.5 where `Ni` is absent or in [0, 1], and illum 6's and 9's variants: warnings; a negative or NaN `Ni` is refused) |
//! | `illum 10` | refused (shadow matte) |
//! | `illum 11` | the course's metal: constant reflectance `Ks` |
//! | `d < 1`, `Tr > 0` | glass (illum 4, 6, 7, 9, or the course's illum 0-2 with `Ni > 1`); refused on any other surface. `d` and `Tr` both given and disagreeing (`Tr` is 1 - `d`): `d` is used (warning) |
//! | `newmtl` of a name defined before | the last definition is used, as other loaders do (warning) |
//! | `Ke` | emitted radiance (`emission = "ke"`, the default) |
//! | `Ka` | emitted radiance with `[[mesh]] emission = "ka"` (the course's convention; a material with `Ke` too is refused); otherwise the ambient colour, which a physically based renderer does not use |
//! | `Ni` | the index of refraction of glass; not read elsewhere |
//! | `Ks` | the specular colour of illum 2, 3, 5, 8 and 11 (above; elsewhere: warning); negative or NaN in a channel, refused whatever the `illum` |
//! | `Tf` | on glass, its transmittance: a factor on refracted light at every crossing, each channel in [0, 1] (refused outside it); warning elsewhere. With `[[mesh]] tf = "absorbed"` the glass keeps `1 - Tf` instead: G3D's reading, in which Morgan McGuire's Cornell boxes are written (their `Tf 0.1` is clear glass). Glass that would keep less than half the light at a crossing in every channel is drawn so with a warning naming the other reading. Absent, clear glass either way. Absorption inside glass has no MTL key: use the scene file's `absorption` |
//! | `map_Kd` | the diffuse albedo's texture, times `Kd` (the MTL spec's product; the texture alone where `Kd` is absent): PNG, JPEG, TGA or EXR, relative to the MTL file; 8-bit and 16-bit images are sRGB-decoded, EXR is linear; read at the OBJ's `vt` (without them, at each triangle's barycentrics: warning), bilinear, repeated. On illum 0-2 only (elsewhere: warning, drawn without). Where `Kd` x the brightest texel (+ `Ks` on illum 2) exceeds 1 in a channel, they are scaled there to 1 (warning). A missing or unreadable image, or texture options (`-s`, `-o`, ...), are refused |
//! | `map_Ks`, `map_d` | refused (of the texture maps only `map_Kd` is rendered) |
//! | `bump`, `map_Bump`, `map_Ns`, `refl`, `disp`, `decal` | warning: drawn without |
//! | `Pr`, `Pm`, `Ps`, `Pc`, `Pcr`, `aniso`, `anisor`, `map_Pr`, `map_Pm` (the PBR extension) | refused |

use super::materials::{check, in_unit};
use crate::file::{EmissionSource, TfReading};
use crate::material::ALPHA_RANGE;
use crate::material::Material;
use glam::Vec3;

/// The MTL text checked line by line before tobj reads it: a value tobj cannot parse (it
/// says only "material parse error") is refused here naming its line and text. Colours
/// (`Ka`, `Kd`, `Ks`, `Ke`, `Tf`) given with one number are grey, a variant real MTL files
/// use: written out as three numbers here, since tobj panics on fewer than three. Two
/// numbers or none is an error naming the line.
pub(super) fn prescan(bytes: &[u8]) -> Result<Vec<u8>, String> {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Err("not UTF-8 text".into());
    };
    let mut out = String::with_capacity(text.len() + 64);
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let n = i + 1;
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else {
            out.push_str(line);
            continue;
        };
        let args: Vec<&str> = words.collect();
        let is_number = |w: &&str| w.parse::<f32>().is_ok();
        let not_a_number = |w: &str, hint: &str| {
            Err(format!(
                "line {n}: `{}`: `{w}` is not a number{hint}",
                line.trim()
            ))
        };
        match key {
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => {
                if let Some(w) = args.iter().take(3).find(|w| !is_number(w)) {
                    let hint = if matches!(args.first(), Some(&("spectral" | "xyz"))) {
                        " (the spectral and xyz forms are not read: give RGB)"
                    } else {
                        ""
                    };
                    return not_a_number(w, hint);
                }
                match args.as_slice() {
                    [v] => {
                        out.push_str(&format!("{key} {v} {v} {v}\n"));
                        continue;
                    }
                    [] | [_, _] => {
                        return Err(format!(
                            "line {n}: `{key}` needs one number (grey) or three (RGB), got {}",
                            args.len()
                        ));
                    }
                    _ => {}
                }
            }
            // tobj reads the first word of these as a number and ignores the rest.
            "Ns" | "Ni" | "d" | "Tr" => match args.first() {
                None => return Err(format!("line {n}: `{key}` needs a number")),
                Some(w) if !is_number(w) => return not_a_number(w, ""),
                Some(_) => {}
            },
            "illum" if args.first().is_none_or(|w| w.parse::<u8>().is_err()) => {
                return Err(format!(
                    "line {n}: `{}`: the illumination model must be a whole number (the MTL \
                     spec's 0-10, the course's 11)",
                    line.trim()
                ));
            }
            "newmtl" if args.is_empty() => {
                return Err(format!("line {n}: `newmtl` needs a material name"));
            }
            "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns"
            | "map_NS" | "bump" | "map_d"
                if args.is_empty() =>
            {
                return Err(format!("line {n}: `{key}` needs an image file name"));
            }
            _ => {}
        }
        out.push_str(line);
    }
    Ok(out.into_bytes())
}

/// An MTL material turned into one of photonflow's: the material, its emission, and a line
/// for each thing it approximates (printed as `warning:` lines).
pub(super) struct Converted {
    pub(super) material: Material,
    pub(super) emission: Vec3,
    /// `map_Kd`'s file name, relative to the MTL file.
    pub(super) albedo_map: Option<String>,
    pub(super) warnings: Vec<String>,
}

/// MTL keys that change a surface's look but that photonflow does not read: a file that sets
/// one is refused (`error`) or warned about (`warning`), never silently drawn otherwise.
const UNREAD_KEYS: [(&str, &str); 12] = [
    ("Pr", "error"),
    ("Pm", "error"),
    ("Ps", "error"),
    ("Pc", "error"),
    ("Pcr", "error"),
    ("aniso", "error"),
    ("anisor", "error"),
    ("map_Pr", "error"),
    ("map_Pm", "error"),
    ("refl", "warning"),
    ("disp", "warning"),
    ("decal", "warning"),
];

/// The keys of an MTL material that every `illum` model reads alike, checked.
struct Keys {
    kd: Vec3,
    albedo_map: Option<String>,
    emission: Vec3,
    /// `d`, or `1 - Tr`.
    opacity: f32,
    tf: Option<Vec3>,
    tf_text: String,
    warnings: Vec<String>,
}

/// Reads [`Keys`]; refuses keys photonflow does not read (`UNREAD_KEYS`, texture maps other
/// than `map_Kd`) and warns of those it draws without.
fn read_keys(m: &tobj::Material, emission: EmissionSource) -> Result<Keys, String> {
    let v = |a: Option<[f32; 3]>| a.map(Vec3::from).unwrap_or(Vec3::ZERO);
    let mut warnings = Vec::new();
    // The MTL spec multiplies `map_Kd` by `Kd`; a texture without a `Kd` is drawn as it is.
    let albedo_map = m.diffuse_texture.clone();
    let kd = match (m.diffuse, &albedo_map) {
        (None, Some(_)) => Vec3::ONE,
        (kd, _) => v(kd),
    };
    if let Some(t) = &albedo_map {
        if t.trim_start().starts_with('-') {
            return Err(format!(
                "`map_Kd {t}`: texture options (-s, -o, -clamp, ...) are not read; give the \
                 image file alone"
            ));
        }
        if kd == Vec3::ZERO {
            warnings.push(format!(
                "`map_Kd {t}` with `Kd 0 0 0`: the MTL spec multiplies the two, so the surface \
                 is black"
            ));
        }
    }
    let e = match emission {
        EmissionSource::Ke => v(m.emissive),
        EmissionSource::Ka => {
            if let Some(ke) = m.emissive.filter(|k| k.iter().any(|&c| c != 0.0)) {
                return Err(format!(
                    "`Ke {} {} {}` is not read: the scene file reads emission from `Ka` \
                     (emission = \"ka\"); drop `Ke`, or set emission = \"ke\" and move the \
                     emission there",
                    ke[0], ke[1], ke[2]
                ));
            }
            v(m.ambient)
        }
    };
    // `Tr` is `1 - d` (some exporters write one, some the other).
    let tr = match m.unknown_param.get("Tr") {
        Some(t) => Some(
            t.trim()
                .parse::<f32>()
                .map_err(|_| format!("`Tr {t}`: not a number"))?,
        ),
        None => None,
    };
    let opacity = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
    if let (Some(d), Some(t)) = (m.dissolve, tr)
        && (d - (1.0 - t)).abs() > 1e-3
    {
        warnings.push(format!(
            "`d {d}` and `Tr {t}` disagree (`Tr` is 1 - `d`): `d` is used, opacity {d}"
        ));
    }
    if !(0.0..=1.0).contains(&opacity) {
        return Err(format!("`d`/`Tr`: opacity {opacity} must lie in [0, 1]"));
    }
    let tf_text = m.unknown_param.get("Tf").cloned().unwrap_or_default();
    let tf = match m.unknown_param.get("Tf") {
        Some(t) => {
            let c: Vec<f32> = t
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            match c.as_slice() {
                &[r, g, b] if t.split_whitespace().count() == 3 => Some(Vec3::new(r, g, b)),
                _ => {
                    return Err(format!(
                        "`Tf {t}`: needs three numbers (an RGB transmission filter)"
                    ));
                }
            }
        }
        None => None,
    };
    for (key, severity) in UNREAD_KEYS {
        if let Some(val) = m.unknown_param.get(key) {
            let what = format!("`{key} {val}`: photonflow does not read this key");
            if severity == "error" {
                return Err(what);
            }
            warnings.push(format!("{what}; the surface is drawn without it"));
        }
    }
    for (key, tex) in [
        ("map_Ks", &m.specular_texture),
        ("map_d", &m.dissolve_texture),
    ] {
        if let Some(t) = tex {
            return Err(format!(
                "`{key} {t}`: of the texture maps only `map_Kd` is rendered; remove the line \
                 to draw the material's constant value"
            ));
        }
    }
    for (key, tex) in [
        ("bump", &m.normal_texture),
        ("map_Ns", &m.shininess_texture),
    ] {
        if let Some(t) = tex {
            warnings.push(format!(
                "`{key} {t}`: not rendered; the surface is drawn without it"
            ));
        }
    }
    Ok(Keys {
        kd,
        albedo_map,
        emission: e,
        opacity,
        tf,
        tf_text,
        warnings,
    })
}

/// The mapping of this module's table. `Err` is one line naming the key at fault.
pub(super) fn convert_mtl(
    m: &tobj::Material,
    emission: EmissionSource,
    tf_reading: TfReading,
) -> Result<Converted, String> {
    let Keys {
        kd,
        albedo_map,
        emission: e,
        opacity,
        tf,
        tf_text,
        mut warnings,
    } = read_keys(m, emission)?;
    let ni = m.optical_density;
    let ks_given = m.specular.map(Vec3::from);
    let ks = ks_given.unwrap_or(Vec3::ZERO);
    let illum = m.illumination_model;
    let glass_illum = matches!(illum, Some(4 | 6 | 7 | 9));
    // The course's convention: `Ni > 1` on a partly transparent material without an `illum`
    // that says otherwise is glass.
    let course_glass =
        matches!(illum, None | Some(0..=2)) && opacity < 1.0 && ni.is_some_and(|n| n > 1.0);
    if opacity < 1.0 && !(glass_illum || course_glass) {
        return Err(format!(
            "opacity {opacity} (`d`/`Tr`): partly transparent surfaces are rendered only as \
             glass (illum 4, 6, 7 or 9 with `Ni`)"
        ));
    }
    // Checked before the model is chosen: a negative or NaN `Ks` would otherwise fail
    // `Ks > 0` and draw a Lambertian surface without a word.
    if let Some(k) = ks_given.filter(|k| !(k.is_finite() && k.min_element() >= 0.0)) {
        return Err(format!(
            "`Ks {} {} {}`: the specular reflectance must be a number >= 0 in each channel",
            k.x, k.y, k.z
        ));
    }
    let glassy = glass_illum || course_glass;
    if glassy && tf.is_some_and(|t| !in_unit(t)) {
        return Err(format!(
            "`Tf {tf_text}`: the transmission filter of glass must lie in [0, 1] in each channel"
        ));
    }
    // What glass keeps at a crossing: `Tf` as the spec reads it, or `1 - Tf` (G3D's reading).
    let tf = match tf_reading {
        TfReading::Transmitted => tf,
        TfReading::Absorbed if glassy => tf.map(|t| Vec3::ONE - t),
        TfReading::Absorbed => tf,
    };
    if glassy && let Some(t) = tf.filter(|t| t.max_element() < 0.5) {
        let (now, other) = match tf_reading {
            TfReading::Transmitted => ("the fraction transmitted", "absorbed"),
            TfReading::Absorbed => ("the fraction absorbed (`tf = \"absorbed\"`)", "transmitted"),
        };
        warnings.push(format!(
            "`Tf {}` read as {now}: the glass keeps ({}, {}, {}) of the light at each \
             crossing and absorbs most of it (a ball, crossed twice, keeps under a quarter); \
             if the file means the other reading (G3D's, in which Morgan McGuire's archive is \
             written, takes `Tf` as the fraction absorbed), set `[[mesh]] tf = \"{other}\"`",
            tf_text.trim(),
            t.x,
            t.y,
            t.z
        ));
    }
    if !glassy && tf.is_some_and(|t| t != Vec3::ONE) {
        warnings.push(format!(
            "`Tf {}`: a transmission filter is read only for glass; illum {} is opaque",
            tf_text,
            illum.map_or("(none)".to_string(), |c| c.to_string())
        ));
    }
    let mat = match illum {
        _ if course_glass => glass(&mut warnings, "", m, tf)?,
        Some(2) if ks.max_element() > 0.0 => {
            let ns = m.shininess.unwrap_or(0.0);
            if !(ns.is_finite() && ns >= 0.0) {
                return Err(format!("`Ns {ns}`: the Phong exponent must be >= 0"));
            }
            let (g, scaled) = bsdf::Glossy::from_mtl(kd, ks, ns);
            if scaled {
                warnings.push(format!(
                    "`Kd` + `Ks` exceeds 1 in a channel ({} {} {}): both scaled there to sum \
                     to 1",
                    kd.x + ks.x,
                    kd.y + ks.y,
                    kd.z + ks.z
                ));
            }
            Material::Glossy {
                albedo: g.albedo,
                specular: g.specular,
                // A Phong exponent past 2e8 would be a mirror: the smallest roughness
                // the GGX models take.
                alpha: g.alpha.max(*ALPHA_RANGE.start()),
            }
        }
        None | Some(0..=2) => {
            if ks.max_element() > 0.0 {
                warnings.push(format!(
                    "`Ks {} {} {}` is not drawn: only illum 2 turns on the specular term \
                     (illum {})",
                    ks.x,
                    ks.y,
                    ks.z,
                    illum.map_or("absent".to_string(), |c| c.to_string())
                ));
            }
            Material::Lambertian { albedo: kd }
        }
        Some(3) => mirror(&mut warnings, "", m, kd),
        Some(5) => mirror(
            &mut warnings,
            "illum 5 (Fresnel reflection): drawn as a mirror of constant reflectance `Ks`",
            m,
            kd,
        ),
        Some(8) => mirror(
            &mut warnings,
            "illum 8 (reflection without ray tracing): drawn as a ray-traced mirror",
            m,
            kd,
        ),
        Some(4 | 7) => glass(&mut warnings, "", m, tf)?,
        Some(6) => glass(
            &mut warnings,
            "illum 6 (refraction, Fresnel off): drawn as glass with Fresnel reflection",
            m,
            tf,
        )?,
        Some(9) => glass(
            &mut warnings,
            "illum 9 (glass without ray-traced reflection): drawn as glass with Fresnel \
             reflection",
            m,
            tf,
        )?,
        Some(10) => {
            return Err(
                "illum 10 (a shadow matte: shadows cast onto invisible surfaces) \
                        is not rendered"
                    .into(),
            );
        }
        Some(11) => Material::Metal {
            reflectance: ks_given.unwrap_or(Vec3::ONE),
        },
        Some(c) => {
            return Err(format!(
                "unknown illum code {c} (the MTL spec's 0-10 and the course's 11 metal)"
            ));
        }
    };
    check(&mat, |k| {
        match k {
            "albedo" => "`Kd`",
            "specular" | "reflectance" => "`Ks`",
            "ior" => "`Ni`",
            "transmittance" => "`Tf`",
            "alpha" => "alpha (from `Ns`)",
            other => other,
        }
        .to_string()
    })?;
    Ok(Converted {
        material: mat,
        emission: e,
        albedo_map,
        warnings,
    })
}

/// A mirror of reflectance `Ks` (illum 3, 5, 8), with `why` (if not empty) and an unused
/// `Kd` warned about.
fn mirror(warnings: &mut Vec<String>, why: &str, m: &tobj::Material, kd: Vec3) -> Material {
    let ks = m.specular.map(Vec3::from).unwrap_or(Vec3::ZERO);
    if !why.is_empty() {
        warnings.push(why.to_string());
    }
    if kd.max_element() > 0.0 {
        warnings.push(format!(
            "`Kd {} {} {}` is not used: illum {} draws a mirror of reflectance `Ks`",
            kd.x,
            kd.y,
            kd.z,
            m.illumination_model.unwrap_or(0)
        ));
    }
    // The peers' mapping: `Ks`, or a perfect mirror where `Ks` is absent or black.
    let reflectance = if ks.max_element() > 0.0 {
        ks
    } else {
        Vec3::ONE
    };
    Material::Mirror { reflectance }
}

/// Glass of index `Ni` (1.5 where absent or in [0, 1]: warning; refused where negative or
/// not a number) and transmittance `tf`, with `why` (if not empty) and an unused `Ks` warned
/// about.
fn glass(
    warnings: &mut Vec<String>,
    why: &str,
    m: &tobj::Material,
    tf: Option<Vec3>,
) -> Result<Material, String> {
    let ni = m.optical_density;
    let ks_given = m.specular.map(Vec3::from);
    let ks = ks_given.unwrap_or(Vec3::ZERO);
    if !why.is_empty() {
        warnings.push(why.to_string());
    }
    let ior = match ni {
        Some(n) if n > 1.0 => n,
        // Exporters write `Ni 0` for "unset"; a negative or NaN index is no such convention.
        Some(n) if n.is_nan() || n < 0.0 => {
            return Err(format!(
                "`Ni {n}`: the index of refraction of glass must be a number above 1 (0, which \
                 exporters write for unset, is drawn as 1.5)"
            ));
        }
        _ => {
            warnings.push(format!(
                "glass without an index above 1 (`Ni {}`): drawn with index 1.5",
                ni.map_or("absent".to_string(), |n| n.to_string())
            ));
            1.5
        }
    };
    if ks_given.is_some_and(|k| k != Vec3::ONE) {
        warnings.push(format!(
            "`Ks {} {} {}` is not used: glass reflects by the Fresnel equations",
            ks.x, ks.y, ks.z
        ));
    }
    // `Tf` scales refracted light at every crossing: Mitsuba 3's
    // `specular_transmittance`, which the peers' mapping gives it too.
    Ok(Material::Dielectric {
        ior,
        transmittance: tf.unwrap_or(Vec3::ONE),
        absorption: Vec3::ZERO,
    })
}
