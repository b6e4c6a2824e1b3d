#!/usr/bin/env python3
"""Runs talus-element on a .prm file and checks the result.

  check_element_csv.py mc-triaxial TOOL PRM WORKDIR --c C --phi PHI --psi PSI --sigma3 S3
      drained triaxial compression of Mohr-Coulomb: final axial stress equals the
      closed-form strength (1e-8 relative), lateral stress held (1e-9), the strength is
      never exceeded, and the last increments flow with
      d eps_v / d eps_a = -2 sin(psi) / (1 - sin(psi)) (1e-6 relative).
  check_element_csv.py broken TOOL PRM WORKDIR
      the tool must exit with status 2 (bad input) and name the file and a line.
"""
import argparse
import csv
import math
import os
import subprocess
import sys


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["mc-triaxial", "broken"])
    ap.add_argument("tool")
    ap.add_argument("prm")
    ap.add_argument("workdir")
    ap.add_argument("--c", type=float)
    ap.add_argument("--phi", type=float)
    ap.add_argument("--psi", type=float)
    ap.add_argument("--sigma3", type=float)
    ap.add_argument("--csv", default="mc_drained_triaxial.csv")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    csv_path = os.path.join(a.workdir, a.csv)
    if os.path.exists(csv_path):
        os.remove(csv_path)
    r = subprocess.run([os.path.abspath(a.tool), os.path.abspath(a.prm)], cwd=a.workdir,
                       capture_output=True, text=True)
    print(r.stdout, r.stderr)

    if a.mode == "broken":
        if r.returncode != 2:
            fail(f"expected exit status 2, got {r.returncode}")
        if os.path.basename(a.prm) not in r.stderr or "Line <" not in r.stderr:
            fail("error message does not name the file and line")
        print("OK: broken .prm rejected with status 2")
        return

    if r.returncode != 0:
        fail(f"talus-element exited with {r.returncode}")
    if os.path.exists(csv_path + ".tmp"):
        fail("temporary file left behind")
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    if len(rows) < 3:
        fail("too few rows")
    sf = math.sin(math.radians(a.phi))
    s1 = a.sigma3 * (1 + sf) / (1 - sf) + 2 * a.c * math.cos(math.radians(a.phi)) / (1 - sf)
    last, prev = rows[-1], rows[-2]
    s1_num = -float(last["sig_xx"])
    err = abs(s1_num - s1) / s1
    print(f"sigma_1' = {s1_num:.10g} Pa, closed form {s1:.10g} Pa, relative error {err:.3e}")
    if err > 1e-8:
        fail("failure stress off")
    for k in ("sig_yy", "sig_zz"):
        if abs(-float(last[k]) - a.sigma3) > 1e-9 * a.sigma3:
            fail(f"lateral stress {k} not held")
    if max(-float(row["sig_xx"]) for row in rows) > s1 * (1 + 1e-10):
        fail("strength exceeded on the way")
    ratio = (float(last["eps_v"]) - float(prev["eps_v"])) / (float(last["eps_a"]) - float(prev["eps_a"]))
    sp = math.sin(math.radians(a.psi))
    expected = -2 * sp / (1 - sp)
    rerr = abs(ratio - expected) / abs(expected)
    print(f"d eps_v/d eps_a = {ratio:.10g}, closed form {expected:.10g}, relative error {rerr:.3e}")
    if rerr > 1e-6:
        fail("dilatancy ratio off")
    print("OK")


if __name__ == "__main__":
    main()
