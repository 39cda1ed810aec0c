//! Textures through every method: a texture is read wherever the albedo is (the eye pass,
//! photon scattering, the estimates at receivers, the splats), so a constant texture draws
//! the image of its constant colour to the bit, in every method. Against Mitsuba, a checker
//! floor: `references::textured::a_textured_receiver_matches_mitsuba`.

use crate::kit::{TempDir, bits, render_uncached, scene_at, sum_layers};
use render::Overrides;
use scene::{MaterialDesc, Method, srgb_to_linear};

/// The textured-floor scene at 32 x 32 with its floor one colour: the texture `image` (a
/// file in `dir`) times 1, or the albedo `albedo` without a texture.
fn floor_of(dir: &TempDir, texture: Option<&str>, albedo: [f32; 3]) -> scene::Scene {
    scene_at("cornell-textured/textured-floor.toml", 32, 3, |f| {
        f.materials.insert(
            "floor".into(),
            MaterialDesc::Lambertian {
                albedo,
                emission: [0.0; 3],
                texture: texture
                    .map(|t| scene::TextureDesc::File(dir.path().join(t).display().to_string())),
            },
        );
    })
}

/// A floor drawn with a 1 x 1 texture of sRGB (200, 120, 40) and one drawn with the decoded
/// colour as its albedo are the same image in every method, bit for bit. A method that read
/// the material's albedo (1, the texture's scale) somewhere instead of the texture would not
/// be: photons bouncing off the floor, the estimate at the floor, the splat onto it or the
/// gather hits there each carry the albedo.
#[test]
fn a_constant_texture_draws_its_colour_to_the_bit_in_every_method() {
    let dir = TempDir::new("textures-constant");
    let rgb = [200u8, 120, 40];
    let img = image::RgbImage::from_fn(1, 1, |_, _| image::Rgb(rgb));
    img.save(dir.path().join("c.png")).unwrap();
    let colour = rgb.map(|c| srgb_to_linear(c as f32 / 255.0));
    let textured = floor_of(&dir, Some("c.png"), [1.0; 3]);
    let plain = floor_of(&dir, None, colour);
    // Not a vacuous check: the texture's scale alone draws another image.
    let white = floor_of(&dir, None, [1.0; 3]);
    for (method, count) in [
        (Method::Path, 4),
        (Method::GlobalDirect, 1),
        (Method::FinalGather, 1),
        (Method::CausticSplat, 2),
        (Method::PathSplat, 2),
        (Method::Sppm, 2),
    ] {
        let o = Overrides {
            method: Some(method),
            photons: Some(20_000),
            splat_photons: Some(20_000),
            spp: matches!(method, Method::Path | Method::PathSplat).then_some(count),
            passes: matches!(method, Method::Sppm | Method::CausticSplat).then_some(count),
            ..Overrides::default()
        };
        let image = |s: &scene::Scene| bits(&sum_layers(&render_uncached(s, &o, None), |_| true));
        let t = image(&textured);
        assert!(
            t == image(&plain),
            "{method:?}: the texture's colour is not drawn everywhere"
        );
        assert!(
            t != image(&white),
            "{method:?}: the floor's colour does not show"
        );
    }
}
