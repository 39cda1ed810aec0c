"""Render a Mitsuba 3 XML scene as photonflow's reference halves read it: the file itself,
loaded by Mitsuba with its `$width`, `$height` and `$spp` parameters set, rendered in passes
of independent seeds (pass k draws seed `seed * 1000003 + k`, as mitsuba_render_rough.py
does), averaged, written as linear float32 RGB EXR (ZIP).

    python mitsuba_xml.py PEERS SCENE.xml --width W --height H --spp N --spp-per-pass P
        --seed S [--variant llvm_ad_rgb] [-D name=value ...] -o OUT.exr
"""
import argparse
import sys
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("peers")
    ap.add_argument("scene")
    ap.add_argument("--width", type=int, required=True)
    ap.add_argument("--height", type=int, required=True)
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--spp-per-pass", type=int, required=True)
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("-D", action="append", default=[], dest="defines")
    ap.add_argument("-o", required=True)
    a = ap.parse_args()
    sys.path.insert(0, a.peers)
    import mitsuba as mi
    import numpy as np
    from exrio import write_exr

    mi.set_variant(a.variant)
    params = dict(d.split("=", 1) for d in a.defines)
    params.update(width=str(a.width), height=str(a.height), spp=str(a.spp_per_pass))
    scene = mi.load_file(a.scene, **params)
    passes = a.spp // a.spp_per_pass
    assert passes * a.spp_per_pass == a.spp, "spp must be a multiple of spp-per-pass"
    acc = np.zeros((a.height, a.width, 3))
    t0 = time.time()
    for k in range(passes):
        img = mi.render(scene, seed=a.seed * 1000003 + k, spp=a.spp_per_pass)
        acc += np.asarray(img, dtype=np.float64)[..., :3]
        print(f"  pass {k + 1}/{passes} ({time.time() - t0:.0f} s)", flush=True)
    write_exr(a.o, acc / passes)


if __name__ == "__main__":
    main()
