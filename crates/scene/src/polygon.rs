//! OBJ faces → triangles, in time linear in a face's size for convex faces.
//!
//! tobj's own triangulation fans every polygon from its first vertex: right only for convex
//! faces, and a fan of a 100k-vertex face is 100k slivers that all overlap at one vertex, so
//! the BVH over them degenerates (loading such a face took 31 s, a million vertices an hour).
//! Here a convex face (found in O(n log n)) is split in halves recursively: n - 2 triangles, most of
//! them small and local. Non-convex faces are ear-clipped, which is quadratic or worse in their
//! size, so only up to [`MAX_NONCONVEX`] corners; larger ones are refused with a clear error.
//! Vertices that lie inside a straight edge are no corners: a large face is triangulated
//! without them (in O(n)), as their triangles would have no area.

// A decoder of untrusted bytes: no input may reach a panic, so the lints that find the ways
// to one (unwrap, expect, indexing, explicit panics) are errors here; `cargo clippy` is the
// check.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::unreachable
    )
)]

use glam::{DVec2, DVec3, Vec3};

/// Largest non-convex face that is ear-clipped, in corners (at most n^3 / 6 point tests: about
/// 3M here, milliseconds). Larger non-convex faces are refused instead of hanging the load.
pub const MAX_NONCONVEX: usize = 256;

/// Convex faces up to this size are fanned from their first vertex exactly as tobj did, so
/// existing meshes (quads, small n-gons) keep the triangles they always had; larger convex
/// faces get the balanced split.
const FAN_MAX: usize = 16;

/// Appends the triangles of the polygon `face` (indices into `pos`; the caller checks they are
/// in range, and one that is not is an error) to `out`. Faces of fewer than three vertices
/// (points, lines) add nothing.
pub(crate) fn triangulate(
    face: &[u32],
    pos: &[Vec3],
    out: &mut Vec<[u32; 3]>,
) -> Result<(), String> {
    match *face {
        [] | [_] | [_, _] => return Ok(()),
        [a, b, c] => {
            out.push([a, b, c]);
            return Ok(());
        }
        _ => {}
    }
    let n = face.len();
    // Vertices inside straight edges add only zero-area triangles, and a BVH over many of
    // those (a square of 400k vertices along its edges) took minutes to build: triangulate the
    // corners. Faces up to `FAN_MAX` keep every vertex, and the triangles they always had.
    let corners;
    let face = if n > FAN_MAX {
        corners = drop_straight(face, pos)?;
        match corners.as_slice() {
            // No area at all: one triangle of it keeps it in sight of the checks that refuse
            // such faces (a zero-area light), instead of n - 2 of them.
            [] | [_] | [_, _] => {
                if let [a, b, c, ..] = *face {
                    out.push([a, b, c]);
                }
                return Ok(());
            }
            &[a, b, c] => {
                out.push([a, b, c]);
                return Ok(());
            }
            c => c,
        }
    } else {
        face
    };
    let p = project(face, pos)?;
    if is_convex(&p) {
        if let Some((&first, rest)) = face.split_first()
            && n <= FAN_MAX
        {
            for (&b, &c) in rest.iter().zip(rest.iter().skip(1)) {
                out.push([first, b, c]);
            }
        } else {
            balanced(face, out);
        }
        return Ok(());
    }
    let m = face.len();
    if m > MAX_NONCONVEX {
        let corners = if m < n {
            format!(" ({m} of them corners, the rest inside straight edges)")
        } else {
            String::new()
        };
        return Err(format!(
            "a non-convex face of {n} vertices{corners}: photonflow triangulates non-convex \
             faces of at most {MAX_NONCONVEX} corners (split it into smaller faces)"
        ));
    }
    ear_clip(face, &p, out);
    Ok(())
}

