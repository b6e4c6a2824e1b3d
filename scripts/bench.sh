#!/bin/bash
# make bench: the explicit MPM benchmark (3D soft block spreading under gravity,
# 8 material points per cell, 1.31M points, fixed number of steps, one rank), with
# linear shape functions and then with quadratic B-splines.
# Prints ns per particle-step with a breakdown, the fraction of material points
# that changed cell per step and the cost of a VTU snapshot in steps. Then the parallel figures (issue 15) of the 3D block
# and of a 2D column collapse in the corner of a wide box: 1 rank, two concurrent
# 1-rank runs (the memory-bandwidth ceiling of 2 ranks), 2 ranks (and 2 ranks with
# load balancing for the corner scene): speed-up, efficiency against the ceiling,
# full sorts, peak memory per point. Then the implicit family (issue 13): a 2D and a
# 3D scene (time per step and per Newton iteration, assembly ns per point, linear
# solve time), and the quasi-static oedometer solved by talus-explicit (local
# damping) and by talus-implicit (static) to the same accuracy: both wall times.
# Then the semi-implicit family (issue 14): the paper's Table 4 protocol on a
# saturated slope (single- vs double-point, 2x2 ... 6x6 points per cell, ns per
# point-step with a breakdown, the double/single overhead) and the same slope
# with k = 1e-7 m/s by talus-explicit 2-phase and talus-semi-implicit to the
# same simulated time (the explicit wall time extrapolated from a fixed number
# of steps).
# First of all, the start-up of a tool's process (scripts/bench_startup.py).
# Build type must be Release (the Makefile's default).
set -euo pipefail
BUILD=${1:-build}
LOG=$(mktemp)
trap 'rm -f "$LOG"' EXIT
grep -q "CMAKE_BUILD_TYPE:STRING=Release" "$BUILD/CMakeCache.txt" || {
  echo "bench: $BUILD is not a Release build; refusing to benchmark the debug library" >&2; exit 2; }
# ---- start-up of a tool's process (issue 41): --help, --check, time to the first step
python3 scripts/bench_startup.py "$BUILD"
echo

# ---- the memory bandwidth of one core (issue 41 item 1): the roofline of the explicit step
STREAM_BIN=$(mktemp)
c++ -O2 -o "$STREAM_BIN" scripts/stream_bandwidth.cc
echo "bench: memory bandwidth of one core (scripts/stream_bandwidth.cc)"
"$STREAM_BIN" | tee "$LOG"
rm -f "$STREAM_BIN"
TRIAD=$(awk '/^stream: triad/ {print $3}' "$LOG")
echo

for PRM in parameter_files/bench/block_spreading_3d.prm parameter_files/bench/block_spreading_3d_bspline.prm; do
echo "bench: $PRM (single rank)"
"$BUILD/tools/talus-explicit" "$PRM" | tee "$LOG"
python3 - "$LOG" "$TRIAD" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
triad = float(sys.argv[2])
b = re.search(r"breakdown \[s\]: P2G ([\d.e+-]+), grid ([\d.e+-]+), G2P\+stress ([\d.e+-]+), relocation ([\d.e+-]+) \(moves [\d.e+-]+, sorts [\d.e+-]+\), "
              r"output ([\d.e+-]+) \((\d+) VTU snapshots ([\d.e+-]+)\); particles moved cell (\d+)", text)
d = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s", text)
steps, n, wall = int(d.group(1)), int(d.group(2)), float(d.group(3))
ps = steps * n
names = ["P2G (mass/force + momentum)", "grid update", "G2P + stress + fused P2G", "relocation (+ sorts)", "output"]
print("\nbench summary: %d material points, %d steps, wall %.1f s" % (n, steps, wall))
for name, v in zip(names, b.groups()[:5]):
    print("  %-30s %7.1f ns/particle-step" % (name, 1e9 * float(v) / ps))
