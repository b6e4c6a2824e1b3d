"""Unilateral contact floor of talus-implicit ('boundary conditions/contact',
docs/implicit.md "Contact floor"): an elastic block on the floor (PRM:
block_contact_floor.prm), dynamic, stage 0 gravity down, stage 1 gravity
reversed. Checks:
  * contact floor, stage 0: the block stays on the floor (centre of mass within
    1e-4 m of its start; the floor pushes, no node is released);
  * contact floor, stage 1: the block lifts off and rises freely, centre of mass
    y(T) - y(T_0) within 0.5 % of the rise of a rigid body under Newmark 1/2, 1/4
    released at T_0 from rest (a = 0 at the switch, g after it: after N steps of h
    g h^2 (1/4 + N (N - 1) / 2), 2 % below the continuous g t^2 / 2 at h = 2e-3 s,
    the trapezoidal rule's half step of lag); the log reports releases;
  * fixed floor (the mutant): the same scene does NOT lift off (rise < 1e-3 m):
    the unilateral check can fail;
  * the contact run on 2 ranks: centre of mass of every step within 1e-8 m of the
    1-rank run, the same Newton iterations and the same active-set totals.
Usage: check_implicit_contact_block.py TOOLS_DIR PRM WORKDIR
"""
import re
import shutil
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
tool = f"{tools}/talus-implicit"
shutil.rmtree(work, ignore_errors=True)
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
base = tv.prm_set(base, "output/series interval", "0")
g, T0, T1 = 9.81, 0.1, 0.2


def run(text, name, np=1):
    _, out, _ = tv.run_tool(tool, text, f"{work}/{name}", name, np=np)
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    summary = [l.strip() for l in out.splitlines() if "contact walls:" in l]
    return s, out, summary


def rise(s):
    t, y = s["time"], s["centre_of_mass_y"]
    y0 = y[0]
    i0 = min(range(len(t)), key=lambda i: abs(t[i] - T0))
    stay = max(abs(y[i] - y0) for i in range(i0 + 1))
    return t, y, stay, y[-1] - y[i0]


s1, out1, sum1 = run(base, "contact")
t, y, stay, up = rise(s1)
h = t[-1] - t[-2]
N = round((T1 - T0) / h)
expect = g * h * h * (0.25 + N * (N - 1) / 2)
print(f"contact floor: |y_c - y_c0| <= {stay:.3e} m while standing; rise after reversal {up:.6f} m "
      f"(Newmark rigid free rise {expect:.6f} m: error {up / expect - 1:+.3%}; continuous g t^2/2 = "
      f"{0.5 * g * (T1 - T0) ** 2:.6f} m); {sum1[0] if sum1 else 'no summary'}")
tv.check(abs(t[-1] - T1) < 1e-9, f"the contact run reached its end time ({t[-1]:g} s)")
tv.check(stay < 1e-4, f"contact floor holds the standing block (|y_c - y_c0| = {stay:.2e} m < 1e-4 m)")
tv.check(abs(up / expect - 1) < 0.005, f"contact floor lets the block lift off: rise within 0.5 % of the free rise "
                                      f"({up / expect - 1:+.3%})")
stand_log = [l for l in out1.splitlines() if " t = " in l and "contact:" in l]
stage0_released = 0
for l in stand_log:
    m = re.search(r" t = ([0-9.e+-]+):.*contact: \d+ pass\(es\), (\d+) released", l)
    if m and float(m.group(1)) <= T0 + 1e-9:
        stage0_released += int(m.group(2))
m = re.search(r"(\d+) node releases", sum1[0] if sum1 else "")
releases = int(m.group(1)) if m else 0
print(f"releases while standing: {stage0_released}; in the whole run: {releases}")
tv.check(stage0_released == 0, "no floor node released while gravity presses the block down")
tv.check(releases > 0, "the floor nodes are released after the reversal (reported in the log)")

fixed = tv.prm_set(tv.prm_set(base, "boundary conditions/contact", ""), "boundary conditions/fixed", "2")
s2, _, _ = run(fixed, "fixed")
_, _, stay2, up2 = rise(s2)
print(f"fixed floor: rise after reversal {up2:.3e} m")
tv.check(up2 < 1e-3, f"the fixed floor holds the block (rise {up2:.2e} m < 1e-3 m): the lift-off check can fail")

s3, _, sum3 = run(base, "contact_np2", np=2)
dy = max(abs(a - b) for a, b in zip(s1["centre_of_mass_y"], s3["centre_of_mass_y"]))
dx = max(abs(a - b) for a, b in zip(s1["centre_of_mass_x"], s3["centre_of_mass_x"]))
print(f"1 vs 2 ranks: centre of mass differs by at most {max(dx, dy):.2e} m; 2 ranks: {sum3[0] if sum3 else ''}")
tv.check(len(s1["time"]) == len(s3["time"]), "1 and 2 ranks take the same steps")
tv.check(max(dx, dy) < 1e-8, f"1 vs 2 ranks: centre of mass within 1e-8 m ({max(dx, dy):.2e})")
tv.check(s1["newton_iterations"] == s3["newton_iterations"], "1 vs 2 ranks: the same Newton iterations per step")
tv.check(sum1 == sum3, "1 vs 2 ranks: the same active-set totals")
tv.finish()
