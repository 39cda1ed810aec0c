#!/usr/bin/env bash
# Mitsuba 3 reference images for photonflow's tests: every scene rendered twice, halves `a` and
# `b` with independent seeds, as linear RGB float32 EXR (ZIP). README.md says what each file is.
#
#   PEERS=/path/to/peers PEERS_VENV=/path/to/venv tests/references/make.sh [NAME...]
#   PEERS=/path/to/peers PEERS_VENV=/path/to/venv tests/references/make.sh stats
#
# PEERS       the peers directory: mitsuba_render.py, objmtl.py, exrio.py, worksheet/
# PEERS_VENV  the virtual environment the peers' setup.sh made (Mitsuba 3.9.1, drjit 1.5.0,
#             OpenEXR, numpy); or PEERS_PYTHON=its python
# VARIANT     Mitsuba variant, default llvm_ad_rgb (needs libLLVM >= 16); scalar_rgb is slower
#             and draws different random numbers, so its images differ within noise
# NAME        cornell-spheres-analytic, cornell-spheres-closeup, cornell-glossy, cornell-rough,
#             cornell-textured, cornell-coloured-glass, furnace, plane-light, corner,
#             point-caustic, cornell-spot, environment, mcguire-original, mcguire-sphere,
#             mcguire-mirror, mcguire-water, mcguire-glossy, mitsuba-worksheet,
#             mitsuba-shapes-and-lights, mitsuba-materials (default: all)
# SPP_POINT, SPP_SPOT, SPP_ENV  spp per half of point-caustic, cornell-spot, environment
#             (default 24576, 8192, 24576)
# SPP_MCGUIRE spp per half of mcguire-sphere, -mirror, -water and -glossy (default 8192)
# BENCH=1     the benchmark references instead of the test ones, for the NAMEs that have
#             them: mcguire-original at 256 x 256 (8192 spp per half) and
#             cornell-spheres-analytic at 512 x 512 (4096 spp per half); needs OUTDIR (they
#             are not committed)
# SPP_WS_BENCH  spp per half of the worksheet's benchmark halves (default 4096)
# HALVES      which halves to render (default "a b"; e.g. HALVES=b to finish an interrupted run)
# OUTDIR      where the images go and `stats` reads them (default: this directory)
# `stats` prints the noise figures of the halves present (the tables of README.md).
#
# The scenes are read from scenes/*.toml of this repository (camera, and checks that the
# Mitsuba description still matches), except the worksheet scene's geometry: its box OBJ keeps
# the emission in Ka, which the peers' OBJ reader does not read, so the peers' copy
# (worksheet/cornell_worksheet_box.obj, Ke, already in scene units, same triangles) is used.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
: "${PEERS:?set PEERS=/path/to/peers (the directory with mitsuba_render.py)}"
if [ -z "${PEERS_PYTHON:-}" ]; then
  : "${PEERS_VENV:?set PEERS_VENV=/path/to/venv (or PEERS_PYTHON=/path/to/python)}"
  PEERS_PYTHON=$PEERS_VENV/bin/python
fi
PY=$PEERS_PYTHON
VARIANT=${VARIANT:-llvm_ad_rgb}
SEED_A=1
SEED_B=2
BENCH=${BENCH:-0}
if [ "$BENCH" = 1 ]; then
  : "${OUTDIR:?BENCH=1 needs OUTDIR=/path/outside/the/repository}"
fi
OUT=${OUTDIR:-$HERE}
mkdir -p "$OUT"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# Camera JSON (mitsuba_render.py's format) from a scene file's [camera], at W x H, after
# checking the scene is still what the Mitsuba description assumes (KIND: obj | worksheet |
# obj-spheres). obj-spheres also writes the scene's spheres as the peers' spheres JSON
# (OUT-spheres.json) with their materials in an MTL beside it: `metal` as a constant-Ks mirror
# (illum 3), `dielectric` as glass (illum 7, Ni), `rough_conductor` and `rough_dielectric` as
# the codes 13 and 14 that mitsuba_render_rough.py adds to the peers' mapping.
camera() { # KIND SCENE.toml W H OUT.json
  "$PY" "$HERE/peer_scene.py" "$PEERS" "$@"
}