print("  %-30s %7.1f ns/particle-step" % ("total", 1e9 * wall / ps))
# roofline (docs/scaling.md, "Roofline of the explicit step"): the bytes each pass must move per
# point-step for the 3D linear elastic point (location and reference location 3 doubles each, 16
# property doubles), at the bus bandwidth of one core = STREAM triad x 4/3 (triad does not count
# the write-allocate read of its target)
bus = triad * 4.0 / 3.0
model = [("momentum pass (P2G column)", 152, 0), ("grid update", 24, 1), ("update pass (G2P column)", 352, 2)]
print("  roofline at %.2f GB/s (triad %.2f x 4/3): measured / bound per pass" % (bus, triad))
bound_total = 0
for name, nbytes, k in model:
    bound = nbytes / bus
    bound_total += bound
    measured = 1e9 * float(b.groups()[k]) / ps
    print("    %-28s %4d B  bound %6.1f ns  measured %7.1f ns  ratio %5.2f" % (name, nbytes, bound, measured, measured / bound))
print("    %-28s %4d B  bound %6.1f ns  measured %7.1f ns  ratio %5.2f (relocation and output not bounded)"
      % ("step", sum(m[1] for m in model), bound_total, 1e9 * wall / ps, 1e9 * wall / ps / bound_total))
