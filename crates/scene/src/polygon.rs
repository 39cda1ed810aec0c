//! OBJ faces → triangles, in time linear in a face's size for convex faces.
//!
//! tobj's own triangulation fans every polygon from its first vertex: right only for convex
//! faces, and a fan of a 100k-vertex face is 100k slivers that all overlap at one vertex, so
//! the BVH over them degenerates (loading such a face took 31 s, a million vertices an hour).
//! Here a convex face (found in O(n log n)) is split in halves recursively: n - 2 triangles, most of
//! them small and local. Non-convex faces are ear-clipped, which is quadratic or worse in their
//! size, so only up to [`MAX_NONCONVEX`] vertices; larger ones are refused with a clear error.

use glam::{DVec2, DVec3, Vec3};

/// Largest non-convex face that is ear-clipped (at most n^3 / 6 point tests: about 3M here,
/// milliseconds). Larger non-convex faces are refused instead of hanging the load.
pub const MAX_NONCONVEX: usize = 256;

/// Convex faces up to this size are fanned from their first vertex exactly as tobj did, so
/// existing meshes (quads, small n-gons) keep the triangles they always had; larger convex
/// faces get the balanced split.
const FAN_MAX: usize = 16;

/// Appends the triangles of the polygon `face` (indices into `pos`, all in range: the caller
/// checks) to `out`. Faces of fewer than three vertices (points, lines) add nothing.
pub(crate) fn triangulate(
    face: &[u32],
    pos: &[Vec3],
    out: &mut Vec<[u32; 3]>,
) -> Result<(), String> {
    let n = face.len();
    if n < 3 {
        return Ok(());
    }
    if n == 3 {
        out.push([face[0], face[1], face[2]]);
        return Ok(());
    }
    let p = project(face, pos);
    if is_convex(&p) {
        if n <= FAN_MAX {
            for i in 1..n - 1 {
                out.push([face[0], face[i], face[i + 1]]);
            }
        } else {
            balanced(face, out);
        }
        return Ok(());
    }
    if n > MAX_NONCONVEX {
        return Err(format!(
            "a non-convex face of {n} vertices: photonflow triangulates non-convex faces of at \
             most {MAX_NONCONVEX} vertices (split it into smaller faces)"
        ));
    }
    ear_clip(face, &p, out);
    Ok(())
}

/// The face's vertices in 2D, in its plane (Newell's normal; the axis it points along most is
/// dropped), oriented counter-clockwise.
fn project(face: &[u32], pos: &[Vec3]) -> Vec<DVec2> {
    let v = |i: usize| pos[face[i] as usize].as_dvec3();
    let o = v(0);
    let mut normal = DVec3::ZERO;
    for i in 0..face.len() {
        let a = v(i) - o;
        let b = v((i + 1) % face.len()) - o;
        normal += a.cross(b);
    }
    let a = normal.abs();
    let (x, y, s) = if a.z >= a.x && a.z >= a.y {
        (0, 1, normal.z)
    } else if a.x >= a.y {
        (1, 2, normal.x)
    } else {
        (2, 0, normal.y)
    };
    let flip = if s < 0.0 { -1.0 } else { 1.0 };
    (0..face.len())
        .map(|i| {
            let d = (v(i) - o).to_array();
            DVec2::new(flip * d[x], d[y])
        })
        .collect()
}

/// Convex, to within rounding: the face's area (shoelace, counter-clockwise) equals its convex
/// hull's to 1e-6 relative. Turn signs alone cannot tell: a 100k-gon written with six
/// decimals has rounding dents at half its vertices, and a face that winds twice or crosses
/// itself has turns of one sign only near its crossings. O(n log n) (a sort). A face with no
/// area at all counts as convex: any split of it is as degenerate as the face.
fn is_convex(p: &[DVec2]) -> bool {
    let n = p.len();
    let area: f64 = (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() / 2.0;
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
            while hull.len() >= start + 2 {
                let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
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
    let m = hull.len();
    (0..m)
        .map(|i| hull[i].perp_dot(hull[(i + 1) % m]))
        .sum::<f64>()
        / 2.0
}

/// A convex face split in halves: triangle (i, m, j) with m the middle of the chain i..j, then
/// both halves. Iterative, O(n); keeps the face's winding.
fn balanced(face: &[u32], out: &mut Vec<[u32; 3]>) {
    let mut stack = vec![(0usize, face.len() - 1)];
    while let Some((i, j)) = stack.pop() {
        if j - i < 2 {
            continue;
        }
        let m = i + (j - i) / 2;
        out.push([face[i], face[m], face[j]]);
        stack.push((i, m));
        stack.push((m, j));
    }
}

/// Ear clipping of a counter-clockwise polygon. A face with no ear left (self-intersecting or
/// degenerate) is finished as a fan, as tobj would have, so every face gives n - 2 triangles.
fn ear_clip(face: &[u32], p: &[DVec2], out: &mut Vec<[u32; 3]>) {
    let mut idx: Vec<usize> = (0..face.len()).collect();
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            if (p[b] - p[a]).perp_dot(p[c] - p[b]) <= 0.0 {
                return false;
            }
            !idx.iter().any(|&q| {
                q != a
                    && q != b
                    && q != c
                    && p[q] != p[a]
                    && p[q] != p[b]
                    && p[q] != p[c]
                    && inside(p[q], p[a], p[b], p[c])
            })
        });
        let k = ear.unwrap_or(0);
        let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
        out.push([face[a], face[b], face[c]]);
        idx.remove(k);
    }
    out.push([face[idx[0]], face[idx[1]], face[idx[2]]]);
}

/// `q` inside or on the counter-clockwise triangle (a, b, c).
fn inside(q: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    (b - a).perp_dot(q - a) >= 0.0
        && (c - b).perp_dot(q - b) >= 0.0
        && (a - c).perp_dot(q - c) >= 0.0
}
