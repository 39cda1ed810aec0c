"""The peers' mitsuba_render.py with two more MTL codes for analytic spheres, so that scene
files with GGX spheres translate one to one (make.sh writes these MTL lines itself), and
albedo textures:

  illum 13, Ks, Ns = alpha  -> roughconductor (ggx, material none, specular_reflectance Ks)
  illum 14, Ni, Ns = alpha  -> roughdielectric (ggx, int_ior Ni, ext_ior 1)
  map_Kd FILE on a diffuse  -> diffuse with a bitmap reflectance (bilinear, repeat, 8-bit files
  material, Kd 1 1 1           sRGB-decoded); the OBJ's `vt` become the mesh's texture
                               coordinates as Mitsuba's own OBJ reader makes them, (u, 1 - v)

`--tf transmitted|absorbed` (default transmitted) says how the MTL's `Tf` is read on glass
(illum 4, 6, 7, 9), as the scene file's `[[mesh]] tf` says to photonflow: `transmitted`, the
Wavefront spec's fraction let through, is Mitsuba's `specular_transmittance` as it is;
`absorbed` (G3D's reading, McGuire's archive) gives it `1 - Tf`. Unlike the peers' mapping,
which drops it when a channel is 1, it is set whenever a channel is below 1.

It also takes `--lights FILE.json`: a JSON list of the scene file's `[[light]]` tables (as
make.sh writes them, `filename` made absolute), added to the scene as Mitsuba 3 emitters:

  point        -> point (position, intensity)
  spot         -> spot (to_world = look_at(position, look_at, up), intensity, cutoff_angle,
                  beam_width given explicitly, default cutoff_angle * 3/4); Mitsuba's spot
                  shines along its local +z, which look_at maps to look_at - position; up is
                  [0, 1, 0], or [1, 0, 0] when the axis is within 1 degree of vertical (the
                  spot is round: up only fixes the unused roll)
  directional  -> directional (direction: the way the light travels, irradiance)
  environment  -> envmap (filename, scale, to_world = Rz(z) Ry(y) Rx(x) of `rotate` in
                  degrees, x applied first); or, with `radiance`, constant (radiance)

Everything else is the peers' script: run as `python mitsuba_render_rough.py PEERS ARGS...`
with PEERS the peers' directory and ARGS mitsuba_render.py's own (plus `--lights`)."""
import json
import os
import sys

import numpy as np

peers = sys.argv.pop(1)
lights_json = None
if "--lights" in sys.argv:
    i = sys.argv.index("--lights")
    lights_json = sys.argv[i + 1]
    del sys.argv[i:i + 2]
tf_reading = "transmitted"
if "--tf" in sys.argv:
    i = sys.argv.index("--tf")
    tf_reading = sys.argv[i + 1]
    del sys.argv[i:i + 2]
    if tf_reading not in ("transmitted", "absorbed"):
        sys.exit(f"--tf {tf_reading}: transmitted or absorbed")
sys.path.insert(0, peers)
import mitsuba_render  # noqa: E402
import objmtl  # noqa: E402

classify, bsdf_dict = objmtl.classify, mitsuba_render.bsdf_dict


def rough_classify(mat, glossy=False):
    illum = int(mat.get("illum", 1))
    if "map_Kd" in mat:
        if illum not in (0, 1) or tuple(mat.get("Kd", (1, 1, 1))) != (1.0, 1.0, 1.0) or max(mat["Ke"]) > 0:
            sys.exit(f"map_Kd {mat['map_Kd']}: this wrapper draws textures on illum 0/1 with Kd 1 1 1 only")
        return "texture", {"filename": mat["map_Kd"]}
    if illum == 13:
        return "roughconductor", {"reflectance": tuple(mat["Ks"]), "alpha": float(mat["Ns"])}
    if illum == 14:
        return "roughdielectric", {"ior": float(mat["Ni"]), "alpha": float(mat["Ns"])}
    kind, p = classify(mat, glossy)
    if kind == "dielectric":
        tf = tuple(float(x) for x in mat.get("Tf", (1.0, 1.0, 1.0)))
        if min(tf) < 0.0 or max(tf) > 1.0:
            sys.exit(f"Tf {tf}: each channel in [0, 1]")
        t = tf if tf_reading == "transmitted" else tuple(1.0 - x for x in tf)
        return "glass", {"ior": p["ior"], "transmittance": t}
    return kind, p


