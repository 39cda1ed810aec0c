//! OBJ, MTL and PLY files at fault: malformed colours, faces of 200k and 400k vertices, a
//! mesh that is a FIFO or scaled past the scene's range, messages naming the line, PLY files
//! cut short, with absurd counts, bad headers and out-of-range indices, valid scenes.

use super::*;
use tests::ply::{Format, Mesh, write};

/// A polygon face of `n` vertices on a unit circle around the floor's centre (x, z), written
/// with 7 decimals; `notch` pulls one vertex to the centre (non-convex).
fn polygon_obj(n: usize, notch: bool) -> String {
    let mut o = String::from(OBJ);
    o += "o disc\nusemtl white\n";
    for i in 0..n {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        let (x, z) = if notch && i == n / 2 {
            (0.0, 0.0)
        } else {
            (t.cos(), -t.sin())
        };
        o += &format!("v {x:.7} 0.001 {z:.7}\n");
    }
    o += "f";
    for i in 0..n {
        o += &format!(" {}", i + 9);
    }
    o + "\n"
}

/// A polygon face of `n` vertices (a multiple of 4) along the edges of a square around the
/// floor's centre, `n / 4` per edge from its corner: between four corners, runs of collinear
/// vertices (the sides are x or z = +-0.5 exactly).
fn square_edges_obj(n: usize) -> String {
    let q = n / 4;
    let mut o = String::from(OBJ);
    o += "o square\nusemtl white\n";
    let t = |i: usize| -0.5 + i as f64 / q as f64;
    for side in 0..4 {
        for i in 0..q {
            let (x, z) = match side {
                0 => (t(i), 0.5),
                1 => (0.5, -t(i)),
                2 => (-t(i), -0.5),
                _ => (-0.5, t(i)),
            };
            o += &format!("v {x:.7} 0.001 {z:.7}\n");
        }
    }
    o += "f";
    for i in 0..4 * q {
        o += &format!(" {}", i + 9);
    }
    o + "\n"
}

/// The case's `s.toml` loads into `n` triangles: the work its loader did.
fn triangles(n: usize) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        let s = scene::Scene::load(d.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.geometry.mesh().len(), n, "triangles of s.toml");
    }))
}

/// A case whose MTL gives the floor's material `white` `lines` instead of `Kd 0.5 0.5 0.5`,
/// run through `info`: refused with `words`, or, with none, loaded and checked by `check`.
fn white(
    name: &'static str,
    lines: &str,
    words: &'static [&'static str],
    check: Option<Check>,
) -> Case {
    let files = files(scene(""), OBJ, &MTL.replace("Kd 0.5 0.5 0.5", lines));
    info_case(name, files, words, check)
}

/// A case of `files` run through `info`: refused with `words`, or, with none, loaded and
/// checked by `check`.
fn info_case(
    name: &'static str,
    files: Vec<(&'static str, Input)>,
    words: &'static [&'static str],
    check: Option<Check>,
) -> Case {
    Case {
        name,
        files,
        setup: vec![],
        prepare: None,
        args: "info {d}/s.toml",
        code: if words.is_empty() { 0 } else { 1 },
        words,
        check,
    }
}