# Two halves of one scene. render NAME KIND SCENE.toml W H SPP SPP_PER_PASS OBJ [ARGS...]
# INTEGRATOR=ptracer before the call picks Mitsuba's particle (light) tracer (default path);
# the scene file's [[light]] tables go to the wrapper as --lights (camera() writes them).
render() {
  local name=$1 kind=$2 toml=$3 w=$4 h=$5 spp=$6 pp=$7 obj=$8
  shift 8
  camera "$kind" "$toml" "$w" "$h" "$TMP/$name-${w}x$h.json"
  local half seed lights=() integrator=${INTEGRATOR:-path} tf
  [ ! -e "$TMP/$name-${w}x$h-lights.json" ] || lights=(--lights "$TMP/$name-${w}x$h-lights.json")
  # How the MTL's `Tf` is read on glass: the scene file's `[[mesh]] tf` (peer_scene.py checks
  # there is one mesh), given to the wrapper as photonflow reads it.
  tf=$("$PY" -c 'import sys, tomllib; print(tomllib.load(open(sys.argv[1], "rb"))["mesh"][0].get("tf", "transmitted"))' "$toml")
  for half in ${HALVES:-a b}; do
    if [ $half = a ]; then seed=$SEED_A; else seed=$SEED_B; fi
    echo "== $name ${w}x$h half $half: seed $seed, $spp spp, $integrator"
    "$PY" "$HERE/mitsuba_render_rough.py" "$PEERS" "$obj" "$@" ${lights[@]+"${lights[@]}"} --tf "$tf" \
      --camera "$TMP/$name-${w}x$h.json" \
      --width "$w" --height "$h" --spp "$spp" --spp-per-pass "$pp" --seed "$seed" \
      --integrator "$integrator" --max-depth -1 --rr-depth 5 --sampler independent --rfilter box \
      --variant "$VARIANT" -o "$OUT/$name-${w}x$h-$half.exr"
  done
}