print("  material points changing cell per step: %.1f %%" % (100.0 * int(b.group(8)) / ps))
# a VTU snapshot against a step: the loop's wall time without its output, per step (the first
# snapshot is written before the loop, the last one inside it)
n_snap, t_snap = int(b.group(6)), float(b.group(7))
step = (wall - float(b.group(5))) / steps
print("  VTU snapshot: %.3f s each (%d written), a step %.3f s: snapshot = %.2f steps (goal <= 1)"
      % (t_snap / n_snap, n_snap, step, t_snap / n_snap / step))
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
prm_set() { # prm_set FILE OUTDIR [ENTRY=VALUE ...]: a copy with another output directory and
  # the given 'set ENTRY = VALUE' lines changed (each entry must occur in FILE)
  local copy kv
  copy="$TMPD/$(basename "$2").prm"
  sed -e "s#set directory *= .*#set directory = $2#" "$1" > "$copy"
  for kv in "${@:3}"; do
    grep -q "set ${kv%%=*} *= " "$copy" || { echo "bench: no entry '${kv%%=*}' in $1" >&2; return 2; }
    sed -i "s#\\(set ${kv%%=*} *= *\\).*#\\1${kv#*=}#" "$copy"
  done
  echo "$copy"
}
prm_with() { # prm_with FILE OUTDIR [load balancing interval]: a copy with another output directory
  local copy
  copy=$(prm_set "$1" "$2")
  if [ -n "${3:-}" ]; then
    sed -i "s#set interval *= *0 .*#set interval = $3#" "$copy"
  fi
  echo "$copy"
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
# ns per point (wall and CPU: docs/implicit.md, "Assembly cost"), linear-solve time and iterations, a 2D (KLU) and a 3D (CG + ML AMG)
# scene, and the 3D block in mixed u-p by GMRES with the block preconditioner
# (issue 39 item 5: 110,592 points without a direct factorisation)
for PRM in parameter_files/bench/implicit_cantilever_2d.prm parameter_files/bench/implicit_block_3d.prm \
           parameter_files/bench/implicit_up_block_3d.prm; do
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
cpu = re.search(r"assembly CPU time \[s\]: ([\d.e+-]+)", t)
cpu_text = f"; CPU {1e9 * float(cpu.group(1)) / (na * n):.0f} ns per point" if cpu else ""
print(f"  assembly (residual + tangent) {1e9 * ta / (na * n):.0f} ns per point ({na} assemblies, {ta:.2f} s{cpu_text})")
li = int(re.search(r"linear iterations (\d+)", t.split("done:")[1]).group(1))
print(f"  linear solve {ts / max(ns, 1):.3f} s per solve ({ns} solves), {li / max(ns, 1):.1f} linear iterations per solve")
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

# ---- semi-implicit family (issue 14), (a) the Table 4 protocol of seed 002 on
# the saturated slope (parameter_files/bench/semi_implicit_slope.prm): single-
# (point sets = one set: one point set carrying soil and water) vs double-point
# at 2x2 ... 6x6 points per cell, B-splines, the same dt and
# number of steps, no output; single and double alternate so that the
# machine's load drifts over both alike, and every run is made twice: the
# faster of the two counts (a shared machine only ever slows a run down)
SLOPE=parameter_files/bench/semi_implicit_slope.prm
echo "bench: $SLOPE (single rank; point sets one set | double, 2x2 ... 6x6 points per cell, each twice)"
for rep in 1 2; do
  for ppd in 2 3 4 5 6; do
    for sets in one_set double; do
      "$BUILD/tools/talus-semi-implicit" --time-shape-walk "$(prm_set "$SLOPE" "$TMPD/out_semi_${sets}_$ppd" \
        "particles per direction=$ppd" "point sets=${sets/_/ }")" > "$TMPD/semi_${sets}_${ppd}_$rep.log"
      tail -n 2 "$TMPD/semi_${sets}_${ppd}_$rep.log"
    done
  done
done
# (b) the same slope with k = 1e-7 m/s: talus-semi-implicit (double point,
# 2x2) to the scene's end time, and talus-explicit 2-phase (coupled) at the
# step talus-critical-dt reports, for 'maximum steps' steps
"$BUILD/tools/talus-semi-implicit" "$(prm_set "$SLOPE" "$TMPD/out_semi_k7" \
  "particles per direction=2" "hydraulic conductivity=1e-7")" > "$TMPD/semi_k7_1.log"
EXPL=parameter_files/bench/semi_implicit_slope_explicit.prm
"$BUILD/tools/talus-critical-dt" "$(prm_set "$EXPL" "$TMPD/out_expl_k7_dt")" > "$TMPD/expl_k7_dt.log"
"$BUILD/tools/talus-explicit" "$(prm_set "$EXPL" "$TMPD/out_expl_k7")" > "$TMPD/expl_k7.log"
python3 - "$TMPD" <<'PY'
import re, sys
d = sys.argv[1]
NUM = r"([\d.e+-]+)"
def semi(tag, reps=(1,)):  # the run of least wall time among the repetitions
    return min((semi_run(f"{d}/semi_{tag}_{r}.log") for r in reps), key=lambda r: r["wall"])
def semi_run(path):
    t = open(path).read()
    m = re.search(rf"done: (\d+) steps, dt {NUM} s, wall {NUM} s \(pressure solves {NUM} s", t)
    b = re.search(rf"breakdown \[s\]: P2N {NUM}, grid {NUM}, Poisson assembly {NUM}, pressure solve {NUM}(?: \(AMG set-up [\d.e+-]+\))?, "
                  rf"N2P {NUM}, update\+stress {NUM}, relocation {NUM}; points soil (\d+) water (\d+); "
                  rf"shape functions: one stencil walk over both sets {NUM} s", t)
    r = dict(steps=int(m.group(1)), dt=float(m.group(2)), wall=float(m.group(3)))
    # the pressure system's rebuilds: AMG hierarchies and pressure DoF sets (sparsity + matrix)
    r["amg"] = int(re.search(r"AMG set-ups (\d+)", t).group(1))
    r["dofsets"] = int(re.search(r"pressure DoF set rebuilds (\d+)", t).group(1))
    for k, v in zip(("p2n", "grid", "poisson", "solve", "n2p", "stress", "relocation"), b.groups()[:7]):
        r[k] = float(v)
    r["soil"], r["water"], r["walk"] = int(b.group(8)), int(b.group(9)), float(b.group(10))
    return r
def ns(r, seconds):  # per point-step, the points of one set (the paper's count)
    return 1e9 * seconds / (r["steps"] * r["soil"])
phases = [("shape functions*", None), ("P2N", "p2n"), ("N2P (FLIP + remap)", "n2p"), ("stress (update + F-bar)", "stress"),
          ("Poisson set-up + assembly", "poisson"), ("pressure solve", "solve"), ("grid (nodal)", "grid"),
          ("relocation + water move", "relocation")]
runs = {(s, p): semi(f"{s}_{p}", (1, 2)) for p in range(2, 7) for s in ("one_set", "double")}
r0 = runs[("one_set", 2)]
print(f"\nbench semi-implicit, Table 4 protocol: saturated slope, quadratic B-splines, dt {r0['dt']:g} s, "
      f"{r0['steps']} steps, no output (I/O excluded), 1 rank, the faster of 2 runs each; machine shared, figures noisy")
print("  single = point sets 'one set' (one point set carrying soil and water); rebuilds: AMG set-ups and "
      "pressure DoF sets (sparsity + matrix) over the run")
print("  ppc  points/set   single [s]  double [s]  double/single   ns/point-step single  double"
      "   AMG set-ups single double   DoF sets single double")
ratios = []
for p in range(2, 7):
    s, dd = runs[("one_set", p)], runs[("double", p)]
    ratios.append(dd["wall"] / s["wall"])
    print(f"  {p}x{p}  {s['soil']:10d}  {s['wall']:10.2f}  {dd['wall']:10.2f}  {ratios[-1]:13.3f}   "
          f"{ns(s, s['wall']):20.0f}  {ns(dd, dd['wall']):6.0f}   {s['amg']:18d} {dd['amg']:6d}"
          f"   {s['dofsets']:15d} {dd['dofsets']:6d}")
mean = sum(ratios) / len(ratios)
print(f"  mean double/single {mean:.3f} (goal <= 1.10: {'met' if mean <= 1.10 else 'NOT met'}; "
      f"{sum(x <= 1.10 for x in ratios)} of {len(ratios)} sizes within it)")
print("  breakdown, ns per point-step (points of one set), single / double:")
print("  " + " " * 27 + "".join(f"{p}x{p}".rjust(14) for p in range(2, 7)))
for name, key in phases:
    cells = []
    for p in range(2, 7):
        v = []
        for s in ("one_set", "double"):
            r = runs[(s, p)]
            v.append(ns(r, 7 * r["walk"] * r["steps"]) if key is None else ns(r, r[key]))
        cells.append(f"{v[0]:.0f}/{v[1]:.0f}".rjust(14))
    print(f"  {name:27s}" + "".join(cells))
print("  * 7 stencil walks (cell search, values and gradients) of the sets per step (one set: of its one set), "
      "timed once at the end;"
      " contained in the phases below it, not added")

k7 = semi("k7")
T = k7["steps"] * k7["dt"]
e = open(f"{d}/expl_k7.log").read()
em = re.search(rf"done: (\d+) steps, (\d+) particles, wall {NUM} s", e)
edt = float(re.search(rf"dt = {NUM} s", e).group(1))
crit = re.search(r"critical time step .*", open(f"{d}/expl_k7_dt.log").read()).group(0)
esteps, ewall = int(em.group(1)), float(em.group(3))
full = T / edt
ewall_full = ewall * full / esteps
print(f"\nbench semi-implicit vs explicit: the same saturated slope, k = 1e-7 m/s, to t = {T:g} s, 1 rank")
print(f"  talus-critical-dt (explicit scene): {crit}")
print(f"  talus-explicit 2-phase (coupled, linear, 2x2, {em.group(2)} points): dt {edt:.4g} s, ran {esteps} steps "
      f"({esteps * edt:.3g} s simulated) in {ewall:.2f} s;")
print(f"    to t = {T:g} s: {full:.4g} steps, wall {ewall_full:.4g} s EXTRAPOLATED linearly from those {esteps} steps")
print(f"  talus-semi-implicit (double point, B-splines, 2x2, {k7['soil']} + {k7['water']} points): dt {k7['dt']:g} s, "
      f"{k7['steps']} steps, wall {k7['wall']:.2f} s (pressure solves {k7['solve']:.2f} s)")
print(f"  semi-implicit speed-up {ewall_full / k7['wall']:.0f} x (expected > 10 x); time steps {edt:.3g} -> {k7['dt']:g} s "
      f"({k7['dt'] / edt:.0f} x)")
PY
