//! Faces to triangles: convex, non-convex and straight-edged faces, by area and count.

use super::{GOOD_MTL, Scratch, scene_toml};
use crate::Scene;

/// An OBJ of the light and one face of `pts` (x, z at y = `y(i)`), material `white`.
fn face_obj(pts: &[(f64, f64)], y: impl Fn(usize) -> f64) -> String {
    let light = "o light\nusemtl light\nv -0.1 1 -0.1\nv 0.1 1 -0.1\nv 0.1 1 0.1\nv -0.1 1 0.1\nf 1 2 3\nf 1 3 4\n";
    let mut o = format!("mtllib m.mtl\n{light}o face\nusemtl white\n");
    for (i, (x, z)) in pts.iter().enumerate() {
        o += &format!("v {x} {} {z}\n", y(i));
    }
    o += "f";
    for i in 0..pts.len() {
        o += &format!(" {}", i + 5);
    }
    o + "\n"
}

/// The face's triangles (those of material `white`) and their total area, or the load error.
fn face_area(obj: &str) -> Result<(usize, f64), String> {
    // One directory per call: the tests that call this run in parallel.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = Scratch::new(
        &format!("poly-{call}"),
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", obj),
            ("m.mtl", GOOD_MTL),
        ],
    );
    let s = Scene::load(dir.path("s.toml")).map_err(|e| e.to_string())?;
    let m = s.geometry.mesh();
    let white = s.material_of("white").unwrap();
    let tris: Vec<usize> = (0..m.len()).filter(|&t| m.materials[t] == white).collect();
    Ok((tris.len(), tris.iter().map(|&t| m.area(t) as f64).sum()))
}

/// Faces are triangulated in (near) linear time: a convex face of 200k vertices loads at
/// once (a fan of it took minutes to build a BVH over), a non-convex face is ear-clipped
/// into the right area, and a huge non-convex face is refused, not clipped for hours.
#[test]
fn polygons_triangulate_fast_and_right() {
    let face = |pts: &[(f64, f64)]| face_obj(pts, |_| 0.0);
    let area_of = face_area;
    // An L of area 3: a fan from its first vertex (tobj's) covers 4, outside the L.
    let l = [
        (0.0, 2.0),
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
    ];
    let (n, a) = area_of(&face(&l)).unwrap();
    assert_eq!(n, 4);
    assert!((a - 3.0).abs() < 1e-5, "L-shape area {a}");
    // A circle of 200k vertices written with 7 decimals (rounding dents everywhere).
    let n = 200_000;
    let circle: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            (
                (t.cos() * 1e7).round() / 1e7,
                -(t.sin() * 1e7).round() / 1e7,
            )
        })
        .collect();
    // Rounding puts runs of vertices on exactly straight lines (near the axes, where one
    // coordinate moves by a step of the 7th decimal or none between neighbours): those are
    // not corners, and the face is triangulated by the others. Counted here on the f32
    // coordinates the loader reads, each vertex against its neighbours.
    let read: Vec<[f64; 2]> = circle
        .iter()
        .map(|&(x, z)| [x, z].map(|c| f64::from(format!("{c}").parse::<f32>().unwrap())))
        .collect();
    let inside = (0..n)
        .filter(|&i| {
            let [a, b, c] = [read[(i + n - 1) % n], read[i], read[(i + 1) % n]];
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            u[0] * v[1] - u[1] * v[0] == 0.0 && u[0] * v[0] + u[1] * v[1] > 0.0
        })
        .count();
    assert!(
        inside > 0 && inside < n / 10,
        "{inside} vertices on straight runs"
    );
    // Work done, not seconds: every corner is in exactly one fan triangle (speed is the
    // bad-input table's timeout's business, and a benchmark's).
    let (tris, a) = area_of(&face(&circle)).unwrap();
    assert_eq!(tris, n - inside - 2);
    assert!((a - std::f64::consts::PI).abs() < 1e-3, "circle area {a}");
    // The same circle with a notch: non-convex and far too big to ear-clip.
    let mut notched = circle.clone();
    notched[n / 2] = (0.0, 0.0);
    let e = area_of(&face(&notched)).unwrap_err();
    assert!(e.contains("a non-convex face of 200000 vertices"), "{e}");
}

/// Vertices inside straight edges are not corners: a face along a square's edges is two
/// triangles (it used to be n - 2, most of zero area, and a BVH over 400k of those took
/// minutes), a non-convex face with long straight edges is clipped by its corners (it used to
/// be refused as too big to clip), and what only looks straight in the face's plane, or a
/// face with no area, keeps what it had.
#[test]
fn straight_edges_are_triangulated_by_their_corners() {
    // A square of side 2 with `q` vertices per edge, corners included, counter-clockwise.
    let square = |q: usize| -> Vec<(f64, f64)> {
        let t = |i: usize| -1.0 + 2.0 * i as f64 / q as f64;
        let mut p = Vec::new();
        p.extend((0..q).map(|i| (t(i), -1.0)));
        p.extend((0..q).map(|i| (1.0, t(i))));
        p.extend((0..q).map(|i| (-t(i), 1.0)));
        p.extend((0..q).map(|i| (-1.0, -t(i))));
        p
    };
    let flat = |_| 0.0;
    let (tris, a) = face_area(&face_obj(&square(25_000), flat)).unwrap();
    assert_eq!(tris, 2);
    assert!((a - 4.0).abs() < 1e-6, "square area {a}");
    // Vertex 0 repeated, and the run across the wrap-around (the last edge into the first).
    let mut sq = square(50);
    sq.rotate_left(25);
    sq.insert(0, sq[0]);
    let (tris, a) = face_area(&face_obj(&sq, flat)).unwrap();
    assert_eq!(tris, 2);
    assert!((a - 4.0).abs() < 1e-6, "rotated square area {a}");
    // An L of area 3 with 1000 vertices per unit of edge: 6 corners, 4 triangles.
    let corners: [(f64, f64); 6] = [
        (0.0, 2.0),
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
    ];
    let mut l = Vec::new();
    for (k, &(x0, z0)) in corners.iter().enumerate() {
        let (x1, z1) = corners[(k + 1) % corners.len()];
        let steps = 1000 * (x1 - x0).abs().max((z1 - z0).abs()) as usize;
        l.extend((0..steps).map(|i| {
            let f = i as f64 / steps as f64;
            (x0 + f * (x1 - x0), z0 + f * (z1 - z0))
        }));
    }
    assert_eq!(l.len(), 8000);
    let (tris, a) = face_area(&face_obj(&l, flat)).unwrap();
    assert_eq!(tris, 4);
    assert!((a - 3.0).abs() < 1e-5, "L area {a}");
    // Straight seen from above, but the edge z = -1 zigzags in y: its 8 vertices stay, the
    // 7 inside each other edge go.
    let sq = square(8);
    let zigzag = |i: usize| if i < 8 && i % 2 == 1 { 0.01 } else { 0.0 };
    let (tris, _) = face_area(&face_obj(&sq, zigzag)).unwrap();
    assert_eq!(tris, sq.len() - 3 * 7 - 2);
    // A face of 20 vertices on one line has no area: one triangle of it, not 18.
    let line: Vec<(f64, f64)> = (0..20).map(|i| (i as f64 * 0.1, 0.0)).collect();
    let (tris, a) = face_area(&face_obj(&line, flat)).unwrap();
    assert_eq!((tris, a), (1, 0.0));
}
