#!/bin/bash
# make bench: the explicit MPM benchmark (3D soft block spreading under gravity,
# 8 material points per cell, 1.31M points, fixed number of steps, one rank), with
# linear shape functions and then with quadratic B-splines.
# Prints ns per particle-step with a breakdown and the fraction of material points
# that changed cell per step. Build type must be Release (the Makefile's default).
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