fn cases() -> Vec<Case> {
    let black = MTL.replace("Kd 0.5 0.5 0.5", "Kd 0 0 0");
    let mirror = MTL.replace("Kd 0.5 0.5 0.5", "illum 3\nKs 0.9 0.9 0.9");
    vec![
        // Coloured glass: MTL `Tf`.
        Case {
            name: "MTL Tf out of range on glass",
            files: files(
                scene(""),
                OBJ,
                &MTL.replace(
                    "Kd 0.5 0.5 0.5",
                    "Kd 0.5 0.5 0.5\nnewmtl glass\nillum 7\nNi 1.5\nTf 1.5 0.5 0.5",
                ),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["m.mtl", "material `glass`", "`Tf 1.5 0.5 0.5`", "[0, 1]"],
            check: None,
        },
        Case {
            name: "MTL Tf on glass is coloured glass",
            files: files(
                scene(""),
                OBJ,
                &MTL.replace(
                    "Kd 0.5 0.5 0.5",
                    "Kd 0.5 0.5 0.5\nnewmtl glass\nillum 7\nNi 1.5\nTf 0.9 0.5 0.2",
                ),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        // Panics.
        Case {
            name: "MTL colour of one number is grey",
            files: with(
                good(),
                "m.mtl",
                text(MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        Case {
            name: "MTL colour of two numbers",
            files: with(
                good(),
                "m.mtl",
                text(MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "m.mtl",
                "line 2",
                "`Kd` needs one number (grey) or three",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "a mesh scaled to 1e19",
            files: with(
                files(scene("[[mesh]]\nobj = \"b.obj\"\nscale = 1e19\n"), OBJ, MTL),
                "b.obj",
                text("mtllib m.mtl\no big\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nf 1 2 3\n"),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "b.obj",
                "beyond the 1e15 scene units",
                "mesh 1 of",
                "s.toml",
            ],
            check: None,
        },
        // Hangs.
        Case {
            name: "a convex face of 200k vertices",
            files: with(good(), "a.obj", text(polygon_obj(200_000, false))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        Case {
            name: "a non-convex face of 200k vertices",
            files: with(good(), "a.obj", text(polygon_obj(200_000, true))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "object `disc`, face 1",
                "non-convex face of 200000",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "a mesh that is a FIFO",
            files: with(good(), "a.obj", Input::Fifo),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["a.obj", "not a regular file", "s.toml"],
            check: None,
        },
        Case {
            name: "a face of 400k vertices along a square's edges",
            files: with(good(), "a.obj", text(square_edges_obj(400_000))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            // The floor's and the light's 4, and the square's 2: its vertices inside straight
            // edges are no corners (400k - 2 triangles, most of no area, took minutes).
            check: triangles(6),
        },
        // Messages.
        Case {
            name: "an empty OBJ",
            files: with(good(), "a.obj", text("")),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["a.obj", "the OBJ file is empty", "s.toml"],
            check: None,
        },
        Case {
            name: "an OBJ without mtllib",
            files: with(good(), "a.obj", text(OBJ.replace("mtllib m.mtl\n", ""))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "`usemtl white` (line 2)",
                "no `mtllib` line",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "usemtl of an unknown material",
            files: with(
                good(),
                "a.obj",
                text(OBJ.replace("usemtl light", "usemtl lamp")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "`usemtl lamp` (line 11): unknown material",
                "m.mtl defines `white`, `light`",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "faces before any usemtl",
            files: with(good(), "a.obj", text(OBJ.replace("usemtl white\n", ""))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "object `floor` has faces before any `usemtl` line",
                "s.toml",
            ],
            check: None,
        },
        // Valid scenes refused.
        Case {
            name: "all surfaces black, final gathering",
            files: files(scene(""), OBJ, &black),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --photons 2000 --cache {d}/cache --out {d}/out",
            code: 0,
            words: &[],
            check: present("out/plan.txt", "no surface is diffuse"),
        },
        Case {
            name: "only mirrors, final gathering",
            files: files(scene(""), OBJ, &mirror),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --photons 2000 --cache {d}/cache --out {d}/out",
            code: 0,
            words: &[],
            check: present(
                "out/plan.txt",
                "only emitters, seen directly or through specular",
            ),
        },
        Case {
            name: "only mirrors, sppm",
            files: files(scene(""), OBJ, &mirror),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --out {d}/out",
            code: 0,
            words: &[],
            check: present("out/plan.txt", "no surface is diffuse"),
        },
        // Values checked and named, never dropped.
        white(
            "MTL Ni NaN on glass",
            "illum 7\nNi nan",
            &[
                "m.mtl",
                "material `white`",
                "`Ni NaN`",
                "index of refraction",
            ],
            None,
        ),
        white(
            "MTL Ni negative on glass",
            "illum 4\nNi -1.5",
            &[
                "m.mtl",
                "material `white`",
                "`Ni -1.5`",
                "index of refraction",
            ],
            None,
        ),
        white(
            "MTL Ni 0 on glass, the exporters' unset",
            "illum 7\nNi 0",
            &[],
            warns(&["m.mtl: material `white`", "`Ni 0`", "index 1.5"]),
        ),
        white(
            "MTL Ks negative with illum 2",
            "Kd 0.5 0.5 0.5\nKs -0.5 -0.5 -0.5\nNs 10\nillum 2",
            &["m.mtl", "material `white`", "`Ks -0.5 -0.5 -0.5`", ">= 0"],
            None,
        ),
        white(
            "MTL Ks NaN with illum 2",
            "Kd 0.5 0.5 0.5\nKs nan 0.5 0.5\nNs 10\nillum 2",
            &["m.mtl", "material `white`", "`Ks NaN 0.5 0.5`", ">= 0"],
            None,
        ),
        white(
            "MTL illum -1",
            "Kd 0.5 0.5 0.5\nillum -1",
            &["m.mtl", "line 3", "`illum -1`", "s.toml"],
            None,
        ),
        white(
            "MTL colour in words",
            "Kd bright white",
            &[
                "m.mtl",
                "line 2",
                "`Kd bright white`",
                "not a number",
                "s.toml",
            ],
            None,
        ),
        white(
            "MTL Ns in words",
            "Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs high\nillum 2",
            &["m.mtl", "line 4", "`Ns high`", "not a number", "s.toml"],
            None,
        ),
        white(
            "MTL Kd above 1",
            "Kd 2 2 2",
            &["m.mtl: material `white`: `Kd` = [2, 2, 2] must lie in [0, 1]"],
            None,
        ),
        white(
            "MTL d and a disagreeing Tr",
            "Kd 0.5 0.5 0.5\nd 1.0\nTr 0.5",
            &[],
            warns(&[
                "m.mtl: material `white`",
                "`d 1`",
                "`Tr 0.5`",
                "`d` is used",
            ]),
        ),
        Case {
            name: "MTL material defined twice",
            files: files(
                scene(""),
                OBJ,
                &format!("{MTL}newmtl white\nKd 0.2 0.2 0.2\n"),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: Some(Box::new(|d: &Path| {
                warns(&["m.mtl: material `white`", "defined 2 times", "the last"]).unwrap()(d);
                let s = scene::Scene::load(d.join("s.toml")).unwrap();
                let id = s.material_of("white").unwrap() as usize;
                let want = scene::Material::Lambertian {
                    albedo: glam::Vec3::splat(0.2),
                };
                assert_eq!(s.materials[id], want, "not the last definition");
            })),
        },
        // A texture brighter than 1 under a diffuse albedo.
        Case {
            name: "MTL map_Kd above 1 under a Lambertian Kd",
            files: with(
                files(
                    scene(""),
                    OBJ,
                    &MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.7 0.7 0.7\nmap_Kd t.exr"),
                ),
                "t.exr",
                Input::Exr(Image::from_fn(2, 2, |_, _| [4.0; 3])),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: texture_scaled(&["m.mtl: material `white`", "brightest texel", "exceeds 1"]),
        },
    ]
}

/// The good scene's second mesh: `p.ply` under the scene-file material `grey`.
const PLY_MESH: &str = "[[mesh]]\nply = \"p.ply\"\nmaterial = \"grey\"\n\
    [material.grey]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n";

/// A quad just above the floor, as `p.ply` holds it.
fn ply_quad() -> Mesh {
    Mesh {
        positions: vec![
            [-0.5, 0.01, -0.5],
            [-0.5, 0.01, 0.5],
            [0.5, 0.01, 0.5],
            [0.5, 0.01, -0.5],
        ],
        faces: vec![vec![0, 1, 2, 3]],
        ..Mesh::default()
    }
}

/// The quad in little-endian binary, with `edit` applied to its header text.
fn ply_header_edit(edit: impl Fn(String) -> String) -> Vec<u8> {
    let b = write(Format::Little, &ply_quad());
    let end = b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let mut out = edit(String::from_utf8(b[..end].to_vec()).unwrap()).into_bytes();
    out.extend(&b[end..]);
    out
}

/// A case over the good scene and `p.ply` holding `ply`, through `info` (scene text
/// `toml`): refused with `words` or, with none, loaded and checked by `check`.
fn ply_case(
    name: &'static str,
    toml: &str,
    ply: Input,
    words: &'static [&'static str],
    check: Option<Check>,
) -> Case {
    info_case(
        name,
        with(files(scene(toml), OBJ, MTL), "p.ply", ply),
        words,
        check,
    )
}

fn ply_cases() -> Vec<Case> {
    let bytes = |m: &Mesh| Input::Bytes(write(Format::Little, m));
    let good = write(Format::Little, &ply_quad());
    let mut nan = ply_quad();
    nan.positions[2][1] = f32::NAN;
    let mut index = ply_quad();
    index.faces[0][3] = 7;
    vec![
        // The OBJ's four triangles and the quad's two.
        ply_case(
            "PLY binary",
            PLY_MESH,
            bytes(&ply_quad()),
            &[],
            triangles(6),
        ),
        ply_case(
            "PLY ascii",
            PLY_MESH,
            Input::Bytes(write(Format::Ascii, &ply_quad())),
            &[],
            triangles(6),
        ),
        ply_case(
            "PLY binary body cut short",
            PLY_MESH,
            Input::Bytes(good[..good.len() - 5].to_vec()),
            &["p.ply", "the file is cut short", "(mesh 1 of", "s.toml"],
            None,
        ),
        ply_case(
            "PLY header without end_header",
            PLY_MESH,
            text(
                String::from_utf8_lossy(&good[..good.len() - 4 * 12 - 1 - 16])
                    .replace("end_header\n", ""),
            ),
            &["p.ply", "no `end_header` line", "s.toml"],
            None,
        ),
        ply_case(
            "PLY face index out of range",
            PLY_MESH,
            bytes(&index),
            &[
                "p.ply",
                "face 0: vertex index 7 out of range (the file has 4 vertices)",
            ],
            None,
        ),
        ply_case(
            "PLY NaN vertex",
            PLY_MESH,
            bytes(&nan),
            &["p.ply", "vertex 2 is not finite", "s.toml"],
            None,
        ),
        ply_case(
            "PLY absurd element count",
            PLY_MESH,
            Input::Bytes(ply_header_edit(|h| {
                h.replace("vertex 4", "vertex 4000000000000")
            })),
            &[
                "p.ply",
                "element `vertex` claims 4000000000000 entries",
                "bytes follow",
            ],
            None,
        ),
        ply_case(
            "PLY unknown format",
            PLY_MESH,
            Input::Bytes(ply_header_edit(|h| {
                h.replace("binary_little_endian", "binary_pdp_endian")
            })),
            &["p.ply", "unknown format `binary_pdp_endian`"],
            None,
        ),
        ply_case(
            "PLY list count of type float",
            PLY_MESH,
            Input::Bytes(ply_header_edit(|h| h.replace("list uchar", "list float"))),
            &[
                "p.ply",
                "list `vertex_indices`",
                "must be an integer type, not `float`",
            ],
            None,
        ),
        ply_case(
            "PLY vertex without z",
            PLY_MESH,
            Input::Bytes(ply_header_edit(|h| h.replace("property float z\n", ""))),
            &[
                "p.ply",
                "element `vertex` has no property `z` (it has: x, y)",
            ],
            None,
        ),
        ply_case(
            "PLY a FIFO",
            PLY_MESH,
            Input::Fifo,
            &["p.ply", "not a regular file", "s.toml"],
            None,
        ),
        ply_case(
            "PLY mesh without a material",
            &PLY_MESH.replace("material = \"grey\"\n", ""),
            bytes(&ply_quad()),
            &[
                "s.toml",
                "mesh 1 (p.ply): a PLY mesh needs `material",
                "known: ",
                "grey",
            ],
            None,
        ),
        ply_case(
            "PLY mesh with an unknown material",
            &PLY_MESH.replace("material = \"grey\"", "material = \"gray\""),
            bytes(&ply_quad()),
            &["s.toml", "mesh 1 (p.ply): unknown material `gray`", "grey"],
            None,
        ),
    ]
}

#[test]
fn bad_input_table() {
    run_table("obj-mtl", cases().into_iter().chain(ply_cases()).collect());
}
