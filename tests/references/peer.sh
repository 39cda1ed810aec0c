#!/usr/bin/env bash
# Render a scene file of this repository with a peer renderer in about SECONDS of wall time on
# 2 threads, into a linear RGB EXR: the peers of `bench accuracy` (`--peer NAME`).
#
#   PEERS=/path/to/peers PEERS_VENV=/path/to/venv [BPY_VENV=/path/to/bpy-venv] \
#     tests/references/peer.sh PEER SCENE.toml SECONDS OUT.exr
#
# PEER        mitsuba | mitsuba-ptracer | luxcore | cycles | smallvcm-ppm | smallvcm-bpt |
#             smallvcm-vcm
# PEERS       the peers directory (mitsuba_render.py, luxcore_render.py, cycles_render.py,
#             smallvcm/ built with its build.sh, worksheet/)
# PEERS_VENV  the peers' virtual environment (Mitsuba 3, LuxCore, OpenEXR); or PEERS_PYTHON
# BPY_VENV    cycles only: a Python 3.11 environment with bpy, numpy, OpenEXR
# PEER_CACHE  where Mitsuba's timing calibration is kept (default: peer-cache beside OUT)
# THREADS     default 2
# PEER_SPP    mitsuba, mitsuba-ptracer: render exactly this many spp, SECONDS ignored (no
#             calibration; `bench path` compares at equal spp)
# PEER_SEED   mitsuba, mitsuba-ptracer: the sampler's seed (default 7)
#
# The scene is converted as make.sh converts it (peer_scene.py). The last line on stdout,
# `settings: ...`, says what ran; a peer that cannot render the scene exits with status 3 and
# the reason as its last line on stderr.
#
#   mitsuba       path tracer (llvm_ad_rgb, independent sampler, box filter, no depth limit,
#                 Russian roulette from depth 5). It has no time limit: the spp come from a
#                 calibration (two short untimed renders, 16 and 64 spp, one and four passes of
#                 16, cached per scene file and size) fitting wall = start-up + spp x seconds
#                 per spp, to fill SECONDS. (4 and 32 spp, a pass of 4 against two of 16,
#                 measured the compilation of two kernels more than the passes: on McGuire's
#                 Glossy box at 128 x 128 they predicted under 1 ms per spp where long runs
#                 took 4.5, and runs overshot their budgets fourfold.)
#   mitsuba-ptracer  Mitsuba 3's particle (light) tracer, calibrated the same way: it draws
#                 no specular surface the camera sees (as photonflow's `light`).
#   luxcore      path tracer + PhotonGI caustic cache (100k photons a second of SECONDS, 100k
#                 to 1M; radius 0.2% of the scene's diagonal: 0.05 in the worksheet), its own
#                 time halt, whole seconds: SECONDS + the cache build's (cached per scene, with a
#                 margin: the passes may get up to a second and a quarter of the build more). The
#                 indirect cache is off: LuxCore 2.11 counts caustic light twice with both.
#   cycles       path tracer, passes of 4 spp until SECONDS are used (cycles_render.py --time)
#   smallvcm-*   SmallVCM on its built-in worksheet scene (only that scene, at 512 x 512,
#                 box-averaged down to the scene's size when that divides 512): ppm with merge
#                 radius 0.05, vcm with 0.02, bpt; `-t SECONDS`.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
[ $# -eq 4 ] || { echo "usage: peer.sh PEER SCENE.toml SECONDS OUT.exr" >&2; exit 2; }
peer=$1 scene=$2 secs=$3 out=$4
: "${PEERS:?set PEERS=/path/to/peers}"
if [ -z "${PEERS_PYTHON:-}" ]; then
  : "${PEERS_VENV:?set PEERS_VENV=/path/to/venv (or PEERS_PYTHON=/path/to/python)}"
  PEERS_PYTHON=$PEERS_VENV/bin/python
fi
PY=$PEERS_PYTHON
THREADS=${THREADS:-2}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cannot() { echo "$peer: $*" >&2; exit 3; }

# KIND W H OBJ SPHERES LIGHTS GLOSSY WORKSHEET TF DIAG, and the camera JSON.
eval "$("$PY" "$HERE/peer_scene.py" "$PEERS" auto "$scene" "$TMP/camera.json")"
spheres=()
[ -z "$SPHERES" ] || spheres=(--spheres "$SPHERES")
only_mtl() { # the peers other than Mitsuba map only the MTL's diffuse, mirror, glass, Ke
  [ -z "$LIGHTS" ] || cannot "the scene's [[light]] tables: only mitsuba maps them"
  [ "$GLOSSY" = 0 ] || cannot "glossy MTL materials (illum 2, Ks > 0): only mitsuba maps them"
  [ "$TF" = transmitted ] || cannot "tf = \"$TF\" (the MTL's Tf read as absorbed): only mitsuba reads it so"
}

case $peer in
  mitsuba|mitsuba-ptracer)
    integrator=path
    [ "$peer" = mitsuba ] || integrator=ptracer
    lights=()
    [ -z "$LIGHTS" ] || lights=(--lights "$LIGHTS")
    glossy=()
    [ "$GLOSSY" = 0 ] || glossy=(--glossy)
    mi() { # SPP OUT
      "$PY" "$HERE/mitsuba_render_rough.py" "$PEERS" "$OBJ" ${spheres[@]+"${spheres[@]}"} \
        ${lights[@]+"${lights[@]}"} ${glossy[@]+"${glossy[@]}"} --tf "$TF" --camera "$TMP/camera.json" \
        --width "$W" --height "$H" --spp "$1" --spp-per-pass 16 --seed "${PEER_SEED:-7}" --integrator "$integrator" \
        --max-depth -1 --rr-depth 5 --sampler independent --rfilter box --variant llvm_ad_rgb \
        -o "$2" > /dev/null
    }
    if [ -n "${PEER_SPP:-}" ]; then
      mi "$PEER_SPP" "$out"
      echo "settings: Mitsuba 3 $integrator (llvm_ad_rgb, all cores), $PEER_SPP spp (PEER_SPP), seed ${PEER_SEED:-7}, independent sampler, box filter"
      exit 0
    fi
    cache=${PEER_CACHE:-$(dirname "$out")/peer-cache}
    mkdir -p "$cache"
    key=$(cat "$scene" "$TMP/camera.json" | cksum | cut -d' ' -f1)
    cal=$cache/$peer-cal16-64-$key-${W}x$H.txt
    if [ ! -s "$cal" ]; then
      t() { local t0; t0=$(date +%s.%N); mi "$1" "$TMP/cal.exr"; echo "$(date +%s.%N) $t0" | awk '{ print $1 - $2 }'; }
      t16=$(t 16) t64=$(t 64)
      echo "$t16 $t64" | awk '{b = ($2 - $1) / 48; if (b <= 1e-5) b = 1e-5; a = $1 - 16 * b; if (a < 0) a = 0; print a, b}' > "$cal"
    fi
    read -r a b < "$cal"
    spp=$(awk -v s="$secs" -v a="$a" -v b="$b" 'BEGIN { n = int((s - a) / b); print (n < 1 ? 1 : n) }')
    mi "$spp" "$out"
    echo "settings: Mitsuba 3 $integrator (llvm_ad_rgb, all cores), $spp spp from a cached calibration (start-up $(printf %.2f "$a") s + $(printf %.4f "$b") s/spp), independent sampler, box filter"
    ;;
  luxcore)
    only_mtl
    r=$(awk -v d="$DIAG" 'BEGIN { printf "%.4g", 0.002 * d }')
    photons=$(awk -v s="$secs" 'BEGIN { n = int(100000 * s); print (n > 1000000 ? 1000000 : n < 100000 ? 100000 : n) }')
    # LuxCore's halt time counts from the start, its cache build included: the build's
    # seconds (measured by the last run of this scene, size and photon count, else by a first
    # run that ends in it) go on top of SECONDS.
    cache=${PEER_CACHE:-$(dirname "$out")/peer-cache}
    mkdir -p "$cache"
    build=$cache/luxcore-$(cat "$scene" "$TMP/camera.json" | cksum | cut -d' ' -f1)-$photons.txt
    lux() { # HALT
      "$PY" "$PEERS/luxcore_render.py" "$OBJ" ${spheres[@]+"${spheres[@]}"} --camera "$TMP/camera.json" \
        --width "$W" --height "$H" --time "$1" --threads "$THREADS" --seed 7 --no-indirect \
        --photons "$photons" --caustic-radius "$r" -o "$out" > "$TMP/lux.log"
      sed -n 's/.*PhotonGI cache build) \([0-9.]*\) s.*/\1/p' "$TMP/lux.log" > "$build"
    }
    # The build's time varies with the machine's load: a margin of a quarter and a second.
    halt() { awk -v s="$secs" -v b="$(cat "$build" 2>/dev/null || echo 0)" 'BEGIN { print int(s + 1.25 * b + 1) }'; }
    [ -s "$build" ] || lux 1
    t=$(halt)
    lux "$t"
    spp=$(sed -n 's/.* spp=\([0-9]*\).*/\1/p' "$TMP/lux.log" | tail -1)
    [ "${spp:-0}" -gt 0 ] || cannot "no pass rendered in the halt time of $t s (cache build $(cat "$build") s)"
    echo "settings: LuxCore PATHCPU + PhotonGI caustic cache ($photons photons, radius $r, indirect cache off), halt $t s = $secs s + the cache build ($(cat "$build") s) with a margin, $spp spp, $THREADS threads, box filter"
    ;;
  cycles)
    only_mtl
    : "${BPY_VENV:?set BPY_VENV=/path/to/a Python 3.11 venv with bpy, numpy, OpenEXR}"
    log=$("$BPY_VENV/bin/python" "$PEERS/cycles_render.py" "$OBJ" ${spheres[@]+"${spheres[@]}"} \
      --camera "$TMP/camera.json" --width "$W" --height "$H" --time "$secs" --threads "$THREADS" \
      --seed 7 --quiet -o "$out")
    spp=$(echo "$log" | grep -o 'spp=[0-9]*' | tail -1 || true)
    echo "settings: Blender Cycles path tracer (bpy), passes of 4 spp until $secs s ${spp:+($spp)}, $THREADS threads, no denoiser, no adaptive sampling, box filter"
    ;;
  smallvcm-ppm | smallvcm-bpt | smallvcm-vcm)
    [ "$WORKSHEET" = 1 ] || cannot "SmallVCM knows only the worksheet scene (scenes/cornell-spheres/analytic.toml's view, clear glass)"
    exe=$PEERS/smallvcm/build/smallvcm
    [ -x "$exe" ] || cannot "$exe missing: bash \$PEERS/smallvcm/build.sh"
    alg=${peer#smallvcm-}
    radius=()
    case $alg in ppm) radius=(-R 0.05) ;; vcm) radius=(-R 0.02) ;; esac
    "$exe" -s ws -a "$alg" -t "$secs" -j "$THREADS" ${radius[@]+"${radius[@]}"} -o "$TMP/o.pfm" > /dev/null
    # SmallVCM renders 512 x 512 with a box filter: averaging blocks of pixels is the box
    # filter of a smaller image.
    "$PY" - "$PEERS" "$TMP/o.pfm" "$W" "$H" "$out" <<'EOF'
import sys
sys.path.insert(0, sys.argv[1] + "/smallvcm")
from pfm2exr import exrio, read_pfm
img = read_pfm(sys.argv[2])[..., :3]
w, h = int(sys.argv[3]), int(sys.argv[4])
H, W = img.shape[:2]
if W % w or H % h or W // w != H // h:
    sys.exit(f"smallvcm: the scene's {w}x{h} is not {W}x{H} averaged in square blocks")
f = W // w
exrio.write_exr(sys.argv[5], img.reshape(h, f, w, f, 3).mean(axis=(1, 3)).astype("float32"))
EOF
    echo "settings: SmallVCM $alg${radius[1]:+ (merge radius ${radius[1]})}, -t $secs s, $THREADS threads, 512x512 box-averaged to ${W}x$H"
    ;;
  *) echo "unknown PEER $peer (mitsuba, mitsuba-ptracer, luxcore, cycles, smallvcm-ppm, smallvcm-bpt, smallvcm-vcm)" >&2; exit 2 ;;
esac
