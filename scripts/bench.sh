#!/bin/bash
# make bench: the explicit MPM benchmark (3D soft block spreading under gravity,
# 8 material points per cell, 1.31M points, fixed number of steps, one rank), with
# linear shape functions and then with quadratic B-splines.
# Prints ns per particle-step with a breakdown and the fraction of material points
# that changed cell per step. Then the parallel figures (issue 15) of the 3D block
# and of a 2D column collapse in the corner of a wide box: 1 rank, two concurrent
# 1-rank runs (the memory-bandwidth ceiling of 2 ranks), 2 ranks (and 2 ranks with
# load balancing for the corner scene): speed-up, efficiency against the ceiling,
# full sorts, peak memory per point. Then the implicit family (issue 13): a 2D and a
# 3D scene (time per step and per Newton iteration, assembly ns per point, linear
# solve time), and the quasi-static oedometer solved by talus-explicit (local
# damping) and by talus-implicit (static) to the same accuracy: both wall times.
# Build type must be Release (the Makefile's default).
set -euo pipefail
BUILD=${1:-build}
LOG=$(mktemp)
trap 'rm -f "$LOG"' EXIT
grep -q "CMAKE_BUILD_TYPE:STRING=Release" "$BUILD/CMakeCache.txt" || {
  echo "bench: $BUILD is not a Release build; refusing to benchmark the debug library" >&2; exit 2; }
for PRM in parameter_files/bench/block_spreading_3d.prm parameter_files/bench/block_spreading_3d_bspline.prm; do
echo "bench: $PRM (single rank)"
"$BUILD/tools/talus-explicit" "$PRM" | tee "$LOG"
python3 - "$LOG" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
b = re.search(r"breakdown \[s\]: P2G ([\d.e+-]+), grid ([\d.e+-]+), G2P\+stress ([\d.e+-]+), relocation ([\d.e+-]+) \(moves [\d.e+-]+, sorts [\d.e+-]+\), "
              r"output ([\d.e+-]+); particles moved cell (\d+)", text)
d = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s", text)
steps, n, wall = int(d.group(1)), int(d.group(2)), float(d.group(3))
ps = steps * n
names = ["P2G (mass/force + momentum)", "grid update", "G2P + stress + fused P2G", "relocation (+ sorts)", "output"]
print("\nbench summary: %d material points, %d steps, wall %.1f s" % (n, steps, wall))
for name, v in zip(names, b.groups()[:5]):
    print("  %-30s %7.1f ns/particle-step" % (name, 1e9 * float(v) / ps))
print("  %-30s %7.1f ns/particle-step" % ("total", 1e9 * wall / ps))
print("  material points changing cell per step: %.1f %%" % (100.0 * int(b.group(6)) / ps))
PY
done

# ---- parallel figures (issue 15): 2 ranks against the hardware ceiling.
# The ceiling: two independent 1-rank runs side by side share the memory
# bandwidth; each slows down by a factor s, so 2 ranks can at best reach a
# speed-up of 2/s. Efficiency = speed-up / ceiling.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 OMP_NUM_THREADS=1
TMPD=$(mktemp -d)
trap 'rm -f "$LOG"; rm -rf "$TMPD"' EXIT
wall() { grep -o "wall [0-9.e+-]* s" "$1" | awk '{print $2}'; }
points() { grep -o "done: [0-9]* steps, [0-9]* particles" "$1" | awk '{print $2, $4}'; }
prm_with() { # prm_with FILE OUTDIR [load balancing interval]: a copy with another output directory
  sed -e "s#set directory *= .*#set directory = $2#" "$1" > "$TMPD/$(basename "$2").prm"
  if [ -n "${3:-}" ]; then
    sed -i "s#set interval *= *0 .*#set interval = $3#" "$TMPD/$(basename "$2").prm"
  fi
  echo "$TMPD/$(basename "$2").prm"
}
parallel_figures() { # parallel_figures NAME PRM [load balancing interval for the balanced run]
  local name=$1 prm=$2 lb=${3:-}
  local one two a b
  one=$(prm_with "$prm" "$TMPD/out_${name}_1")
  /usr/bin/time -f "%M" -o "$TMPD/${name}_rss" "$BUILD/tools/talus-explicit" "$one" > "$TMPD/${name}_1.log"
  "$BUILD/tools/talus-explicit" "$(prm_with "$prm" "$TMPD/out_${name}_a")" > "$TMPD/${name}_a.log" &
  "$BUILD/tools/talus-explicit" "$(prm_with "$prm" "$TMPD/out_${name}_b")" > "$TMPD/${name}_b.log" &
  wait
  mpirun -np 2 "$BUILD/tools/talus-explicit" "$(prm_with "$prm" "$TMPD/out_${name}_2")" > "$TMPD/${name}_2.log"
  if [ -n "$lb" ]; then
    mpirun -np 2 "$BUILD/tools/talus-explicit" "$(prm_with "$prm" "$TMPD/out_${name}_2lb" "$lb")" > "$TMPD/${name}_2lb.log"
  fi
  python3 - "$TMPD" "$name" "$lb" <<'PY'
import re, sys
d, name, lb = sys.argv[1], sys.argv[2], sys.argv[3]
def run(tag):
    t = open(f"{d}/{name}_{tag}.log").read()
    m = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s", t)
    s = re.search(r"full sorts (\d+)", t)
    return int(m.group(1)), int(m.group(2)), float(m.group(3)), int(s.group(1)) if s else -1, t
steps, n, t1, _, _ = run("1")
ta, tb = run("a")[2], run("b")[2]
slow = (ta + tb) / 2 / t1
ceiling = 2 / slow
rss = int(open(f"{d}/{name}_rss").read().split()[-1]) * 1024
print(f"\nbench parallel: {name}, {n} material points, {steps} steps")
print(f"  1 rank                         {1e9 * t1 / (steps * n):7.1f} ns/point-step (wall {t1:.1f} s)")
print(f"  2 concurrent 1-rank runs       slow-down {slow:.2f} x each -> ceiling speed-up {ceiling:.2f}")
for tag, label in (("2", "2 ranks"), ("2lb", "2 ranks, load balancing")):
    try:
        _, _, t2, sorts, text = run(tag)
    except FileNotFoundError:
        continue
    sp = t1 / t2
    imb = re.search(r"load balancing: points per rank max/mean ([\d.]+) -> ([\d.]+)", text)
    extra = f", imbalance {imb.group(1)} -> {imb.group(2)}" if imb else ""
    print(f"  {label:30s} {1e9 * t2 / (steps * n):7.1f} ns/point-step of wall time, speed-up {sp:.2f}, "
          f"efficiency {100 * sp / ceiling:.0f} % of the ceiling, full sorts {sorts}{extra}")
print(f"  memory: peak RSS {rss / 1e6:.0f} MB on 1 rank = {rss / n:.0f} bytes per point (process base included)")
PY
}
parallel_figures block_3d parameter_files/bench/block_spreading_3d.prm
parallel_figures corner_2d parameter_files/bench/corner_collapse_2d.prm 50