stats() {
  "$PY" - "$PEERS" "$OUT" <<'EOF'
import glob, os, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import exrio
lum = lambda x: 0.2126 * x[..., 0] + 0.7152 * x[..., 1] + 0.0722 * x[..., 2]
print("| file | mean lum a | mean lum b | (a-b)/mean | z = (a-b)/SE(a-b) | whole-image rel SE, half / both "
      "| 16x16 region-mean rel SE of a half: median / p90 / max | per-pixel rel SE of a half, median over regions |")
print("|---|---|---|---|---|---|---|---|")
for fa in sorted(glob.glob(os.path.join(sys.argv[2], "*-a.exr"))):
    fb = fa[:-6] + "-b.exr"
    if not os.path.exists(fb):
        continue
    A, B = (lum(exrio.read_exr(f).astype(np.float64)) for f in (fa, fb))
    M, D = (A + B) / 2, (A - B) / 2      # E[D^2] = var(M) = var(half) / 2 per pixel
    n = M.size
    var_half = 2 * D * D                   # one-sample estimate of a half's per-pixel variance
    se_half = np.sqrt(var_half.sum()) / n  # SE of a half's whole-image mean
    m = M.mean()
    z = (A.mean() - B.mean()) / (np.sqrt(2) * se_half)
    H, W = M.shape
    r = 16 if H >= 32 else H // 2
    vr = var_half.reshape(H // r, r, W // r, r).sum(axis=(1, 3)) / (r * r) ** 2
    mr = M.reshape(H // r, r, W // r, r).mean(axis=(1, 3))
    lit = mr > 1e-3 * m
    rel_r = np.sqrt(vr[lit]) / mr[lit]
    pix = np.sqrt(var_half.reshape(H // r, r, W // r, r).mean(axis=(1, 3))[lit]) / mr[lit]
    reg = f"{r}x{r}" if r != 16 else ""
    print(f"| {os.path.basename(fa)[:-6]} | {A.mean():.6f} | {B.mean():.6f} | {(A.mean() - B.mean()) / m:+.5%} | {z:+.2f} "
          f"| {se_half / m:.4%} / {se_half / np.sqrt(2) / m:.4%} "
          f"| {np.median(rel_r):.3%} / {np.percentile(rel_r, 90):.3%} / {rel_r.max():.3%}{' (' + reg + ')' if reg else ''} "
          f"| {np.median(pix):.2%} |")
EOF
}

# Two halves of a Mitsuba XML scene of scenes/mitsuba/, rendered from the file itself by
# mitsuba_xml.py (its $width, $height and $spp set). render_xml NAME SCENE.xml W H SPP SPP_PER_PASS
render_xml() {
  local name=$1 xml=$2 w=$3 h=$4 spp=$5 pp=$6 half seed
  for half in ${HALVES:-a b}; do
    if [ $half = a ]; then seed=$SEED_A; else seed=$SEED_B; fi
    echo "== $name ${w}x$h half $half: seed $seed, $spp spp, the XML's integrator"
    "$PY" "$HERE/mitsuba_xml.py" "$PEERS" "$xml" --width "$w" --height "$h" --spp "$spp" \
      --spp-per-pass "$pp" --seed "$seed" --variant "$VARIANT" -o "$OUT/$name-${w}x$h-$half.exr"
  done
}

# spp per half of the light-lit scenes (overridable for quick looks)
SPP_POINT=${SPP_POINT:-24576}
SPP_SPOT=${SPP_SPOT:-8192}
SPP_ENV=${SPP_ENV:-24576}
SPP_MCGUIRE=${SPP_MCGUIRE:-8192}
P=$PEERS/worksheet
S=$REPO/scenes
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(cornell-spheres-analytic cornell-spheres-closeup cornell-glossy cornell-rough cornell-textured cornell-coloured-glass furnace plane-light corner point-caustic cornell-spot environment mcguire-original mcguire-sphere mcguire-mirror mcguire-water mcguire-glossy mitsuba-worksheet mitsuba-shapes-and-lights mitsuba-materials)
if [ "$BENCH" = 1 ]; then
  for n in "${names[@]}"; do
    case $n in
      cornell-spheres-analytic)
        # In passes of 64: a pass holds as many samples as the 128 x 128 ones.
        render $n worksheet "$S/cornell-spheres/analytic.toml" 512 512 "${SPP_WS_BENCH:-4096}" 64 \
          "$P/cornell_worksheet_box.obj" --spheres "$P/cornell_worksheet_spheres.json" ;;
      mcguire-original)
        render $n obj "$S/mcguire/original.toml" 256 256 8192 256 "$S/mcguire/CornellBox-Original.obj" ;;
      stats) stats ;;
      *) echo "no benchmark reference for $n" >&2; exit 2 ;;
    esac
  done
  exit 0
