#!/usr/bin/env bash
# The path tracer's profile per bounce: instructions per sample by category, counted by
# callgrind (deterministic whatever the machine's load), as docs/benchmarks.md records it
# under "profile, path tracer per bounce".
#
#   xtask/profile.sh [SCENE ...]      (default: the worksheet and McGuire's Original box)
#
# Each scene is copied with its camera at SIZE x SIZE pixels (mesh paths made absolute) and
# `[render] max_depth` set to each of DEPTHS (`rr_depth` as the scene has it, 5 by default, so
# the depths below it are the bounces themselves and the last one is every bounce roulette
# lets through). Each copy is rendered with `--method path --threads 1` under callgrind at
# LO and at HI samples per pixel; the difference divided by (HI - LO) x pixels is what one
# more sample costs, with the scene load, BVH build and output writing cancelled out. The
# path method renders in passes of at most an eighth of the run, so 8 samples per pixel are
# 8 passes and 16 are 9: the difference holds one pass's per-pixel film work per 8 samples,
# near what a 64-spp run pays (11 passes). Consecutive depths differ by what one more bounce
# costs a camera sample (averaged over all of them, ended paths included).
#
# Costs go to categories by the source file of each instruction (callgrind attributes
# inlined code to the file it was inlined from, given line tables: the `profiling` profile),
# and, for library code inlined into ours (glam, core), by the enclosing function's name.
#
# Environment: SIZE (128), LO (8), HI (16), DEPTHS ("0 1 2 3 4 5 64"), OUT (out/profile),
# PERF=1 adds a `perf record` at the scene's own size and full depth on 2 threads, PERF_SPP
# (32) samples per pixel (cycle shares), PERF=report reads the last record again; CALLGRIND=0
# categorises the callgrind files of an earlier run again.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
SIZE=${SIZE:-128}
LO=${LO:-8}
HI=${HI:-16}
DEPTHS=${DEPTHS:-"0 1 2 3 4 5 64"}
OUT=${OUT:-out/profile}
PERF=${PERF:-0}
CALLGRIND=${CALLGRIND:-1}
if [ $# -eq 0 ]; then
    set -- scenes/cornell-spheres/analytic.toml scenes/mcguire/original.toml
fi

cargo build --quiet --profile profiling --package photonflow
exe="${CARGO_TARGET_DIR:-$root/target}/profiling/photonflow"

# The categories, first match wins, on callgrind_annotate's `file:function` lines.
# Our own files name the category; inlined library code (glam, core, alloc) goes by the
# function it was inlined into, which is the name after the colon.
categorise() {
    awk '
    function cat(loc,   f, fn_) {
        f = loc; fn_ = loc
        sub(/:.*/, "", f); sub(/^[^:]*:/, "", fn_)
        if (f ~ /miniz_oxide|fdeflate|\/exr-|\/png-|\/image-|crates\/film\/src\/(io|img)\.rs/) return "output"
        if (f ~ /crates\/geom\//)                                   return "rays"
        if (f ~ /obvhs/)                                            return "rays"
        if (f ~ /crates\/bsdf\//)                                   return "bsdf"
        if (f ~ /crates\/scene\/src\/world\.rs/)                    return "bsdf"
        if (f ~ /crates\/scene\/src\/(lights|texture)/)             return "lights"
        if (f ~ /crates\/math\/src\/sampler\.rs/)                   return "sampler"
        if (f ~ /crates\/math\/src\/rng\.rs/)                       return "sampler"
        if (f ~ /crates\/math\/src\/warp\.rs/ && fn_ ~ /power_heuristic/) return "mis"
        if (f ~ /crates\/math\/src\/warp\.rs/)                      return "warps"
        if (f ~ /crates\/math\/src\/frame\.rs/)                     return "frame"
        if (f ~ /crates\/scene\/src\/camera/)                       return "camera"
        if (f ~ /crates\/film\//)                                   return "film"
        if (f ~ /crates\/eye\/src\/render\.rs/)                     return "film"
        if (f ~ /crates\/eye\/src\/path\.rs/)                       return "integrator"
        if (fn_ ~ /malloc|free|realloc|calloc|memalign|__rust_alloc|__rust_dealloc|__rdl_/) return "alloc"
        if (fn_ ~ /memcpy|memmove|memset/)                          return "memcpy"
        # libm: sincosf (directions sampled), atan2 and acos (a sphere hit'"'"'s uv), pow.
        if (f ~ /^\.\/math\// || fn_ ~ /^(__)?(sincosf|ieee754|atan2|acos|pow)/) return "libm"
        if (fn_ ~ /geom::|obvhs::/)                                 return "rays"
        if (fn_ ~ /bsdf::/)                                         return "bsdf"
        if (fn_ ~ /lights::|LightTable/)                            return "lights"
        if (fn_ ~ /Sobol|sampler|Rng/)                              return "sampler"
        if (fn_ ~ /power_heuristic/)                                return "mis"
        if (fn_ ~ /warp::/)                                         return "warps"
        if (fn_ ~ /camera/)                                         return "camera"
        if (fn_ ~ /film::|render_tile|TileBuffer/)                  return "film"
        # Library code (glam, core) inlined into the path loop (`PathTracer::li`) or the
        # sample loop around it, whose own calls (BSDFs, lights, camera) are inlined there
        # too: not attributable by file.
        if (fn_ ~ /PathTracer::li|eye::render::/)                   return "inlined-math"
        if (fn_ ~ /PathTracer|eye::path/)                           return "integrator"
        return "other"
    }
    # Lines: "  1,234,567 (1.25%)  file:function" (callgrind_annotate --inclusive=no --auto=no).
    /PROGRAM TOTALS/ { next }
    /^ *[0-9][0-9,]* +[^ ]/ {
        n = $1; gsub(/,/, "", n)
        loc = $0; sub(/^ *[0-9,]+ +(\([ 0-9.]+%\) +)?/, "", loc); sub(/ \[[^]]*\]$/, "", loc)
        sum[cat(loc)] += n
    }
    END { for (c in sum) printf "%s %d\n", c, sum[c] }'
}

CATS="rays bsdf lights mis sampler warps frame camera integrator inlined-math film alloc memcpy libm output other"

# scene_copy SRC DST DEPTH: SRC at SIZE x SIZE, absolute mesh paths, max_depth DEPTH.
scene_copy() {
    local src=$1 dst=$2 depth=$3 dir
    dir=$(cd "$(dirname "$src")" && pwd)
    awk -v dir="$dir" -v size="$SIZE" -v depth="$depth" '
        /^\[/ { in_render = ($0 == "[render]"); in_camera = ($0 == "[camera]") }
        in_camera && /^width *=/  { print "width = " size; next }
        in_camera && /^height *=/ { print "height = " size; next }
        in_render && /^max_depth *=/ { next }
        /^(obj|ply|mtl) *= *"[^\/]/ { sub(/"/, "\"" dir "/") }
        { print }
        $0 == "[render]" { print "max_depth = " depth; seen = 1 }
        END { if (!seen) printf "\n[render]\nmax_depth = %d\n", depth }
    ' "$src" >"$dst"
}

for scene in "$@"; do
    stem=$(basename "$(dirname "$scene")")-$(basename "$scene" .toml)
    work="$OUT/$stem"
    mkdir -p "$work"
    echo "## $scene ($SIZE x $SIZE, spp $LO and $HI, depths $DEPTHS)"
    for d in $DEPTHS; do
        scene_copy "$scene" "$work/d$d.toml" "$d"
        for spp in "$LO" "$HI"; do
            cg="$work/callgrind.d$d.s$spp.out"
            if [ "$CALLGRIND" = 1 ]; then
                valgrind --tool=callgrind --callgrind-out-file="$cg" \
                    "$exe" render "$work/d$d.toml" --method path --spp "$spp" --threads 1 \
                    --out "$work/run-d$d-s$spp" >/dev/null 2>"$work/valgrind.d$d.s$spp.log"
            fi
            callgrind_annotate --inclusive=no --auto=no --threshold=100 "$cg" 2>/dev/null |
                categorise >"$work/cats.d$d.s$spp.txt"
            # MIS is `power_heuristic`, inlined wherever it is called: its lines' counts,
            # moved from warps (the rest of its file) to mis.
            callgrind_annotate --auto=yes --threshold=100 "$cg" 2>/dev/null | awk '
                /^-- Auto-annotated source:/ { on = ($0 ~ /crates\/math\/src\/warp\.rs/) }
                on && /fn power_heuristic/ { body = 1 }
                body {
                    n = $1; src = $0
                    sub(/^ *([0-9,]+ +\([ 0-9.]+%\)|\.) ?/, "", src)
                    if (src ~ /^ *$/) { body = 0; next }
                    if (n ~ /^[0-9,]+$/) { gsub(/,/, "", n); mis += n }
                }
                END { printf "mis %d\nwarps %d\n", mis, -mis }' >>"$work/cats.d$d.s$spp.txt"
        done
    done
    # Per sample at each depth: (HI - LO) / ((HI - LO) x pixels), then per bounce.
    awk -v cats="$CATS" -v depths="$DEPTHS" -v lo="$LO" -v hi="$HI" -v px=$((SIZE * SIZE)) \
        -v work="$work" '
    BEGIN {
        nc = split(cats, C, " "); nd = split(depths, D, " ")
        for (i = 1; i <= nd; i++) {
            for (s = 0; s < 2; s++) {
                spp = s ? hi : lo
                f = work "/cats.d" D[i] ".s" spp ".txt"
                while ((getline line < f) > 0) {
                    split(line, a, " "); v[i, s, a[1]] += a[2]
                }
                close(f)
            }
            tot[i] = 0
            for (c = 1; c <= nc; c++) {
                ps[i, C[c]] = (v[i, 1, C[c]] - v[i, 0, C[c]]) / ((hi - lo) * px)
                tot[i] += ps[i, C[c]]
            }
        }
        printf "\ninstructions per sample at max_depth d (cumulative)\n\n| category |"
        for (i = 1; i <= nd; i++) printf " d=%s |", D[i]
        printf " share at d=%s |\n|---|", D[nd]
        for (i = 1; i <= nd + 1; i++) printf "---:|"
        printf "\n"
        for (c = 1; c <= nc; c++) {
            printf "| %s |", C[c]
            for (i = 1; i <= nd; i++) printf " %.0f |", ps[i, C[c]]
            printf " %.1f%% |\n", 100 * ps[nd, C[c]] / tot[nd]
        }
        printf "| **total** |"
        for (i = 1; i <= nd; i++) printf " **%.0f** |", tot[i]
        printf " 100%% |\n"

        printf "\ninstructions per sample added by each bounce (d minus the depth before)\n\n| category | camera + first hit (d=%s) |", D[1]
        for (i = 2; i <= nd; i++) printf " %s..%s |", D[i - 1], D[i]
        printf "\n|---|"
        for (i = 1; i <= nd; i++) printf "---:|"
        printf "\n"
        for (c = 1; c <= nc; c++) {
            printf "| %s | %.0f |", C[c], ps[1, C[c]]
            for (i = 2; i <= nd; i++) printf " %.0f |", ps[i, C[c]] - ps[i - 1, C[c]]
            printf "\n"
        }
        printf "| **total** | **%.0f** |", tot[1]
        for (i = 2; i <= nd; i++) printf " **%.0f** |", tot[i] - tot[i - 1]
        printf "\n"
    }'
    if [ "$PERF" != 0 ]; then
        # Cycle shares of the whole run at the scene's own size and depth on 2 threads, with
        # `perf record` (user space), by the same categories: `perf report` names each
        # sample's innermost source file (inlined code included) and enclosing symbol.
        full="$work/full.toml"
        scene_copy "$scene" "$full" "${DEPTHS##* }"
        awk -v w="$(grep -m1 '^width' "$scene" | tr -dc 0-9)" \
            -v h="$(grep -m1 '^height' "$scene" | tr -dc 0-9)" '
            /^width *=/ { $0 = "width = " w } /^height *=/ { $0 = "height = " h } { print }
        ' "$full" >"$full.tmp" && mv "$full.tmp" "$full"
        [ -f "$work/perf.data" ] && [ "$PERF" = report ] ||
            perf record -q -e cycles:u -F 2000 -o "$work/perf.data" \
            "$exe" render "$full" --method path --spp "${PERF_SPP:-32}" --threads 2 \
            --out "$work/run-perf" >/dev/null 2>&1
        perf report -i "$work/perf.data" --no-children --sort srcfile,sym --full-source-path \
            --stdio -q 2>/dev/null |
            awk '/%/ { p = $1; sub(/%/, "", p); s = $0; sub(/.*\[\.\] /, "", s)
                       printf "%d %s:%s\n", p * 10000, $2, s }' |
            categorise >"$work/perf.cats.txt"
        awk -v cats="$CATS" -v d="${DEPTHS##* }" -v f1="$work/perf.cats.txt" \
            -v f2="$work/cats.d${DEPTHS##* }.s$HI.txt" -v f3="$work/cats.d${DEPTHS##* }.s$LO.txt" '
        BEGIN {
            nc = split(cats, C, " ")
            while ((getline l < f1) > 0) { split(l, a, " "); cy[a[1]] = a[2] }
            while ((getline l < f2) > 0) { split(l, a, " "); hi[a[1]] += a[2] }
            while ((getline l < f3) > 0) { split(l, a, " "); lo[a[1]] += a[2] }
            for (c = 1; c <= nc; c++) {
                k = C[c]; ir[k] = hi[k] - lo[k]
                if (k != "other" && k != "output") { tc += cy[k]; ti += ir[k] }
            }
            printf "\ncycles (perf, whole run, 2 threads) against instructions (callgrind, per sample) at max_depth %s, shares of the categories but output and other\n\n", d
            printf "| category | cycles share | instructions share | cycles / instructions, relative |\n|---|---:|---:|---:|\n"
            for (c = 1; c <= nc; c++) {
                k = C[c]; if (k == "other" || k == "output") continue
                r = ir[k] > 0 && ti > 0 ? (cy[k] / tc) / (ir[k] / ti) : 0
                printf "| %s | %.1f%% | %.1f%% | %.2f |\n", k, 100 * cy[k] / tc, 100 * ir[k] / ti, r
            }
            printf "\n(output and other, the image written and the scene loaded: %.1f%% of the run'"'"'s cycles)\n", 100 * (cy["other"] + cy["output"]) / (tc + cy["other"] + cy["output"])
        }'
    fi
    echo
done