/// The face without the vertices that lie strictly inside the straight segment between their
/// neighbours (in 3D, exactly: the cross product of the two edges is zero and they point the
/// same way), nor those that repeat the vertex before them. Each removal keeps the face's
/// boundary point for point, so its triangles cover the same surface. One pass with a stack
/// (whole runs go, each vertex popped at most once), then the same across the wrap-around.
/// In 3D, not in the plane `project` picks: a face that is not planar may look straight
/// there and still bend.
fn drop_straight(face: &[u32], pos: &[Vec3]) -> Result<Vec<u32>, String> {
    let at = |i: u32| -> Result<DVec3, String> {
        pos.get(i as usize).map(|p| p.as_dvec3()).ok_or_else(|| {
            format!(
                "vertex {} is out of range ({} vertices)",
                i as u64 + 1,
                pos.len()
            )
        })
    };
    // `b` strictly between `a` and `c` on one line; f32 coordinates are exact in f64, so
    // collinear ones give exactly zero.
    let straight = |a: DVec3, b: DVec3, c: DVec3| {
        let (u, v) = (b - a, c - b);
        u.cross(v) == DVec3::ZERO && u.dot(v) > 0.0
    };
    let mut out: Vec<(u32, DVec3)> = Vec::with_capacity(face.len());
    for &i in face {
        let q = at(i)?;
        if out.last().is_some_and(|&(_, t)| t == q) {
            continue;
        }
        while let Some(&[(_, a), (_, b)]) = out.last_chunk::<2>() {
            if straight(a, b, q) {
                out.pop();
            } else {
                break;
            }
        }
        out.push((i, q));
    }
    // The wrap-around: the last vertices against the first, then the first against the last.
    let mut first = 0;
    loop {
        let m = out.len() - first;
        let (Some(&(_, f)), Some(&(_, f2))) = (out.get(first), out.get(first + 1)) else {
            break;
        };
        if m < 3 {
            break;
        }
        if let Some(&[(_, a), (_, b)]) = out.last_chunk::<2>()
            && (b == f || straight(a, b, f))
        {
            out.pop();
            continue;
        }
        match out.last() {
            Some(&(_, z)) if straight(z, f, f2) => first += 1,
            _ => break,
        }
    }
    Ok(out
        .get(first..)
        .unwrap_or_default()
        .iter()
        .map(|&(i, _)| i)
        .collect())
}

/// Each vertex with the next one, the last with the first.
fn edges<T>(v: &[T]) -> impl Iterator<Item = (&T, &T)> {
    v.iter().zip(v.iter().cycle().skip(1))
}

/// The face's vertices in 2D, in its plane (Newell's normal; the axis it points along most is
/// dropped), oriented counter-clockwise.
fn project(face: &[u32], pos: &[Vec3]) -> Result<Vec<DVec2>, String> {
    let v = face
        .iter()
        .map(|&i| {
            pos.get(i as usize).map(|p| p.as_dvec3()).ok_or_else(|| {
                format!(
                    "vertex {} is out of range ({} vertices)",
                    i as u64 + 1,
                    pos.len()
                )
            })
        })
        .collect::<Result<Vec<DVec3>, String>>()?;
    let Some(&o) = v.first() else {
        return Ok(Vec::new());
    };
    let mut normal = DVec3::ZERO;
    for (&a, &b) in edges(&v) {
        normal += (a - o).cross(b - o);
    }
    let a = normal.abs();
    // The two kept coordinates, in order, and the dropped axis's normal component.
    let (keep, s): (fn(DVec3) -> DVec2, f64) = if a.z >= a.x && a.z >= a.y {
        (|d| DVec2::new(d.x, d.y), normal.z)
    } else if a.x >= a.y {
        (|d| DVec2::new(d.y, d.z), normal.x)
    } else {
        (|d| DVec2::new(d.z, d.x), normal.y)
    };
    let flip = if s < 0.0 { -1.0 } else { 1.0 };
    Ok(v.iter()
        .map(|&p| {
            let d = keep(p - o);
            DVec2::new(flip * d.x, d.y)
        })
        .collect())
}

