//! `crates/scene/src/load/objtext/` against tobj 4, the reader it replaced: every model (name, material,
//! vertices, indices, arities), the materials, the `usemtl` list and the line count, or the
//! same error, on hand-made files that use each rule and on thousands of mutations of them,
//! each read whole and in chunks of 1, 3 and 17 bytes (so a chunk boundary falls everywhere).

use crate::load::objtext::{self, ObjModel};
use std::io::BufReader;
use std::path::Path;

const MTL: &str = "newmtl red\nKd 1 0 0\nnewmtl white\nKd 1 1 1\nnewmtl red\nKd 0.5 0 0\n";
const MTL2: &str = "newmtl blue\nKd 0 0 1\n";

/// Files that exercise each rule the reader keeps.
const CASES: &[&str] = &[
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "mtllib m.mtl\no a\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nusemtl white\nf 1 2 4\ng b\nf -1 -2 -3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1 2/2 4/3\nf 1//1 2//1 3//1 4\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 2 0\nf 1 2 4 3\nf 1 2 5 4 3\nl 1 2\np 1\nf 1\nf 1 2\nf\n",
    "# comment\n\n   \n#x\nv 1 2 3 2\nv 0 0 0 0.5\nv 1 1 1\nf 1 2 3\n",
    "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\nv 9 9 9\nf 1 2 4\n",
    "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nusemtl  red \r\nf 1 2 3\r\no\r\nf 3 2 1\r\ng  spaced name \r\nf 1 3 2",
    "mtllib m.mtl\nmtllib n.mtl\nusemtl blue\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl red\nusemtl red\nf 1 3 2\n",
    "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n",
    "v 0 0 0\nv 1 0 0\nf 1 2 4\no next\nv 0 1 0\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/1 3/1\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\nf 1/1/1/ 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\nf 1 2 99999999999999999999\n",
    "v 0 0 0\nv 1 x 0\n",
    "v 0 0\n",
    "v 0 0 0 0\n",
    "v 0 0 0 1 1\n",
    "v 0 0 0 1 1 1 1\n",
    "vt 0\nvn 0 0\n",
    "v 0 0 0\nusemtl\nf 1 1 1\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\u{ff}\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\ng gr\u{fc}n\u{a0}x\nf 1\u{2003}2\u{a0}3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\n\u{b}f\u{c}1 2 3\n  usemtl red\n  g  x\nf 3 2 1\n",
    "mtllib m.mtl\nusemtl nothere\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl white\nf 1 2 3\nusemtl nothere\nf 3 2 1\n",
    "v 0 0 0 1 1 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v 0 0 0 1 x 1\nv 1 0 0 1 1 1\nv 0 1 0 1 1 1\nf 1 2 3\n",
    "v 1e40 -0 nan\nv inf 1 -inf\nv 0.1e-45 2 3\nf 1 2 3\n",
    "",
    "\n\n",
    "f 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2 3\nf 3/1 2 1/1\n",
    "v -0.999000 +0.212345\t-1.000000\nv 16777216 16777217 .5\nv 5. 0.1234567890123 -0.0\nf 1 2 3\nf\t3  2 1 \n",
    "v 1 2 3\nv 4 5 6\nv 7 8 9\nf 1 2 -1\nf 1 2 3\nvn 0 0 1\nf 1 2 3\nf 1//1 2//1 3//1\nf 3 2 1\n",
    "v 1 2 3\nv 4 5 6\nv 7 8 9\nf 1 2 000000003\nf 1 2 0003\nf 1 2 1234567890\nf 1 2 .3\n",
];

/// The MTL files the cases name.
fn mtl(p: &Path) -> tobj::MTLLoadResult {
    let text = match p.to_str() {
        Some("m.mtl") => MTL,
        Some("n.mtl") => MTL2,
        _ => return Err(tobj::LoadError::OpenFileFailed),
    };
    tobj::load_mtl_buf(&mut BufReader::new(text.as_bytes()))
}

/// What tobj made of `bytes`, in the reader's terms.
type Outcome = Result<(Vec<ObjModel>, Result<Vec<String>, tobj::LoadError>), tobj::LoadError>;

