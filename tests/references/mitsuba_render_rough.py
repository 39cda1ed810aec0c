"""The peers' mitsuba_render.py with two more MTL codes for analytic spheres, so that scene
files with GGX spheres translate one to one (make.sh writes these MTL lines itself):

  illum 13, Ks, Ns = alpha  -> roughconductor (ggx, material none, specular_reflectance Ks)
  illum 14, Ni, Ns = alpha  -> roughdielectric (ggx, int_ior Ni, ext_ior 1)

Everything else is the peers' script: run as `python mitsuba_render_rough.py PEERS ARGS...`
with PEERS the peers' directory and ARGS mitsuba_render.py's own."""
import sys

peers = sys.argv.pop(1)
sys.path.insert(0, peers)
import mitsuba_render  # noqa: E402
import objmtl  # noqa: E402

classify, bsdf_dict = objmtl.classify, mitsuba_render.bsdf_dict


def rough_classify(mat, glossy=False):
    illum = int(mat.get("illum", 1))
    if illum == 13:
        return "roughconductor", {"reflectance": tuple(mat["Ks"]), "alpha": float(mat["Ns"])}
    if illum == 14:
        return "roughdielectric", {"ior": float(mat["Ni"]), "alpha": float(mat["Ns"])}
    return classify(mat, glossy)


def rough_bsdf_dict(kind, p):
    if kind == "roughconductor":
        return {"type": "roughconductor", "distribution": "ggx", "alpha": p["alpha"],
                "material": "none", "specular_reflectance": mitsuba_render.rgb(p["reflectance"])}
    if kind == "roughdielectric":
        return {"type": "roughdielectric", "distribution": "ggx", "alpha": p["alpha"],
                "int_ior": p["ior"], "ext_ior": 1.0}
    return bsdf_dict(kind, p)


objmtl.classify = rough_classify
mitsuba_render.bsdf_dict = rough_bsdf_dict
mitsuba_render.main()
