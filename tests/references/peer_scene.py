#!/usr/bin/env python3
"""A scene file of this repository as the peers read it (make.sh and peer.sh share it).

  peer_scene.py PEERS KIND SCENE.toml W H OUT.json
      the camera JSON (mitsuba_render.py's format) of the scene's [camera] at W x H, after
      checking the scene is still what the peers' description assumes (KIND: obj | worksheet |
      obj-spheres); see make.sh for what each kind writes beside OUT.json.
  peer_scene.py PEERS auto SCENE.toml OUT.json
      the kind found from the scene file, the camera at the scene's own size, and shell
      assignments on stdout for peer.sh: KIND, W, H, OBJ (the OBJ the peers read), SPHERES
      (their spheres JSON, or empty), LIGHTS (the lights JSON, or empty), GLOSSY (1 when an
      MTL material is illum 2 with Ks > 0: only Mitsuba's --glossy maps it) and WORKSHEET (1
      for the worksheet scene itself, the one SmallVCM renders: its camera, clear glass), TF
      (the mesh's `tf`: how its MTL's `Tf` is read on glass, `transmitted` or `absorbed`) and
      DIAG (the diagonal of the OBJ's bounding box, for radii in scene units).
"""
import json, os, shlex, sys, tomllib


def convert(peers, kind, src, w, h, out):
    with open(src, "rb") as f:
        s = tomllib.load(f)
    def need(ok, what):
        if not ok:
            sys.exit(f"{src}: {what}: the Mitsuba description in make.sh no longer matches")
    meshes, spheres, mats = s.get("mesh", []), s.get("sphere", []), s.get("material", {})
    if kind in ("obj", "obj-spheres"):  # one OBJ, untransformed, MTL materials with emission in Ke
        if kind == "obj":
            need(len(meshes) == 1 and not spheres and not mats, "one mesh, no spheres, no [material]")
        else:
            need(len(meshes) == 1 and spheres, "one mesh and spheres")
            mtl, doc = [], {"mtllib": os.path.basename(out)[:-5] + "-spheres.mtl", "spheres": []}
            for name, m in mats.items():
                if m.get("type") == "metal":
                    r = m["reflectance"]
                    mtl.append(f"newmtl {name}\nKd 0 0 0\nKs {r[0]} {r[1]} {r[2]}\nillum 3\n")
                elif m.get("type") == "dielectric":
                    mtl.append(f"newmtl {name}\nKd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi {m['ior']}\nillum 7\n")
                elif m.get("type") == "rough_conductor" and "eta" not in m and "k" not in m:
                    r = m.get("reflectance", [1, 1, 1])
                    mtl.append(f"newmtl {name}\nKs {r[0]} {r[1]} {r[2]}\nNs {m['alpha']}\nillum 13\n")
                elif m.get("type") == "lambertian" and set(m) <= {"type", "albedo"}:
                    r = m["albedo"]
                    mtl.append(f"newmtl {name}\nKd {r[0]} {r[1]} {r[2]}\nillum 1\n")
                elif m.get("type") == "rough_dielectric":
                    mtl.append(f"newmtl {name}\nNi {m['ior']}\nNs {m['alpha']}\nillum 14\n")
                else:
                    need(False, f"material {name}: only metal, dielectric, rough_conductor (no eta, k), rough_dielectric and lambertian (no texture, no emission) spheres")
            for i, sp in enumerate(spheres):
                need(sp["material"] in mats, "sphere " + sp["material"] + ": a [material] of the scene file")
                doc["spheres"].append({"name": f"sphere_{i}", "material": sp["material"],
                                       "center": sp["center"], "radius": sp["radius"]})
            with open(out[:-5] + "-spheres.mtl", "w") as f:
                f.write("\n".join(mtl))
            with open(out[:-5] + "-spheres.json", "w") as f:
                json.dump(doc, f)
        m = meshes[0]
        need(m.get("scale", 1.0) in (1, 1.0, [1, 1, 1]) and m.get("rotate", [0, 0, 0]) == [0, 0, 0]
             and m.get("translate", [0, 0, 0]) == [0, 0, 0], "no transform")
        need(m.get("emission", "ke") == "ke" and m.get("normals", "auto") == "auto", "Ke emission, file normals")
    else:  # worksheet: CornellBox.obj scaled 0.025, turned 180 degrees about y, two spheres
        need(len(meshes) == 1 and os.path.basename(meshes[0]["obj"]) == "CornellBox.obj" and meshes[0].get("scale") == 0.025
             and meshes[0].get("rotate") == [0.0, 180.0, 0.0] and meshes[0].get("emission") == "ka", "box mesh")
        with open(f"{peers}/worksheet/cornell_worksheet_spheres.json") as f:
            ref = {x["material"]: x for x in json.load(f)["spheres"]}
        need(len(spheres) == 2, "two spheres")
        for sp in spheres:
            r = ref[sp["material"]]
            need(abs(sp["radius"] - r["radius"]) < 1e-6
                 and max(abs(a - b) for a, b in zip(sp["center"], r["center"])) < 1e-5, "sphere " + sp["material"])
        need(mats.get("silver") == {"type": "metal", "reflectance": [0.96, 0.98, 0.96]}, "silver: constant-Ks metal")
        glass = dict(mats.get("glass", {}))
        tf = glass.pop("transmittance", None)
        need(glass == {"type": "dielectric", "ior": 1.5}, "glass: dielectric, ior 1.5, no absorption")
        if tf is not None:
            # Coloured glass: the peers' spheres and MTL with the glass's `Tf` set (their mapping
            # gives it to Mitsuba's specular_transmittance only when every channel is below 1).
            need(max(tf) < 1.0 and min(tf) >= 0.0, "glass: transmittance below 1 in every channel")
            with open(f"{peers}/worksheet/cornell_worksheet.mtl") as f:
                mtl = f.read()
            need(mtl.count("Tf 1 1 1") == 1, "the peers' MTL has one clear glass")
            with open(out[:-5] + "-spheres.mtl", "w") as f:
                f.write(mtl.replace("Tf 1 1 1", f"Tf {tf[0]} {tf[1]} {tf[2]}"))
            with open(f"{peers}/worksheet/cornell_worksheet_spheres.json") as f:
                doc = json.load(f)
            doc["mtllib"] = os.path.basename(out)[:-5] + "-spheres.mtl"
            with open(out[:-5] + "-spheres.json", "w") as f:
                json.dump(doc, f)
    # [[light]]: the scene file's tables as a JSON list beside OUT (OUT-lights.json), each checked
    # against the keys mitsuba_render_rough.py maps (--lights), an environment's filename made
    # absolute (relative to the scene file).
    keys = {"point": ({"position", "intensity"}, set()),
            "spot": ({"position", "look_at", "intensity"}, {"cutoff_angle", "beam_width"}),
            "directional": ({"direction", "irradiance"}, set()),
            "environment": (set(), {"filename", "scale", "radiance", "rotate"})}
    lights = []
    for i, l in enumerate(s.get("light", [])):
        l = dict(l)
        kind = l.pop("type", None)
        need(kind in keys, f"light {i}: type point, spot, directional or environment")
        req, opt = keys[kind]
        need(req <= set(l) <= req | opt, f"light {i} ({kind}): keys {sorted(req)} and optionally {sorted(opt)}")
        if kind == "environment":
            need(("filename" in l) != ("radiance" in l), f"light {i}: filename or radiance, one of them")
            need("radiance" not in l or set(l) == {"radiance"}, f"light {i}: radiance alone (a constant has no scale or rotate)")
            if "filename" in l:
                l["filename"] = os.path.join(os.path.dirname(os.path.abspath(src)), l["filename"])
                need(os.path.exists(l["filename"]), f"light {i}: {l['filename']} exists")
        l["type"] = kind
        lights.append(l)
    if lights:
        with open(out[:-5] + "-lights.json", "w") as f:
            json.dump(lights, f)
    c = s["camera"]
    cam = {"type": "perspective", "position": c["eye"], "look_at": c["look_at"],
           "up": c.get("up", [0.0, 1.0, 0.0]), "vfov_deg": c["vfov"], "width": int(w), "height": int(h),
           "pixel_filter": "box", "near_clip": 1e-3}
    with open(out, "w") as f:
        json.dump(cam, f)