fn by_tobj(bytes: &[u8]) -> Outcome {
    let (models, mats) = tobj::load_obj_buf(
        &mut BufReader::new(bytes),
        &tobj::LoadOptions {
            triangulate: false,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        },
        mtl,
    )?;
    let models = models
        .into_iter()
        .map(|m| ObjModel {
            name: m.name,
            material_id: m.mesh.material_id,
            positions: m.mesh.positions,
            normals: m.mesh.normals,
            texcoords: m.mesh.texcoords,
            indices: m.mesh.indices,
            face_arities: m.mesh.face_arities,
        })
        .collect();
    Ok((
        models,
        mats.map(|v| v.into_iter().map(|m| m.name).collect()),
    ))
}

/// The `usemtl` list and the count of lines that are neither blank nor comments.
type Directives = (Vec<(usize, String)>, usize);

fn by_objtext(bytes: &[u8], chunk: usize) -> (Outcome, Option<Directives>) {
    by_objtext_with(bytes, chunk, objtext::PARALLEL)
}

/// [`by_objtext`] with the parallel numbering taking models from `par.min_corners` corners,
/// in tasks of `par.block`.
fn by_objtext_with(
    bytes: &[u8],
    chunk: usize,
    par: objtext::Parallel,
) -> (Outcome, Option<Directives>) {
    let mut read = objtext::read(bytes, chunk);
    read.1 = par;
    match objtext::form(read, mtl) {
        Ok(t) => (
            Ok((
                t.models,
                t.materials.map(|v| v.into_iter().map(|m| m.name).collect()),
            )),
            Some((t.usemtl, t.lines)),
        ),
        Err(e) => (Err(e), None),
    }
}

/// The `usemtl` list and line count as `obj.rs` computed them before (its whole-file scan).
fn directives(bytes: &[u8]) -> Directives {
    let mut usemtl: Vec<(usize, String)> = Vec::new();
    let mut lines = 0;
    for (i, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        lines += 1;
        if line.split_whitespace().next() == Some("usemtl") {
            let name = line.split_once(' ').unwrap_or_default().1.trim();
            if !name.is_empty() && !usemtl.iter().any(|(_, n)| n == name) {
                usemtl.push((i + 1, name.to_string()));
            }
        }
    }
    (usemtl, lines)
}

/// Bit-exact comparison (NaN coordinates included).
fn same(a: &Outcome, b: &Outcome) -> bool {
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    match (a, b) {
        (Err(x), Err(y)) => x == y,
        (Ok((ma, ta)), Ok((mb, tb))) => {
            ta == tb
                && ma.len() == mb.len()
                && ma.iter().zip(mb).all(|(p, q)| {
                    p.name == q.name
                        && p.material_id == q.material_id
                        && bits(&p.positions) == bits(&q.positions)
                        && bits(&p.normals) == bits(&q.normals)
                        && bits(&p.texcoords) == bits(&q.texcoords)
                        && p.indices == q.indices
                        && p.face_arities == q.face_arities
                })
        }
        _ => false,
    }
}

fn check(bytes: &[u8]) {
    let want = by_tobj(bytes);
    // Every model numbered in parallel (where it can be), in tasks of 1, 2 and 5 corners.
    let par = |block| objtext::Parallel {
        min_corners: 0,
        block,
    };
    for (chunk, par) in [
        (1, objtext::PARALLEL),
        (3, par(2)),
        (17, par(1)),
        (objtext::CHUNK, objtext::PARALLEL),
        (objtext::CHUNK, par(5)),
    ] {
        let (got, dirs) = by_objtext_with(bytes, chunk, par);
        assert!(
            same(&got, &want),
            "chunk {chunk}, {par:?}, file {:?}:\n ours {got:?}\n tobj {want:?}",
            String::from_utf8_lossy(bytes)
        );
        if let Some(d) = dirs {
            assert_eq!(d, directives(bytes), "{:?}", String::from_utf8_lossy(bytes));
        }
    }
}

#[test]
fn every_case_reads_as_tobj_reads_it() {
    for case in CASES {
        check(case.as_bytes());
    }
}

