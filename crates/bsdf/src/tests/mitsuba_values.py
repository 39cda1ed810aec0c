"""Reference values of the GGX models from Mitsuba 3, for crates/bsdf/src/tests/microfacet.rs.

Needs Python with Mitsuba 3 (3.9.1 was used; e.g. the peers' virtual environment). Run from the
repository root:

    python crates/bsdf/src/tests/mitsuba_values.py > crates/bsdf/src/tests/mitsuba_values.csv

Mitsuba's `si.wi` is photonflow's `wo` and Mitsuba's `wo` is photonflow's `wi`; Mitsuba's
`eval` includes `|cos|` of its `wo`, which is divided out here, so the `f` columns are
photonflow's `f`. Models (scalar_rgb, GGX, visible-normal sampling, ext_ior 1):
  rc_none   roughconductor, material none, specular_reflectance (0.9, 0.6, 0.3)
  rc_gold   roughconductor, eta (0.143, 0.374, 1.442), k (3.983, 2.385, 1.603)
  rd        roughdielectric, int_ior 1.5, ext_ior 1.0, Radiance and Importance modes
  glossy    diffuse Kd (0.5, 0.3, 0.1) + roughconductor (material none) Ks (0.2, 0.3, 0.1):
            f = sum of the two evals; pdf = pd diffuse + (1 - pd) GGX, pd = mean Kd / (mean Kd
            + mean Ks), the MTL illum 2 mapping photonflow's `Glossy` implements
"""
import math
import sys

import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")

ALPHAS = [0.05, 0.3, 0.8]
KD, KS = [0.5, 0.3, 0.1], [0.2, 0.3, 0.1]
GOLD_ETA, GOLD_K = [0.143, 0.374, 1.442], [3.983, 2.385, 1.603]
RC_NONE_R = [0.9, 0.6, 0.3]


def rgb(v):
    return {"type": "rgb", "value": v}


def rough_conductor(alpha, **kw):
    return mi.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha": alpha, **kw})


def models(alpha):
    diffuse = mi.load_dict({"type": "diffuse", "reflectance": rgb(KD)})
    spec = rough_conductor(alpha, material="none", specular_reflectance=rgb(KS))
    pd = (sum(KD) / 3) / (sum(KD) / 3 + sum(KS) / 3)
    return {
        "rc_none": rough_conductor(alpha, material="none", specular_reflectance=rgb(RC_NONE_R)),
        "rc_gold": rough_conductor(alpha, eta=rgb(GOLD_ETA), k=rgb(GOLD_K)),
        "rd": mi.load_dict({"type": "roughdielectric", "distribution": "ggx", "alpha": alpha,
                            "int_ior": 1.5, "ext_ior": 1.0}),
        "glossy": (diffuse, spec, pd),
    }


