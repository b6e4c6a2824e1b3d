#!/usr/bin/env python3
"""make bench, first section: the start-up of a tool's process (docs/scaling.md, "Start-up").

Wall time of whole processes (median of N runs, started from here): talus-explicit --help,
--check of the demo scene, the same --check with MPI started (TALUS_ALWAYS_START_MPI=1) under
Open MPI's defaults and under the project's single-node settings (what the MPI start costs),
and a single-rank run of the demo scene cut to 1 ms of simulated time (png snapshots off),
whose own "start-up:" line gives the time from the process start to the first step.

Usage: bench_startup.py BUILD_DIR [RUNS]
"""
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

build = sys.argv[1]
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 7
tool = os.path.join(build, "tools", "talus-explicit")
demo = os.path.join("parameter_files", "demo", "column_collapse_2d.prm")
base_env = dict(os.environ)


def run_once(cmd, env_changes=None, drop=()):
    """(wall s, cpu s = user + system of the child, stdout) of one process."""
    env = {k: v for k, v in base_env.items() if k not in drop}
    env.update(env_changes or {})
    with tempfile.TemporaryFile("w+") as out:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        text = out.read()
    if p.returncode != 0:
        sys.exit(f"bench: {' '.join(cmd)} failed (exit {p.returncode}): {text[-400:]}")
    return wall, usage.ru_utime + usage.ru_stime, text


with tempfile.TemporaryDirectory() as tmp:
    prm = os.path.join(tmp, "demo_short.prm")
    text = open(demo).read()
    text = re.sub(r"set end time *= *[^\n#]*", "set end time = 0.001", text)
    text = re.sub(r"set png snapshots *= *[^\n#]*", "set png snapshots = none", text)
    text = re.sub(r"set directory *= *[^\n#]*", f"set directory = {tmp}/out", text)
    open(prm, "w").write(text)
    mca = ("OMPI_MCA_pml", "OMPI_MCA_btl")
    print(f"bench: start-up of a tool's process (s, median of {runs} rounds; "
          f"OMPI_MCA_pml={base_env.get('OMPI_MCA_pml', '(unset)')}, "
          f"OMPI_MCA_btl={base_env.get('OMPI_MCA_btl', '(unset)')})")
    rows = [("talus-explicit --help (no MPI start)", [tool, "--help"], None, ()),
            ("talus-explicit --check demo (no MPI start)", [tool, "--check", demo], None, ()),
            ("  the same with MPI started, Open MPI's defaults", [tool, "--check", demo],
             {"TALUS_ALWAYS_START_MPI": "1", "TALUS_KEEP_MPI_DEFAULTS": "1"}, mca),
            ("  the same with MPI started, single-node settings", [tool, "--check", demo],
             {"TALUS_ALWAYS_START_MPI": "1"}, ()),
            ("demo cut to 1 ms, 1 rank (whole process)", [tool, prm], None, ())]
    # round-robin: each round runs every command once (a drifting machine load hits all alike);
    # round 0 is a warm-up
    results = [[] for _ in rows]
    first_step = []
    for r in range(runs + 1):
        for i, (name, cmd, env, drop) in enumerate(rows):
            wall, cpu, out = run_once(cmd, env, drop)
            if r == 0:
                continue
            results[i].append((wall, cpu))
            if cmd[-1] == prm:
                first_step += [tuple(map(float, m)) for m in re.findall(
                    r"start-up: ([\d.]+) s from the process start to the first step "
                    r"\(main entered at ([\d.]+) s, MPI started at ([\d.]+) s\)", out)]
    print(f"  {'':52s} {'wall':>6s} [min, max]      cpu")
    for (name, *_), res in zip(rows, results):
        walls = [w for w, _ in res]
        print(f"  {name:52s} {statistics.median(walls):6.3f} [{min(walls):.3f}, {max(walls):.3f}]  "
              f"{statistics.median(c for _, c in res):6.3f}")
    if first_step:
        med = [statistics.median(f[i] for f in first_step) for i in range(3)]
        print(f"  {'demo, 1 rank: process start to the first step':52s} {med[0]:6.3f} "
              f"[{min(f[0] for f in first_step):.3f}, {max(f[0] for f in first_step):.3f}] "
              f"(the run's own 'start-up:' line)")
        print(f"    of which: dynamic loading {med[1]:.3f}, MPI start {med[2] - med[1]:.3f}, "
              f".prm and set-up {med[0] - med[2]:.3f} (medians; 10 ms resolution)")
