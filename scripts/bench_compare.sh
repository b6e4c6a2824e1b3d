#!/bin/bash
# bench_compare.sh OLD_BINARY NEW_BINARY [REPEATS] [PRM]: the explicit bench scene
# (default: parameter_files/bench/block_spreading_3d.prm on a 64 x 64 x 24 grid,
# 163,840 points, 300 steps) run by two talus-explicit binaries alternately, for
# a machine shared with other jobs: the figure is CPU time (user + sys) per
# point-step of the N-step run minus that of a 1-step run of the same binary
# (set-up, first P2G and the output of the first step cancel), and the wall
# breakdown of the tool's summary line scaled by the steps' CPU/wall ratio.
# Each repeat runs old then new, the next new then old.
set -euo pipefail
OLD=$1 NEW=$2 REPEATS=${3:-3}
PRM=${4:-parameter_files/bench/block_spreading_3d.prm}
TMPD=$(mktemp -d)
trap 'rm -rf "$TMPD"' EXIT
small() { # small STEPS OUTDIR: the scene at half resolution with STEPS steps
  sed -e "s#set cells *= 128, 128, 48#set cells = 64, 64, 24#" \
      -e "s#set maximum steps *= .*#set maximum steps = $1#" \
      -e "s#set directory *= .*#set directory = $2#" "$PRM" > "$TMPD/s$1.prm"
  echo "$TMPD/s$1.prm"
}
run() { # run BINARY STEPS: prints "cpu wall log"
  local log="$TMPD/run.log"
  /usr/bin/time -f "%U %S" -o "$TMPD/time" "$1" "$(small "$2" "$TMPD/out")" > "$log"
  read -r u s < "$TMPD/time"
  cp "$log" "$TMPD/last_$2.log"
  python3 -c "print($u + $s)"
}
one_figure() { # one_figure NAME BINARY
  local c1 cn
  c1=$(run "$2" 1)
  cn=$(run "$2" 300)
  python3 - "$1" "$c1" "$cn" "$TMPD/last_300.log" "$TMPD/last_1.log" <<'PY'
import re, sys
name, c1, cn, log = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), open(sys.argv[4]).read()
wall1 = float(re.search(r"done: \d+ steps, \d+ particles, wall ([\d.e+-]+) s", open(sys.argv[5]).read()).group(1))
b = re.search(r"breakdown \[s\]: P2G ([\d.e+-]+), grid ([\d.e+-]+), G2P\+stress ([\d.e+-]+), relocation ([\d.e+-]+) \(moves ([\d.e+-]+), sorts ([\d.e+-]+)\), output ([\d.e+-]+)", log)
d = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s", log)
steps, n, wall = int(d.group(1)), int(d.group(2)), float(d.group(3))
ps = (steps - 1) * n
scale = (cn - c1) / (wall - wall1)  # CPU share of the steps (the machine is shared)
parts = [float(x) * scale * 1e9 / (steps * n) for x in b.groups()]
print("%-4s cpu %.1f ns/point-step (cpu %.1f s - %.1f s, wall %.1f s, cpu/wall %.2f) | scaled wall breakdown: "
      "P2G %.1f grid %.1f G2P+stress %.1f relocation %.1f (moves %.1f sorts %.1f) output %.1f"
      % (name, 1e9 * (cn - c1) / ps, cn, c1, wall, scale, *parts))
PY
}
for r in $(seq 1 "$REPEATS"); do
  if [ $((r % 2)) -eq 1 ]; then one_figure old "$OLD"; one_figure new "$NEW"
  else one_figure new "$NEW"; one_figure old "$OLD"; fi
done