def rough_bsdf_dict(kind, p):
    if kind == "roughconductor":
        return {"type": "roughconductor", "distribution": "ggx", "alpha": p["alpha"],
                "material": "none", "specular_reflectance": mitsuba_render.rgb(p["reflectance"])}
    if kind == "texture":
        return {"type": "diffuse", "reflectance": {"type": "bitmap", "filename": p["filename"],
                "filter_type": "bilinear", "wrap_mode": "repeat", "raw": False}}
    if kind == "glass":
        d = {"type": "dielectric", "int_ior": float(p["ior"]), "ext_ior": 1.0}
        if min(p["transmittance"]) < 1.0:
            d["specular_transmittance"] = mitsuba_render.rgb(p["transmittance"])
        return d
    if kind == "roughdielectric":
        return {"type": "roughdielectric", "distribution": "ggx", "alpha": p["alpha"],
                "int_ior": p["ior"], "ext_ior": 1.0}
    return bsdf_dict(kind, p)


load_mtl = objmtl.load_mtl


def load_mtl_with_maps(path):
    """The peers' reader, plus `map_Kd` (an absolute path) for the materials that have one."""
    mats, cur = load_mtl(path), None
    with open(path) as f:
        for raw in f:
            tok = raw.split("#", 1)[0].split()
            if tok and tok[0] == "newmtl":
                cur = " ".join(tok[1:])
            elif tok and tok[0] == "map_Kd" and cur in mats:
                mats[cur]["map_Kd"] = os.path.join(os.path.dirname(os.path.abspath(path)), " ".join(tok[1:]))
    return mats


groups_read = []


def load_obj_with_uv(path):
    """The peers' load_obj for meshes whose groups may carry `vt`: a vertex is a (v, vn, vt)
    triple; a group whose every corner has a `vt` gets `texcoords`."""
    base = os.path.dirname(os.path.abspath(path))
    V, N, T, materials, groups = [], [], [], {}, []
    name, mat, cur = "default", None, None
    with open(path) as f:
        for raw in f:
            tok = raw.split()
            if not tok or tok[0].startswith("#"):
                continue
            key = tok[0]
            if key == "v":
                V.append(tuple(float(t) for t in tok[1:4]))
            elif key == "vn":
                N.append(tuple(float(t) for t in tok[1:4]))
            elif key == "vt":
                T.append(tuple(float(t) for t in tok[1:3]))
            elif key == "f":
                if cur is None:
                    cur = {"name": name, "material": mat, "tris": []}
                    groups.append(cur)
                idx = []
                for t in tok[1:]:
                    parts = (t.split("/") + ["", ""])[:3]
                    ref = lambda s, n: (int(s) - 1 if int(s) > 0 else n + int(s)) if s else -1
                    idx.append((ref(parts[0], len(V)), ref(parts[2], len(N)), ref(parts[1], len(T))))
                for k in range(1, len(idx) - 1):
                    cur["tris"].append((idx[0], idx[k], idx[k + 1]))
            elif key in ("o", "g"):
                name, cur = " ".join(tok[1:]) or "default", None
            elif key == "usemtl":
                mat, cur = " ".join(tok[1:]), None
            elif key == "mtllib":
                for lib in tok[1:]:
                    materials.update(objmtl.load_mtl(os.path.join(base, lib)))
    V, N, T = (np.asarray(a, dtype=np.float64) for a in (V, N or np.zeros((0, 3)), T or np.zeros((0, 2))))
    out = []
    for g in groups:
        if not g["tris"]:
            continue
        corners = np.asarray(g["tris"], dtype=np.int64).reshape(-1, 3)
        uniq, inv = np.unique(corners, axis=0, return_inverse=True)
        has_n, has_t = bool(np.all(uniq[:, 1] >= 0)), bool(np.all(uniq[:, 2] >= 0))
        nrm = None
        if has_n:
            nrm = N[uniq[:, 1]]
            nrm = (nrm / np.linalg.norm(nrm, axis=1, keepdims=True)).astype(np.float32)
        uv = None
        if has_t:
            uv = T[uniq[:, 2]].copy()
            uv[:, 1] = 1.0 - uv[:, 1]
        out.append({"name": g["name"], "material": g["material"], "positions": V[uniq[:, 0]].astype(np.float32),
                    "normals": nrm, "faces": inv.reshape(-1, 3).astype(np.uint32), "texcoords": uv})
    groups_read[:] = out
    return out, materials


