//! A scene of PLY meshes renders the image of the same meshes given as one OBJ, bit for bit,
//! through the command line: a textured floor (texture coordinates), a box of flat faces
//! with their normals, an octahedron with smooth vertex normals, and a light, all under one
//! transform, each PLY file in another encoding. The run's `scene.toml` names the PLY files
//! by absolute path.

use crate::kit::{TempDir, bits, cli};
use tests::ply::{Format, Mesh, write};

/// Each part of the scene: its material and mesh, and the PLY encoding it is written in.
fn parts() -> Vec<(&'static str, Mesh, Format)> {
    let floor = Mesh {
        positions: vec![
            [-1.0, 0.0, -1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
        ],
        // OBJ's `vt`, counted up: the PLY file holds 1 - v.
        uvs: vec![[0.0, 0.75], [0.0, 0.0], [0.875, 0.0], [0.875, 0.75]],
        faces: vec![vec![0, 1, 2, 3]],
        ..Mesh::default()
    };
    // A box of six faces, each its own four vertices and normal, turned about y.
    let mut block = Mesh::default();
    let (c, s) = (0.8f32, 0.6f32);
    let turn = |[x, y, z]: [f32; 3]| [c * x + s * z, y, -s * x + c * z];
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = [0.0; 3];
            n[axis] = sign;
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = block.positions.len() as i32;
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            let corners = if sign > 0.0 {
                corners
            } else {
                [corners[0], corners[3], corners[2], corners[1]]
            };
            for (u, v) in corners {
                let mut p = [0.0f32; 3];
                p[axis] = 0.25 * sign;
                p[a] = 0.25 * u;
                p[b] = 0.25 * v;
                let [x, y, z] = turn(p);
                block.positions.push([x - 0.4, y + 0.25, z - 0.2]);
                block.normals.push(turn(n));
            }
            block.faces.push((base..base + 4).collect());
        }
    }
    // An octahedron with smooth normals (each vertex's direction from the centre).
    let dirs = [
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [0.0, -1.0, 0.0],
    ];
    let gem = Mesh {
        positions: dirs
            .map(|[x, y, z]| [0.4 + 0.3 * x, 0.35 + 0.3 * y, 0.3 + 0.3 * z])
            .to_vec(),
        normals: dirs.to_vec(),
        faces: [
            [0, 2, 1],
            [0, 3, 2],
            [0, 4, 3],
            [0, 1, 4],
            [5, 1, 2],
            [5, 2, 3],
            [5, 3, 4],
            [5, 4, 1],
        ]
        .map(|f| f.to_vec())
        .to_vec(),
        ..Mesh::default()
    };
    let lamp = Mesh {
        positions: vec![
            [-0.25, 1.5, -0.25],
            [0.25, 1.5, -0.25],
            [0.25, 1.5, 0.25],
            [-0.25, 1.5, 0.25],
        ],
        faces: vec![vec![0, 1, 2, 3]],
        ..Mesh::default()
    };
    vec![
        ("floor", floor, Format::Ascii),
        ("white", block, Format::Little),
        ("white", gem, Format::Big),
        ("lamp", lamp, Format::Little),
    ]
}

/// The parts as one OBJ file, an object per part (`v`, `vt`, `vn` as Rust prints f32s: they
/// read back to the same bits), texture coordinates as OBJ counts them.
fn obj_of(parts: &[(&str, Mesh, Format)]) -> String {
    let mut o = String::from("mtllib m.mtl\n");
    let (mut nv, mut nt, mut nn) = (0, 0, 0);
    for (i, (material, m, _)) in parts.iter().enumerate() {
        o += &format!("o part{i}\nusemtl {material}\n");
        for [x, y, z] in &m.positions {
            o += &format!("v {x:?} {y:?} {z:?}\n");
        }
        for [u, v] in &m.uvs {
            o += &format!("vt {u:?} {v:?}\n");
        }
        for [x, y, z] in &m.normals {
            o += &format!("vn {x:?} {y:?} {z:?}\n");
        }
        for f in &m.faces {
            o += "f";
            for &k in f {
                let k = k as usize;
                let (v, t, n) = (nv + k + 1, nt + k + 1, nn + k + 1);
                o += &match (m.uvs.is_empty(), m.normals.is_empty()) {
                    (true, true) => format!(" {v}"),
                    (false, true) => format!(" {v}/{t}"),
                    (true, false) => format!(" {v}//{n}"),
                    (false, false) => format!(" {v}/{t}/{n}"),
                };
            }
            o += "\n";
        }
        nv += m.positions.len();
        nt += m.uvs.len();
        nn += m.normals.len();
    }
    o
}

