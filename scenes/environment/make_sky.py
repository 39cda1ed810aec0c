"""Write sky.exr, the lat-long environment map of env-only.toml (run: python make_sky.py, with
numpy and the OpenEXR module >= 3.3; the committed sky.exr is its output).

128 x 64 texels, linear RGB float32, ZIP. Mitsuba 3's `envmap` conventions: a local direction
(sin t sin p, cos t, -sin t cos p) (y up) is at u = p / 2pi, v = t / pi; texel column i is
centred at u = (i + 0.5) / 128, row j at v = j / 63 (rows 0 and 63 on the poles), radiance
bilinear between texels, wrapping in u. Each texel is the functions below at its own direction:

  sky (above the horizon)  zenith (0.10, 0.20, 0.45) to horizon (0.55, 0.60, 0.70), smooth in
                           elevation
  ground (below)           (0.08, 0.07, 0.06), blended with the sky over 3 degrees about the
                           horizon
  sun                      (40, 38, 34) within 4 degrees of (local) elevation 45 degrees at
                           u = 0.25 (local direction +x tilted up), falling smoothly to 0 at
                           7 degrees: about 10 degrees across, 2 to 3 texels
"""
import os

import numpy as np
import OpenEXR

W, H = 128, 64
u = (np.arange(W) + 0.5) / W
v = np.arange(H) / (H - 1)
p, t = np.meshgrid(2 * np.pi * u, np.pi * v)
d = np.stack([np.sin(t) * np.sin(p), np.cos(t), -np.sin(t) * np.cos(p)], axis=-1)
elev = np.degrees(np.arcsin(np.clip(d[..., 1], -1, 1)))


def smoothstep(e0, e1, x):
    s = np.clip((x - e0) / (e1 - e0), 0, 1)
    return s * s * (3 - 2 * s)


up = np.clip(d[..., 1], 0, 1)[..., None]
sky = np.array([0.55, 0.60, 0.70]) + (np.array([0.10, 0.20, 0.45]) - np.array([0.55, 0.60, 0.70])) * np.sqrt(up)
ground = np.array([0.08, 0.07, 0.06])
img = ground + (sky - ground) * smoothstep(-1.5, 1.5, elev)[..., None]
sun_dir = np.array([np.cos(np.radians(45)), np.sin(np.radians(45)), 0.0])
ang = np.degrees(np.arccos(np.clip(d @ sun_dir, -1, 1)))
img = img + np.array([40.0, 38.0, 34.0]) * smoothstep(7.0, 4.0, ang)[..., None]

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sky.exr")
header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
with OpenEXR.File(header, {"RGB": np.ascontiguousarray(img, dtype=np.float32)}) as f:
    f.write(out)
print(f"wrote {out}: {W} x {H}, max {img.max():.2f}, mean {img.mean():.4f}")
