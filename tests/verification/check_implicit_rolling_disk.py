"""Elastic disk on the grid floor with gravity tilted by theta, talus-implicit,
dynamic (seed 001 §4.5.2, issue 13). Reference (rigid disk, released from rest):
rolling without slip a = (2/3) g sin(theta) (Eq. 4.41); sliding without friction
a = g sin(theta) and no rotation.

Measured:
  * a: least-squares fit x_c(t) = x_0 + v_0 t + a t^2 / 2 of the centre of mass
    (series.csv, every step) over the whole run;
  * the rotation of the disk at the end, from particles_final.csv: the angle phi of
    the best-fitting rotation of the centred reference positions X - X_c onto the
    centred current ones x - x_c (2D Procrustes, equal point masses: the ball's
    points are all of one volume), and the angular velocity omega = sum r x (v - v_c)
    / sum |r|^2 (r = x - x_c);
  * the rolling radius R = y_c (height of the centre above the floor y = 0);
  * the explicit critical step of the same scene from talus-critical-dt.
Checks (--expect roll, the default):
  * dt >= 10 x the explicit critical step;
  * |a / ((2/3) g sin theta) - 1| < 3 %;
  * no slip: |-phi R / (x_c(T) - x_c(0)) - 1| < 3 % and |-omega R / v_c(T) - 1| < 3 %;
  * Newton converged in every step, the run reached its end time.
--expect slide (the smooth-floor case, --floor roller): a within 3 % of g sin theta,
|omega R| < 3 % of v_c, and the rolling checks above must fail (they can fail).
--expect coulomb (a Coulomb floor with mu < tan(theta) / 3: the disk slides with friction): a within 1 % of
g (sin theta - mu cos theta) (mu from 'contact friction'), and the three rolling checks must fail.
--expect roll-accel (Table 4.1's time steps on the node contact floor): a within 3 % of (2/3) g sin theta
only (rotation and spin printed, not checked; no 10 x the explicit step asked: the smaller steps are below it).
--slide-tol TOL: the tolerance of --expect slide (a and |omega R| / v_c; default 3 %).
--ranks: also run on 2 ranks, the centre of mass of every step within 1e-8 m of the 1-rank run.
--disk-mesh MESH_PRM: first run talus-mesh on MESH_PRM (parameter_files/mesh/rolling_disk_polar.prm:
the polar-meshed disk whose points lie on rings) in WORKDIR and give its particle file to body 0
(the .prm's own 'particle file' path is relative to the repository root).
Usage: check_implicit_rolling_disk.py TOOLS_DIR PRM WORKDIR [--floor fixed|roller|contact] [--expect roll|slide]
       [--disk-mesh MESH_PRM] [--set entry=value ...]
"""
import argparse
import math
import os
import re
import subprocess

import talus_verify as tv

ap = argparse.ArgumentParser()
ap.add_argument("tools")
ap.add_argument("prm")
ap.add_argument("work")
ap.add_argument("--floor", choices=["fixed", "roller", "contact"], default=None,
                help="override boundary 2 of the .prm (contact: talus-implicit's unilateral no-slip wall)")
ap.add_argument("--expect", choices=["roll", "roll-accel", "slide", "coulomb"], default="roll")
ap.add_argument("--slide-tol", type=float, default=0.03,
                help="--expect slide: tolerance of a vs g sin theta and of |omega R| / v_c (default 0.03)")
ap.add_argument("--ranks", action="store_true",
                help="also run on 2 ranks: the centre of mass of every step within 1e-8 m of the 1-rank run")
ap.add_argument("--set", action="append", default=[], help="entry=value, e.g. time/end time=0.1")
ap.add_argument("--disk-mesh", default=None, help="talus-mesh .prm of the disk's particle file")
args = ap.parse_args()
os.makedirs(args.work, exist_ok=True)
if args.disk_mesh:
    # the particle file of the disk, made here (paths of the mesh .prm: relative to the repository root)
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(args.disk_mesh))))
    mtext = open(args.disk_mesh).read().replace("meshes/", os.path.join(repo, "meshes") + "/")
    mtext = re.sub(r"output/mesh/[^/\s]+/", "mesh/", mtext)
    tv.run_tool(f"{args.tools}/talus-mesh", mtext, args.work, "mesh")
    args.set = ["body 0/shape=file", "body 0/particle file=" + os.path.join(os.path.abspath(args.work), "mesh",
                                                                             "disk.h5")] + args.set

text = tv.prm_set(open(args.prm).read(), "output/directory", "out")
text = tv.prm_set(text, "output/series interval", "0")
text = tv.prm_set(text, "output/final particles csv", "true")
text = tv.prm_set(text, "output/vtu interval", "0")
for s in args.set:
    key, value = s.split("=", 1)
    text = tv.prm_set(text, key.strip(), value.strip())
