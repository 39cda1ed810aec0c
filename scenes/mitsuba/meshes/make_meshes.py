"""The gallery's PLY mesh, written by Mitsuba 3 (`Mesh.write_ply`, binary little endian):
an icosphere of 320 triangles (an icosahedron subdivided twice, vertices on the unit
sphere) with per-vertex normals. Run with the peers' Python: `python make_meshes.py`."""
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")
t = (1 + 5 ** 0.5) / 2
v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
     (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
     (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
     (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
v = [np.array(p, float) / np.linalg.norm(p) for p in v]
for _ in range(2):
    mid = {}
    def m(a, b):
        k = (min(a, b), max(a, b))
        if k not in mid:
            p = v[a] + v[b]
            v.append(p / np.linalg.norm(p))
            mid[k] = len(v) - 1
        return mid[k]
    f = [g for a, b, c in f for g in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)),
                                      (c, m(c, a), m(b, c)), (m(a, b), m(b, c), m(c, a)))]
P = np.array(v, dtype=np.float32)
F = np.array(f, dtype=np.uint32)
mesh = mi.Mesh("icosphere", len(P), len(F), has_vertex_normals=True)
params = mi.traverse(mesh)
params["vertex_positions"] = P.ravel()
params["faces"] = F.ravel()
params["vertex_normals"] = P.ravel()
params.update()
mesh.write_ply("icosphere.ply")
print(len(P), "vertices,", len(F), "triangles")