fi
for n in "${names[@]}"; do
  case $n in
    cornell-spheres-analytic)
      render $n worksheet "$S/cornell-spheres/analytic.toml" 128 128 8192 1024 \
        "$P/cornell_worksheet_box.obj" --spheres "$P/cornell_worksheet_spheres.json" ;;
    mcguire-original)
      # McGuire's OBJ and MTL as they are: illum 2 with Ks 0 everywhere (Lambertian Kd), so
      # no --glossy; the light's Ke an area emitter on its Kd.
      render $n obj "$S/mcguire/original.toml" 128 128 8192 1024 "$S/mcguire/CornellBox-Original.obj" ;;
    mcguire-sphere)
      # Mirror ball (illum 5: conductor, Ks), glass ball (illum 4: dielectric, Ni, 1 - Tf by
      # the scene file's tf = "absorbed"), diffuse walls.
      render $n obj "$S/mcguire/sphere.toml" 128 128 $SPP_MCGUIRE 1024 "$S/mcguire/CornellBox-Sphere.obj" ;;
    mcguire-mirror)
      render $n obj "$S/mcguire/mirror.toml" 128 128 $SPP_MCGUIRE 1024 "$S/mcguire/CornellBox-Mirror.obj" ;;
    mcguire-water)
      # The water (illum 7, Ni 1.33) and the glass ball as in mcguire-sphere (tf = "absorbed").
      render $n obj "$S/mcguire/water.toml" 128 128 $SPP_MCGUIRE 1024 "$S/mcguire/CornellBox-Water.obj" ;;
    mcguire-glossy)
      # The glossy sphere and block are illum 2 with Ks > 0: the peers' --glossy mapping.
      render $n obj "$S/mcguire/glossy.toml" 128 128 $SPP_MCGUIRE 1024 "$S/mcguire/CornellBox-Glossy.obj" --glossy ;;
    cornell-glossy)
      # The floor is MTL illum 2: the peers' --glossy mapping (Lambertian Kd + GGX Ks).
      render $n obj-spheres "$S/cornell-glossy/glossy-floor.toml" 128 128 8192 1024 \
        "$S/cornell-glossy/box.obj" --spheres "$TMP/$n-128x128-spheres.json" --glossy ;;
    cornell-rough)
      render $n obj-spheres "$S/cornell-glossy/rough-spheres.toml" 128 128 8192 1024 \
        "$S/cornell-glossy/box.obj" --spheres "$TMP/$n-128x128-spheres.json" --glossy ;;
    cornell-textured)
      # The floor's map_Kd: mitsuba_render_rough.py's bitmap texture over the OBJ's vt.
      render $n obj-spheres "$S/cornell-textured/textured-floor.toml" 128 128 8192 1024 \
        "$S/cornell-textured/box.obj" --spheres "$TMP/$n-128x128-spheres.json" ;;
    cornell-coloured-glass)
      # The worksheet box, its glass sphere coloured by `Tf` (the peers' MTL, edited).
      render $n worksheet "$S/cornell-spheres/coloured-glass.toml" 128 128 8192 1024 \
        "$P/cornell_worksheet_box.obj" --spheres "$TMP/$n-128x128-spheres.json" ;;
    cornell-spheres-closeup)
      render $n worksheet "$S/cornell-spheres/closeup.toml" 128 128 8192 1024 \
        "$P/cornell_worksheet_box.obj" --spheres "$P/cornell_worksheet_spheres.json" ;;
    furnace)
      render $n obj "$S/furnace/furnace.toml" 16 16 16384 16384 "$S/furnace/box.obj"
      render $n obj "$S/furnace/furnace.toml" 32 32 16384 4096 "$S/furnace/box.obj" ;;
    plane-light)
      render $n obj "$S/plane-light/plane-light.toml" 64 64 16384 1024 "$S/plane-light/plane.obj" ;;
    corner)
      render $n obj "$S/corner/corner.toml" 64 64 16384 1024 "$S/corner/corner.obj" ;;
    point-caustic)
      # Lit only by a point light: the light tracer (ptracer) finds its caustic, path cannot.
      INTEGRATOR=ptracer render $n obj-spheres "$S/point-caustic/glass-sphere.toml" 128 128 $SPP_POINT 256 \
        "$S/point-caustic/floor.obj" --spheres "$TMP/$n-128x128-spheres.json" ;;
    cornell-spot)
      INTEGRATOR=ptracer render $n obj-spheres "$S/cornell-spot/spot.toml" 128 128 $SPP_SPOT 256 \
        "$S/cornell-spot/box.obj" --spheres "$TMP/$n-128x128-spheres.json" ;;
    environment)
      render $n obj-spheres "$S/environment/env-only.toml" 128 128 $SPP_ENV 1024 \
        "$S/environment/floor.obj" --spheres "$TMP/$n-128x128-spheres.json" ;;
    mitsuba-worksheet)
      render_xml $n "$S/mitsuba/worksheet.xml" 128 128 4096 1024 ;;
    mitsuba-shapes-and-lights)
      render_xml $n "$S/mitsuba/shapes-and-lights.xml" 128 128 4096 1024 ;;
    mitsuba-materials)
      render_xml $n "$S/mitsuba/materials.xml" 128 128 4096 1024 ;;
    stats) stats ;;
    *) echo "unknown NAME $n" >&2; exit 2 ;;
  esac
done
