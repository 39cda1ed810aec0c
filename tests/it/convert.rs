//! `photonflow convert`: the scene file a Mitsuba XML scene means is the same scene, wherever
//! it is written (its file names made relative to it): the same image bit for bit.

use crate::kit::{TempDir, cli, scenes_dir};
use scene::Scene;

#[test]
fn a_converted_scene_is_the_same_scene() {
    let tmp = TempDir::new("convert");
    for name in ["worksheet", "shapes-and-lights", "materials"] {
        let xml = scenes_dir().join(format!("mitsuba/{name}.xml"));
        // Elsewhere, so every file name must be rewritten to be found.
        let out = tmp.path().join(format!("elsewhere/{name}.toml"));
        std::fs::create_dir_all(out.parent().unwrap()).unwrap();
        let (code, err) = cli([
            "convert".into(),
            xml.display().to_string(),
            "--out".into(),
            out.display().to_string(),
            "-D".into(),
            "width=24".into(),
            "-D".into(),
            "height=24".into(),
        ]);
        assert_eq!((code, err), (0, None), "{name}");
        let defines = [("width", "24"), ("height", "24")].map(|(k, v)| (k.into(), v.into()));
        let a = Scene::load_defined(&xml, &defines, |_| {}).unwrap();
        let b = Scene::load(&out).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(a.file.meshes.len(), b.file.meshes.len());
        let img = |s: &Scene| {
            crate::kit::sum_layers(
                &crate::kit::render_uncached(
                    s,
                    &render::Overrides {
                        method: Some(scene::Method::Path),
                        spp: Some(2),
                        ..Default::default()
                    },
                    None,
                ),
                |_| true,
            )
        };
        assert!(img(&a).data == img(&b).data, "{name}: the images differ");
    }
}

/// A run's resolved `scene.toml` names every file by its absolute path (meshes, image
/// textures, environment maps), so it renders the run again from wherever it is read: here
/// the gallery's XML scenes with a bitmap texture, an environment map and a PLY mesh.
#[test]
fn a_runs_scene_file_renders_it_again() {
    let tmp = TempDir::new("resolved");
    for name in ["shapes-and-lights", "materials"] {
        let xml = scenes_dir().join(format!("mitsuba/{name}.xml"));
        let render = |scene: &std::path::Path, out: &std::path::Path, defines: bool| {
            let mut args: Vec<String> = ["render", &scene.display().to_string()]
                .into_iter()
                .map(String::from)
                .collect();
            args.extend(["--method", "path", "--spp", "2", "--threads", "1"].map(String::from));
            args.extend(["--out".to_string(), out.display().to_string()]);
            if defines {
                args.extend(["-D", "width=16", "-D", "height=16"].map(String::from));
            }
            let (code, err) = cli(args);
            assert_eq!((code, err), (0, None), "{name}: {}", scene.display());
            std::fs::read(out.join("image.exr")).unwrap()
        };
        let first = tmp.path().join(format!("{name}-1"));
        let a = render(&xml, &first, true);
        let b = render(
            &first.join("scene.toml"),
            &tmp.path().join(format!("{name}-2")),
            false,
        );
        assert!(a == b, "{name}: the resolved scene renders another image");
    }
}