/// The quick decimal reading gives std's value, bit for bit, or leaves the word to std.
#[test]
fn quick_decimals_are_std_decimals() {
    let mut words: Vec<String> = [
        "0",
        "-0",
        "+0",
        "1",
        "-1.",
        ".5",
        "-.5",
        "5.",
        ".",
        "-",
        "+",
        "",
        "1.2.3",
        "1e3",
        "inf",
        "nan",
        "0x1",
        "16777216",
        "16777217",
        "0.0000000001",
        "0.00000000001",
        "123456789012",
        "1234567890123",
        "9999999.9",
        "0.1",
        "0.3",
        "3.4028235",
        "--1",
        "1-",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..200_000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let digits = (state % 13) as usize;
        let dot = (state >> 8) as usize % (digits + 2);
        let mut w = String::new();
        if state >> 20 & 1 == 1 {
            w.push('-');
        }
        for i in 0..digits {
            if i == dot {
                w.push('.');
            }
            w.push(char::from(b'0' + ((state >> (24 + 3 * i)) % 10) as u8));
        }
        words.push(w);
    }
    let mut quick = 0;
    for w in &words {
        if let Some(x) = objtext::decimal(w.as_bytes()) {
            quick += 1;
            let std: f32 = w.parse().unwrap_or_else(|_| panic!("{w:?} is no f32"));
            assert_eq!(x.to_bits(), std.to_bits(), "{w:?}");
        }
    }
    assert!(quick > words.len() / 3, "{quick} of {}", words.len());
}

/// Mutations of the cases (bytes replaced, inserted, deleted, lines swapped, a token from
/// another case spliced in), from a fixed seed.
#[test]
fn mutated_files_read_as_tobj_reads_them() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n.max(1) as u64) as usize
    };
    const ALPHABET: &[u8] = b" \t\r\n/-+0123456789.vfnt#golusemtl\x0b\xc3\xa9";
    for _ in 0..3000 {
        let mut b = CASES[next(CASES.len())].as_bytes().to_vec();
        for _ in 0..1 + next(4) {
            let at = next(b.len() + 1);
            match next(4) {
                0 if at < b.len() => b[at] = ALPHABET[next(ALPHABET.len())],
                1 => b.insert(at, ALPHABET[next(ALPHABET.len())]),
                2 if at < b.len() => {
                    b.remove(at);
                }
                _ => {
                    let other = CASES[next(CASES.len())].as_bytes();
                    let from = next(other.len() + 1);
                    let to = (from + next(12)).min(other.len());
                    b.splice(at..at, other[from..to].iter().copied());
                }
            }
        }
        check(&b);
    }
}

/// A large file in many chunks: one model over every chunk, faces referring back across
/// chunk boundaries with relative indices.
#[test]
fn a_file_over_many_chunks_reads_as_one() {
    let mut s = String::from("mtllib m.mtl\nusemtl red\n");
    for i in 0..3000 {
        s += &format!("v {i} {} 0.5\nvt 0.{i} 0.5\n", i % 7);
        if i >= 2 {
            s += &format!("f -1/-1 -2/-2 -3/-3\nf {} {} {}\n", i + 1, i, i - 1);
        }
        if i % 1000 == 999 {
            s += &format!("g part{i}\nusemtl white\n");
        }
    }
    let want = by_tobj(s.as_bytes());
    let (got, _) = by_objtext(s.as_bytes(), 1000);
    assert!(same(&got, &want));
    let Ok((models, _)) = got else {
        panic!("{got:?}")
    };
    assert_eq!(models.len(), 4);
    assert_eq!(
        models.iter().map(|m| m.indices.len()).sum::<usize>(),
        2 * 2998 * 3
    );
}

/// Large plain models (no texture or normal index) numbered in parallel: triangles, quads,
/// points and lines, faces across chunk boundaries, relative indices, an index out of range;
/// as tobj reads them, on 1, 2 and 3 threads.
#[test]
fn plain_models_numbered_in_parallel_read_as_tobj_reads_them() {
    let mut s = String::from("mtllib m.mtl\nusemtl red\n");
    for i in 0..4000 {
        s += &format!("v {i} {} 0.5\n", i % 7);
        if i >= 3 {
            // Faces from the back (first use out of order) and points and lines between.
            s += &format!("f {} {} {}\nf -1 -3 -2\n", i + 1, i - 2, i);
            match i % 500 {
                7 => s += &format!("f {} {} {} {}\np {i}\nl 1 {i}\n", i - 2, i - 1, i, i + 1),
                11 => s += "g next\nusemtl white\n",
                _ => {}
            }
        }
    }
    let bad = s.replacen("f 2000 ", "f 99999 ", 1);
    assert!(bad != s);
    for text in [&s, &bad] {
        let want = by_tobj(text.as_bytes());
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for block in [1, 7, 1 << 16] {
                let par = objtext::Parallel {
                    min_corners: 64,
                    block,
                };
                let (got, _) = pool.install(|| by_objtext_with(text.as_bytes(), 1000, par));
                assert!(same(&got, &want), "{threads} threads, {par:?}");
            }
        }
    }
}