/// Convex, to within rounding: the face's area (shoelace, counter-clockwise) equals its convex
/// hull's to 1e-6 relative. Turn signs alone cannot tell: a 100k-gon written with six
/// decimals has rounding dents at half its vertices, and a face that winds twice or crosses
/// itself has turns of one sign only near its crossings. O(n log n) (a sort). A face with no
/// area at all counts as convex: any split of it is as degenerate as the face.
fn is_convex(p: &[DVec2]) -> bool {
    let area: f64 = edges(p).map(|(a, b)| a.perp_dot(*b)).sum::<f64>() / 2.0;
    let hull = hull_area(p);
    if hull <= 0.0 {
        return true;
    }
    (hull - area).abs() <= 1e-6 * hull
}

/// Area of the convex hull of `p` (Andrew's monotone chain).
fn hull_area(p: &[DVec2]) -> f64 {
    let mut pts: Vec<DVec2> = p.iter().copied().filter(|v| v.is_finite()).collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return 0.0;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &q in iter {
            // The last two points of this chain, while it has two.
            while let Some(&[a, b]) = hull.get(start..).and_then(|c| c.last_chunk::<2>()) {
                if (b - a).perp_dot(q - b) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(q);
        }
        // The last point of each chain is the first of the next.
        hull.pop();
    }
    edges(&hull).map(|(a, b)| a.perp_dot(*b)).sum::<f64>() / 2.0
}

/// A convex face split in halves: triangle (first, middle, last) of a chain of vertices, then
/// both halves, which share the middle vertex. Iterative, O(n); keeps the face's winding.
fn balanced(face: &[u32], out: &mut Vec<[u32; 3]>) {
    let mut stack = vec![face];
    while let Some(chain) = stack.pop() {
        if chain.len() < 3 {
            continue;
        }
        let m = (chain.len() - 1) / 2;
        if let (Some(left @ [a, ..]), Some(right @ [b, .., c])) = (chain.get(..=m), chain.get(m..))
        {
            out.push([*a, *b, *c]);
            stack.push(left);
            stack.push(right);
        }
    }
}

/// Ear clipping of a counter-clockwise polygon. A face with no ear left (self-intersecting or
/// degenerate) is finished as a fan, as tobj would have, so every face gives n - 2 triangles.
fn ear_clip(face: &[u32], p: &[DVec2], out: &mut Vec<[u32; 3]>) {
    // The polygon left to clip: each vertex with its projected point.
    let mut ring: Vec<(u32, DVec2)> = face.iter().copied().zip(p.iter().copied()).collect();
    while ring.len() > 3 {
        let m = ring.len();
        // The corner at ring position k: the previous vertex, k and the next, with positions.
        let corner = |k: usize| -> Option<[(usize, (u32, DVec2)); 3]> {
            let (i, j) = ((k + m - 1) % m, (k + 1) % m);
            Some([(i, *ring.get(i)?), (k, *ring.get(k)?), (j, *ring.get(j)?)])
        };
        let is_ear = |k: usize| {
            let Some([(ia, (_, a)), (ib, (_, b)), (ic, (_, c))]) = corner(k) else {
                return false;
            };
            if (b - a).perp_dot(c - b) <= 0.0 {
                return false;
            }
            !ring.iter().enumerate().any(|(iq, &(_, q))| {
                iq != ia && iq != ib && iq != ic && q != a && q != b && q != c && inside(q, a, b, c)
            })
        };
        let k = (0..m).find(|&k| is_ear(k)).unwrap_or(0);
        let Some([(_, (a, _)), (_, (b, _)), (_, (c, _))]) = corner(k) else {
            break;
        };
        out.push([a, b, c]);
        ring.remove(k);
    }
    if let [(a, _), (b, _), (c, _)] = *ring {
        out.push([a, b, c]);
    }
}

/// `q` inside or on the counter-clockwise triangle (a, b, c).
fn inside(q: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    (b - a).perp_dot(q - a) >= 0.0
        && (c - b).perp_dot(q - b) >= 0.0
        && (a - c).perp_dot(q - c) >= 0.0
}