if args.floor:
    for kind in ("fixed", "roller", "contact"):
        if kind == args.floor or f"set {kind}" in text:
            text = tv.prm_set(text, f"boundary conditions/{kind}", "2" if kind == args.floor else "")
    if args.floor != "contact":  # the contact wall's own entries go with it
        text = re.sub(r"^\s*set\s+contact\s+(method|friction|penalty|gap|passes)\b.*$", "", text, flags=re.M)
# talus-critical-dt reads the shared scene entries only: give it the scene with
# a fixed floor (the floor does not enter the explicit critical step)
crit_text = text
if re.search(r"^\s*set\s+contact\s*=\s*\S", text, re.M):
    crit_text = re.sub(r"^\s*set\s+contact\b.*$", "", text, flags=re.M)
    crit_text = tv.prm_set(crit_text, "boundary conditions/fixed", "2")


def entry(path):
    """The value of a 'set' entry of the (edited) .prm text: last occurrence, comment stripped."""
    key = path.split("/")[-1]
    found = None
    for line in text.splitlines():
        m = re.match(r"\s*set\s+" + re.escape(key) + r"\s*=\s*(.*)$", line.split("#", 1)[0])
        if m:
            found = m.group(1).strip()
    tv.check(found is not None, f"the .prm sets '{path}'")
    return found


g_vec = [float(v) for v in entry("gravity/acceleration").split(",")]
g = math.hypot(*g_vec)
sin_theta = g_vec[0] / g
dt = float(entry("time/time step"))
end = float(entry("time/end time"))
print(f"theta = {math.degrees(math.asin(sin_theta)):.4f} deg, |g| = {g:.4f} m/s^2, dt = {dt:g} s, end {end:g} s")

# the explicit critical step of the same scene
os.makedirs(args.work, exist_ok=True)
prm_file = os.path.join(args.work, "disk.prm")
with open(prm_file, "w") as f:
    f.write(crit_text)
csv = os.path.join(args.work, "critical_dt.csv")
p = subprocess.run([os.path.abspath(f"{args.tools}/talus-critical-dt"), "--csv=" + csv, prm_file],
                   capture_output=True, text=True, cwd=args.work, env=tv.child_env())
tv.check(p.returncode == 0, f"talus-critical-dt: exit {p.returncode} {p.stderr.strip()[:300]}")
crit = tv.read_csv(csv)
dt_cr = crit["dt_critical_explicit"][0]
ratio = dt / dt_cr
print(f"explicit critical step {dt_cr:.4e} s; dt / dt_cr = {ratio:.2f} (talus-critical-dt: "
      f"{crit['ratio_to_explicit'][0]:.2f})")
if args.expect != "roll-accel":
    tv.check(ratio >= 10, f"time step {dt:g} s >= 10 x the explicit critical step ({ratio:.2f} x)")

_, out, _ = tv.run_tool(f"{args.tools}/talus-implicit", text, args.work, "disk")
done = [l for l in out.splitlines() if l.startswith("done:")]
print(done[-1] if done else out.strip().splitlines()[-1])

s = tv.read_csv(f"{args.work}/out/series.csv")
t, xc, yc = s["time"], s["centre_of_mass_x"], s["centre_of_mass_y"]
tv.check(abs(t[-1] - end) < 1e-9 * max(1.0, end), f"the run reached its end time ({t[-1]:g} s)")
steps = [i for i in range(len(t)) if s["step"][i] > 0]
its = [s["newton_iterations"][i] for i in steps]
print(f"{len(steps)} steps; Newton iterations per step: mean {sum(its) / len(its):.2f}, max {max(its):.0f}")
for line in out.splitlines():
    if "contact walls:" in line or "contact friction" in line:
        print(line.strip())
if args.ranks:
    _, out2, _ = tv.run_tool(f"{args.tools}/talus-implicit", text, os.path.join(args.work, "np2"), "disk", np=2)
    s2 = tv.read_csv(f"{args.work}/np2/out/series.csv")
    tv.check(len(s2["time"]) == len(t), "1 and 2 ranks take the same steps")
    if len(s2["time"]) == len(t):
        dx = max(abs(u - v) for u, v in zip(xc, s2["centre_of_mass_x"]))
        dy = max(abs(u - v) for u, v in zip(yc, s2["centre_of_mass_y"]))
        print(f"1 vs 2 ranks: centre of mass differs by at most {max(dx, dy):.2e} m")
        tv.check(max(dx, dy) < 1e-8, f"1 vs 2 ranks: centre of mass within 1e-8 m ({max(dx, dy):.2e})")
        tv.check(s["newton_iterations"] == s2["newton_iterations"], "1 vs 2 ranks: the same Newton iterations per step")