def unit(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def tilt(w, angle, rng):
    """w turned by `angle` radians about a random axis perpendicular to it."""
    a = np.cross(w, rng.normal(size=3))
    a /= np.linalg.norm(a)
    return w * math.cos(angle) + np.cross(a, w) * math.sin(angle)


def refract(wo, eta):
    """Refraction of wo about +-z (eta = n_inside / n_outside), or None on total reflection."""
    n = np.array([0.0, 0.0, 1.0])
    c = wo[2]
    if c < 0:
        eta, c, n = 1 / eta, -c, -n
    s2 = (1 - c * c) / eta**2
    if s2 >= 1:
        return None
    return -wo / eta + (c / eta - math.sqrt(1 - s2)) * n


def f32(w):
    return np.asarray(w, dtype=np.float32)


def reflection_pairs(alpha, rng):
    """30 pairs, wo above: near-specular (within ~alpha), random, grazing, and wi below."""
    pairs = []
    thetas = [0.0, 20.0, 45.0, 70.0, 85.0]
    for k, th in enumerate(thetas):
        wo = unit(th, 33.0 * k)
        mirror = np.array([-wo[0], -wo[1], wo[2]])
        for s in [0.0, 0.5, 1.2]:
            wi = tilt(mirror, s * alpha, rng)
            if wi[2] <= 0:
                wi[2] = -wi[2]
            pairs.append((wo, wi))
    while len(pairs) < 28:
        wo = unit(rng.uniform(0, 88), rng.uniform(0, 360))
        wi = unit(rng.uniform(0, 88), rng.uniform(0, 360))
        pairs.append((wo, wi))
    pairs.append((unit(40, 10), unit(120, 200)))  # wi below: nothing
    pairs.append((unit(89, 0), unit(89, 180)))  # both grazing, mirror pair
    return [(f32(a), f32(b)) for a, b in pairs]


def dielectric_pairs(alpha, rng):
    """30 pairs, wo on both sides: near-reflection, near-refraction, random, beyond critical."""
    pairs = []
    for k, th in enumerate([10.0, 50.0, 80.0, 170.0, 140.0, 125.0]):
        wo = unit(th, 47.0 * k)
        mirror = np.array([-wo[0], -wo[1], wo[2]])
        pairs.append((wo, tilt(mirror, 0.5 * alpha, rng)))
        t = refract(wo, 1.5)
        if t is not None:
            pairs.append((wo, tilt(t, 0.0, rng)))
            pairs.append((wo, tilt(t, 0.7 * alpha, rng)))
    while len(pairs) < 30:
        wo = unit(rng.uniform(0, 180), rng.uniform(0, 360))
        wi = unit(rng.uniform(0, 180), rng.uniform(0, 360))
        pairs.append((wo, wi))
    out = []
    for a, b in pairs:
        # A tilt can land wi on the horizon, where f has no meaningful value.
        if abs(b[2]) < 1e-3:
            continue
        out.append((f32(a), f32(b / np.linalg.norm(b))))
    return out


def mitsuba_eval(bsdf, wo, wi, mode):
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(*[float(x) for x in wo])
    ctx = mi.BSDFContext(mode)
    w = mi.Vector3f(*[float(x) for x in wi])
    v = bsdf.eval(ctx, si, w)
    p = bsdf.pdf(ctx, si, w)
    return np.array([v[0], v[1], v[2]], dtype=np.float64), float(p)


def main():
    rng = np.random.default_rng(20240607)
    print("# generated by: python crates/bsdf/src/tests/mitsuba_values.py "
          "> crates/bsdf/src/tests/mitsuba_values.csv (Mitsuba %s, scalar_rgb)" % mi.__version__)
    print("model,alpha,mode,wo_x,wo_y,wo_z,wi_x,wi_y,wi_z,f_r,f_g,f_b,pdf")
    rad, imp = mi.TransportMode.Radiance, mi.TransportMode.Importance
    for alpha in ALPHAS:
        ms = models(alpha)
        refl = reflection_pairs(alpha, rng)
        diel = dielectric_pairs(alpha, rng)
        for name in ["rc_none", "rc_gold", "glossy", "rd"]:
            pairs = diel if name == "rd" else refl
            modes = [rad, imp] if name == "rd" else [rad]
            for mode in modes:
                for wo, wi in pairs:
                    if name == "glossy":
                        d, s, pd = ms[name]
                        fd, pdf_d = mitsuba_eval(d, wo, wi, mode)
                        fs, pdf_s = mitsuba_eval(s, wo, wi, mode)
                        f, pdf = fd + fs, pd * pdf_d + (1 - pd) * pdf_s
                    else:
                        f, pdf = mitsuba_eval(ms[name], wo, wi, mode)
                    # Mitsuba's eval carries |cos| of its wo (photonflow's wi).
                    f = f / abs(float(wi[2]))
                    m = "radiance" if mode == rad else "importance"
                    nums = [*wo, *wi]
                    print(f"{name},{alpha},{m}," + ",".join("%.9g" % x for x in nums) + ","
                          + ",".join("%.7g" % x for x in [*f, pdf]))


if __name__ == "__main__":
    sys.exit(main())