# ---- implicit family (issue 13): time per step, per Newton iteration, assembly
# ns per point and linear-solve time, a 2D (KLU) and a 3D (CG + ML AMG) scene
for PRM in parameter_files/bench/implicit_cantilever_2d.prm parameter_files/bench/implicit_block_3d.prm; do
  echo "bench: $PRM (single rank)"
  "$BUILD/tools/talus-implicit" "$(prm_with "$PRM" "$TMPD/out_$(basename "$PRM" .prm)")" | tee "$LOG"
  python3 - "$LOG" <<'PY'
import re, sys
t = open(sys.argv[1]).read()
d = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s; Newton iterations (\d+)", t)
b = re.search(r"assembly ([\d.e+-]+) \((\d+)\), linear solve ([\d.e+-]+) \((\d+)\), convective phase ([\d.e+-]+)", t)
steps, n, wall, its = int(d.group(1)), int(d.group(2)), float(d.group(3)), int(d.group(4))
ta, na, ts, ns, tc = float(b.group(1)), int(b.group(2)), float(b.group(3)), int(b.group(4)), float(b.group(5))
print(f"\nbench implicit: {n} material points, {steps} steps, {its} Newton iterations, wall {wall:.2f} s")
print(f"  per step {wall / steps:.3f} s; per Newton iteration {wall / max(its, 1):.3f} s")
print(f"  assembly (residual + tangent) {1e9 * ta / (na * n):.0f} ns per point ({na} assemblies, {ta:.2f} s)")
print(f"  linear solve {ts / max(ns, 1):.3f} s per solve ({ns} solves)")
print(f"  convective phase {1e9 * tc / (steps * n):.0f} ns per point-step")
PY
done

# ---- quasi-static: the same oedometer by talus-explicit (local damping until the
# force ratio < 1e-6) and talus-implicit (static, one load step): wall times (the
# tools' own figure and the process time) and the error of each against the
# analytic settlement, so the accuracy is seen to be the same
for fam in explicit implicit; do
  PRM=parameter_files/bench/qs_oedometer_$fam.prm
  echo "bench: $PRM"
  /usr/bin/time -f "process wall %e s" -o "$TMPD/qs_$fam.time" \
    "$BUILD/tools/talus-$fam" "$(prm_with "$PRM" "$TMPD/out_qs_$fam")" > "$TMPD/qs_$fam.log"
  tail -n 2 "$TMPD/qs_$fam.log"
done
python3 - "$TMPD" <<'PY'
import csv, re, sys
d = sys.argv[1]
E, nu, rho, g, H = 1e7, 0.3, 2000.0, 9.81, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
top = rho * g * H * H / (2 * E_oed)
res = {}
for fam in ("explicit", "implicit"):
    rows = list(csv.DictReader(open(f"{d}/out_qs_{fam}/particles_final.csv")))
    err = 0.0
    for r in rows:
        Y = float(r["pos_y"]) - float(r["u_y"])
        err = max(err, abs(float(r["u_y"]) + rho * g * (H * Y - Y * Y / 2) / E_oed))
    wall = float(re.search(r"wall ([\d.e+-]+) s", open(f"{d}/qs_{fam}.log").read()).group(1))
    proc = float(re.search(r"process wall ([\d.]+) s", open(f"{d}/qs_{fam}.time").read()).group(1))
    res[fam] = (wall, proc, err / top, len(rows))
print("\nbench quasi-static oedometer (%d points):" % res["implicit"][3])
for fam, (wall, proc, err, _) in res.items():
    print(f"  talus-{fam:9s} wall {wall:8.2f} s (process {proc:6.2f} s), max settlement error {100 * err:.3f} % of the top value")
print(f"  implicit speed-up: {res['explicit'][0] / res['implicit'][0]:.0f} x (solver wall), "
      f"{res['explicit'][1] / res['implicit'][1]:.0f} x (process, start-up included)")
PY