class WithTexcoords:
    """The mitsuba module as build_scene sees it: meshes of groups with `texcoords` are made
    with texture coordinates, set with the other buffers before build_scene's update()."""

    def __init__(self, mi):
        self.mi, self.pending = mi, {}

    def __getattr__(self, key):
        return getattr(self.mi, key)

    def Mesh(self, name, nv, nf, props=None, has_vertex_normals=False):
        uv = groups_read[int(name.split("_")[0])]["texcoords"]
        mesh = self.mi.Mesh(name, nv, nf, props=props, has_vertex_normals=has_vertex_normals,
                            has_vertex_texcoords=uv is not None)
        if uv is not None:
            self.pending[id(mesh)] = uv
        return mesh

    def load_dict(self, d, *a, **k):
        if lights_json and isinstance(d, dict) and d.get("type") == "scene":
            d = dict(d)
            with open(lights_json) as f:
                for i, light in enumerate(json.load(f)):
                    d[f"light_{i:03d}"] = emitter_dict(self.mi, light)
        return self.mi.load_dict(d, *a, **k)

    def traverse(self, obj):
        params = self.mi.traverse(obj)
        uv = self.pending.pop(id(obj), None)
        if uv is not None:
            params["vertex_texcoords"] = np.ascontiguousarray(uv, dtype=np.float32).ravel()
        return params


def rotation_xyz(deg):
    """Rz(z) Ry(y) Rx(x) for `rotate = [x, y, z]` degrees (x applied first), as a 4x4 list."""
    x, y, z = np.radians(np.asarray(deg, dtype=np.float64))
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    return m.tolist()


def emitter_dict(mi, light):
    """One scene-file [[light]] table -> a Mitsuba 3 emitter dict (module docstring)."""
    rgb = mitsuba_render.rgb
    kind = light["type"]
    if kind == "point":
        return {"type": "point", "position": [float(v) for v in light["position"]],
                "intensity": rgb(light["intensity"])}
    if kind == "spot":
        pos, at = (np.asarray(light[k], dtype=np.float64) for k in ("position", "look_at"))
        axis = (at - pos) / np.linalg.norm(at - pos)
        up = [0.0, 1.0, 0.0] if abs(axis[1]) < np.cos(np.radians(1.0)) else [1.0, 0.0, 0.0]
        cutoff = float(light.get("cutoff_angle", 20.0))
        return {"type": "spot", "intensity": rgb(light["intensity"]), "cutoff_angle": cutoff,
                "beam_width": float(light.get("beam_width", cutoff * 0.75)),
                "to_world": mi.ScalarTransform4f().look_at(origin=pos.tolist(), target=at.tolist(), up=up)}
    if kind == "directional":
        return {"type": "directional", "direction": [float(v) for v in light["direction"]],
                "irradiance": rgb(light["irradiance"])}
    if kind == "environment":
        if "radiance" in light:
            return {"type": "constant", "radiance": rgb(light["radiance"])}
        return {"type": "envmap", "filename": light["filename"], "scale": float(light.get("scale", 1.0)),
                "to_world": mi.ScalarTransform4f(rotation_xyz(light.get("rotate", [0, 0, 0])))}
    sys.exit(f"light type {kind}: not mapped")


build_scene = mitsuba_render.build_scene
objmtl.classify = rough_classify
objmtl.load_mtl = load_mtl_with_maps
objmtl.load_obj = load_obj_with_uv
mitsuba_render.bsdf_dict = rough_bsdf_dict
mitsuba_render.build_scene = lambda mi, *a: build_scene(WithTexcoords(mi), *a)
mitsuba_render.main()