def auto(peers, src, out):
    with open(src, "rb") as f:
        s = tomllib.load(f)
    meshes, spheres = s.get("mesh", []), s.get("sphere", [])
    if len(meshes) != 1:
        sys.exit(f"{src}: the peers read one OBJ; the scene has {len(meshes)} [[mesh]] tables")
    m, here = meshes[0], os.path.dirname(os.path.abspath(src))
    c = s["camera"]
    w, h = c["width"], c["height"]
    if os.path.basename(m.get("obj", "")) == "CornellBox.obj" and m.get("emission") == "ka":
        kind, obj = "worksheet", f"{peers}/worksheet/cornell_worksheet_box.obj"
    else:
        kind, obj = ("obj-spheres" if spheres else "obj"), os.path.join(here, m["obj"])
    convert(peers, kind, src, w, h, out)
    sph = out[:-5] + "-spheres.json"
    if not os.path.exists(sph):
        sph = f"{peers}/worksheet/cornell_worksheet_spheres.json" if kind == "worksheet" else ""
    lights = out[:-5] + "-lights.json"
    glossy = 0
    mtls = [os.path.join(os.path.dirname(obj), l.split(None, 1)[1].strip())
            for l in open(obj) if l.startswith("mtllib ")]
    for p in mtls:
        illum, ks = None, 0.0
        for l in open(p).read().splitlines() + ["newmtl"]:
            t = l.split()
            if t and t[0] == "newmtl":
                glossy |= int(illum == 2 and ks > 0)
                illum, ks = None, 0.0
            elif t and t[0] == "illum":
                illum = int(t[1])
            elif t and t[0] == "Ks":
                ks = max(float(x) for x in t[1:4])
    worksheet = int(kind == "worksheet" and sph.endswith("cornell_worksheet_spheres.json")
                    and c["eye"] == [-6.95, 6.86, 14.026] and c["look_at"] == [-6.95, 6.86, -6.99]
                    and c.get("up", [0.0, 1.0, 0.0]) == [0.0, 1.0, 0.0]
                    and abs(c["vfov"] - 53.13) < 0.01)
    vs = [[float(x) for x in l.split()[1:4]] for l in open(obj) if l.startswith("v ")]
    diag = sum((max(v[i] for v in vs) - min(v[i] for v in vs)) ** 2 for i in range(3)) ** 0.5
    for k, v in [("DIAG", f"{diag:.6g}"), ("KIND", kind), ("W", w), ("H", h), ("OBJ", obj), ("SPHERES", sph),
                 ("LIGHTS", lights if os.path.exists(lights) else ""), ("GLOSSY", glossy),
                 ("WORKSHEET", worksheet), ("TF", m.get("tf", "transmitted"))]:
        print(f"{k}={shlex.quote(str(v))}")


if __name__ == "__main__":
    if sys.argv[2] == "auto":
        auto(sys.argv[1], *sys.argv[3:])
    else:
        convert(*sys.argv[1:])