const MTL: &str = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl white\nKd 0.5 0.5 0.5\n\
    newmtl lamp\nKd 0 0 0\nKe 1 1 1\n";

/// The scene file over `meshes` (its `[[mesh]]` tables), the materials the scene file gives
/// (they win over the MTL's of the same name).
fn scene(meshes: &str) -> String {
    format!(
        "name = \"ply\"\nseed = 5\n[camera]\neye = [0, 1.2, 3]\nlook_at = [0, 0.3, 0]\n\
         vfov = 45\nwidth = 24\nheight = 24\n{meshes}\
         [material.floor]\ntype = \"lambertian\"\nalbedo = [0.9, 0.9, 0.9]\ntexture = \"t.png\"\n\
         [material.white]\ntype = \"lambertian\"\nalbedo = [0.7, 0.6, 0.5]\n\
         [material.lamp]\ntype = \"lambertian\"\nalbedo = [0, 0, 0]\nemission = [12, 12, 12]\n"
    )
}

/// The same transform on every mesh.
const TRANSFORM: &str = "scale = 1.25\nrotate = [0, 20, 0]\ntranslate = [0.1, -0.2, 0]\n";

/// A scene of four PLY meshes (ASCII, little- and big-endian) renders the image of the same
/// meshes as one OBJ, bit for bit, by the path tracer and by SPPM, through `photonflow
/// render`: positions, flat and smooth normals, texture coordinates (a checker floor),
/// polygons, transform and materials all arrive the same way.
#[test]
fn a_ply_scene_renders_as_the_same_obj_scene() {
    let dir = TempDir::new("ply-render");
    let d = dir.path();
    let parts = parts();
    // A 4 x 4 checker: a texture read at the wrong coordinates draws another image.
    let checker = image::RgbImage::from_fn(4, 4, |x, y| {
        image::Rgb(if (x + y) % 2 == 0 {
            [230, 200, 40]
        } else {
            [30, 60, 200]
        })
    });
    checker.save(d.join("t.png")).unwrap();
    std::fs::write(d.join("m.mtl"), MTL).unwrap();
    std::fs::write(d.join("all.obj"), obj_of(&parts)).unwrap();
    std::fs::write(
        d.join("obj.toml"),
        scene(&format!("[[mesh]]\nobj = \"all.obj\"\n{TRANSFORM}")),
    )
    .unwrap();
    let mut plys = String::new();
    for (i, (material, mesh, format)) in parts.iter().enumerate() {
        let mut m = mesh.clone();
        for uv in &mut m.uvs {
            uv[1] = 1.0 - uv[1];
        }
        std::fs::write(d.join(format!("part{i}.ply")), write(*format, &m)).unwrap();
        plys += &format!("[[mesh]]\nply = \"part{i}.ply\"\nmaterial = \"{material}\"\n{TRANSFORM}");
    }
    std::fs::write(d.join("ply.toml"), scene(&plys)).unwrap();
    for args in [
        "--method path --spp 4",
        "--method sppm --passes 2 --photons 20000",
    ] {
        let image = |name: &str| {
            let out = d.join(format!("out-{name}"));
            let argv = format!(
                "render {}/{name}.toml {args} --threads 2 --cache {}/cache-{name} --out {}",
                d.display(),
                d.display(),
                out.display()
            );
            let (code, msg) = cli(argv.split(' ').map(String::from));
            assert_eq!(code, 0, "{name} {args}: {msg:?}");
            film::read_exr(out.join("image.exr")).unwrap_or_else(|e| panic!("{e}"))
        };
        let (obj, ply) = (image("obj"), image("ply"));
        assert!(
            obj.data.iter().any(|p| p.iter().any(|&c| c > 0.0)),
            "{args}: a black image"
        );
        assert!(
            bits(&obj) == bits(&ply),
            "{args}: the PLY scene draws another image"
        );
        // The run's `scene.toml` names the PLY files by absolute path, as it does OBJ files.
        let resolved = std::fs::read_to_string(d.join("out-ply/scene.toml")).unwrap();
        let part = std::path::absolute(d.join("part0.ply")).unwrap();
        assert!(
            resolved.contains(&format!("ply = {:?}", part.display().to_string())),
            "{resolved}"
        );
        let _ = std::fs::remove_dir_all(d.join("out-obj"));
        let _ = std::fs::remove_dir_all(d.join("out-ply"));
    }
}
