#!/bin/bash
# bench_ab.sh A B [REPEATS]: the full explicit bench (parameter_files/bench/block_spreading_3d.prm)
# run by two talus-explicit binaries alternately on a quiet machine: wall ns per
# point-step and the breakdown of the summary line, and the load average, per run.
cd "$(dirname "$0")/.."
A=$1 B=$2 R=${3:-3}
T=$(mktemp -d)
sed -e "s#set directory *= .*#set directory = $T/out#" parameter_files/bench/block_spreading_3d.prm > $T/b.prm
one() {
  "$2" $T/b.prm > $T/log 2>&1
  python3 - "$1" "$T/log" "$(cat /proc/loadavg)" <<'PY'
import re, sys
t = open(sys.argv[2]).read()
b = re.search(r"breakdown \[s\]: P2G ([\d.e+-]+), grid ([\d.e+-]+), G2P\+stress ([\d.e+-]+), relocation ([\d.e+-]+) \(moves ([\d.e+-]+), sorts ([\d.e+-]+)\), output ([\d.e+-]+)", t)
d = re.search(r"done: (\d+) steps, (\d+) particles, wall ([\d.e+-]+) s", t)
s, n, w = int(d.group(1)), int(d.group(2)), float(d.group(3))
f = lambda x: 1e9 * float(x) / (s * n)
print("%-10s total %6.1f | P2G %5.1f grid %4.1f G2P+stress %5.1f reloc %5.1f (moves %4.1f sorts %4.1f) out %4.1f | load %s" %
      (sys.argv[1], 1e9 * w / (s * n), *[f(x) for x in b.groups()], sys.argv[3].split()[0]))
PY
}
for r in $(seq 1 $R); do
  if [ $((r % 2)) -eq 1 ]; then one A "$A"; one B "$B"; else one B "$B"; one A "$A"; fi
done
rm -rf $T