def quadratic_fit(ts, ys):
    """Least squares y = c0 + c1 t + c2 t^2 (normal equations, 3 x 3, Cramer)."""
    S = [sum(x ** k for x in ts) for k in range(5)]
    b = [sum(y * x ** k for x, y in zip(ts, ys)) for k in range(3)]
    A = [[S[i + j] for j in range(3)] for i in range(3)]
    D = tv.det3(A)
    return [tv.det3([[b[i] if j == k else A[i][j] for j in range(3)] for i in range(3)]) / D for k in range(3)]


c = quadratic_fit(t, xc)
a = 2 * c[2]
a_roll, a_slide = 2.0 / 3.0 * g * sin_theta, g * sin_theta
rms = math.sqrt(sum((c[0] + c[1] * x + c[2] * x * x - y) ** 2 for x, y in zip(t, xc)) / len(t))
print(f"fitted centre acceleration a = {a:.5f} m/s^2 (fit RMS {rms:.2e} m); rolling (2/3) g sin = {a_roll:.5f} "
      f"(error {a / a_roll - 1:+.4%}), sliding g sin = {a_slide:.5f} (error {a / a_slide - 1:+.4%})")

# rotation and angular velocity at the end, from the points
P = tv.read_csv(f"{args.work}/out/particles_final.csv")
n = len(P["id"])
X = [(px - ux, py - uy) for px, py, ux, uy in zip(P["pos_x"], P["pos_y"], P["u_x"], P["u_y"])]
x = list(zip(P["pos_x"], P["pos_y"]))
Xc = [sum(q[k] for q in X) / n for k in range(2)]
xm = [sum(q[k] for q in x) / n for k in range(2)]
vm = [sum(P["v_x"]) / n, sum(P["v_y"]) / n]
cross = sum((A[0] - Xc[0]) * (B[1] - xm[1]) - (A[1] - Xc[1]) * (B[0] - xm[0]) for A, B in zip(X, x))
dot = sum((A[0] - Xc[0]) * (B[0] - xm[0]) + (A[1] - Xc[1]) * (B[1] - xm[1]) for A, B in zip(X, x))
phi = math.atan2(cross, dot)
r2 = sum((B[0] - xm[0]) ** 2 + (B[1] - xm[1]) ** 2 for B in x)
omega = sum((B[0] - xm[0]) * (vy - vm[1]) - (B[1] - xm[1]) * (vx - vm[0])
            for B, vx, vy in zip(x, P["v_x"], P["v_y"])) / r2
R = xm[1]
travel = xm[0] - Xc[0]
print(f"end: travel {travel:.5f} m, rotation -phi R = {-phi * R:.5f} m (R = y_c = {R:.5f} m, phi = {phi:.5f} rad); "
      f"v_c = {vm[0]:.5f} m/s, -omega R = {-omega * R:.5f} m/s")
roll_ok = abs(a / a_roll - 1) < 0.03
turn_ok = travel > 0 and abs(-phi * R / travel - 1) < 0.03
spin_ok = vm[0] > 0 and abs(-omega * R / vm[0] - 1) < 0.03
if args.expect == "roll-accel":
    tv.check(roll_ok, f"a within 3 % of (2/3) g sin theta ({a / a_roll - 1:+.3%})")
elif args.expect == "roll":
    tv.check(roll_ok, f"a within 3 % of (2/3) g sin theta ({a / a_roll - 1:+.3%})")
    tv.check(turn_ok, f"no slip: rotation x R within 3 % of the travel "
                      f"({(-phi * R / travel - 1) if travel else float('nan'):+.3%})")
    tv.check(spin_ok, f"no slip: omega R within 3 % of v_c ({(-omega * R / vm[0] - 1) if vm[0] else float('nan'):+.3%})")
elif args.expect == "coulomb":
    mu = float(entry("boundary conditions/contact friction"))
    cos_theta = -g_vec[1] / g
    a_mu = g * (sin_theta - mu * cos_theta)
    tv.check(mu < math.tan(math.asin(sin_theta)) / 3, f"mu = {mu} < tan(theta)/3: the disk must slip")
    tv.check(abs(a / a_mu - 1) < 0.01, f"Coulomb floor: a within 1 % of g (sin - mu cos) = {a_mu:.5f} "
                                       f"({a / a_mu - 1:+.3%})")
    tv.check(not roll_ok and not turn_ok and not spin_ok,
             "the rolling checks fail on the Coulomb floor (acceleration, rotation and spin each)")
else:
    tol = args.slide_tol
    tv.check(abs(a / a_slide - 1) < tol, f"smooth floor: a within {tol:.0%} of g sin theta ({a / a_slide - 1:+.3%})")
    tv.check(vm[0] > 0 and abs(omega * R) < tol * vm[0], f"smooth floor: |omega R| < {tol:.0%} of v_c "
                                                           f"({abs(omega * R) / vm[0] if vm[0] else float('nan'):.3%})")
    tv.check(not roll_ok and not turn_ok and not spin_ok,
             "the rolling checks fail on the smooth floor (acceleration, rotation and spin each)")
tv.finish()
