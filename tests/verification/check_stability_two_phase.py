"""2-phase stability (issue 5): the critical time step of seed 000 Eq. 4.129.

On the Terzaghi column (one cell wide, 2 x 2 points per cell):
  * drag-controlled (k = 1e-7 m/s: Eq. 4.129 ~ 2/a, the forward-Euler limit of the
    explicit drag on the relative velocity): 0.95 x the formula runs 3000 steps
    stably; forced to 1.3 x it is detected unstable (exit 3); talus-critical-dt
    --probe measures the limit at 1.00-1.05 x the formula.
  * wave-controlled (k = 1e-3 m/s, the consolidation case): 0.95 x runs stably;
    the measured limit is 1.6-1.9 x the formula, as for the 1-phase solid (the
    momentum re-projection of Eqs. 4.110-4.111 damps the highest grid mode, see
    docs/explicit.md), so there 2.0 x forced must be detected unstable.
Usage: check_stability_two_phase.py TOOL PRM WORKDIR
"""
import os
import subprocess
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
dt_tool = os.path.join(os.path.dirname(os.path.abspath(tool)), "talus-critical-dt")
base = open(prm_path).read()
base = tv.prm_set(base, "grid/upper corner", "0.025, 1.025")
base = tv.prm_set(base, "grid/cells", "1, 41")
base = tv.prm_set(base, "body 0/upper corner", "0.025, 1")
base = tv.prm_set(base, "time/end time", "1")
base = tv.prm_set(base, "output/series interval", "0")
base = tv.prm_set(base, "output/final particles csv", "false")


def eq_4_129(k, L=0.025, n=0.3, rS=2650.0, rL=1000.0, KL=2.2e9, Ec=1e7, g=9.81):
    """Seed 000 Eqs. 4.122-4.132 computed independently (L^2 and L^4 in b and c,
    see docs/explicit-liquid-two-phase.md)."""
    rho = (1 - n) * rS + n * rL
    c1 = ((Ec + KL / n) / rho) ** 0.5
    rt = rho + (1 / n - 2) * rL
    dt1, dt2 = L / c1, 2 * rt * k / (rL * g)
    a = n * rho * g / ((1 - n) * rS * k)
    b = 4 * (n * rho * KL + (1 - 2 * n) * rL * KL + n * rL * Ec) / (n * (1 - n) * rS * rL * L * L)
    c = 16 * Ec * KL / ((1 - n) * rS * rL * L ** 4)
    s = b + (b * b - 4 * c) ** 0.5
    return (-2 * a + (4 * a * a + 8 * s) ** 0.5) / s, min(dt1, dt2)


def formula_dt(text, name):
    os.makedirs(work, exist_ok=True)
    prm = os.path.join(work, name + ".prm")
    open(prm, "w").write(text)
    csv = os.path.join(work, name + ".csv")
    p = subprocess.run([dt_tool, "--probe", "--probe-steps=400", "--csv=" + csv, prm], capture_output=True, text=True,
                       cwd=work)
    print(p.stdout.strip().splitlines()[-1] if p.stdout else p.stderr)
    tv.check(p.returncode == 0, f"{name}: talus-critical-dt --probe exit code {p.returncode}")
    r = tv.read_csv(csv)
    tv.check(r["phase"][0] == "coupled" and r["formula"][0] == "Eq. 4.129", f"{name}: coupled phase, Eq. 4.129 reported")
    k = float(text.split("hydraulic conductivity =")[1].split()[0])
    ref, ref122 = eq_4_129(k)
    tv.check(abs(r["dt_critical_formula"][0] - ref) <= 1e-9 * ref and abs(r["dt_eq_4_122"][0] - ref122) <= 1e-9 * ref122,
             f"{name}: Eq. 4.129 {r['dt_critical_formula'][0]:.9g} s and Eq. 4.122 {r['dt_eq_4_122'][0]:.9g} s equal "
             f"the independent evaluation ({ref:.9g}, {ref122:.9g} s)")
    return r["dt_critical_formula"][0], r["probe_stable_factor"][0], r["probe_unstable_factor"][0]


for name, k, steps, lim, forced in (("drag", "1e-7", 3000, (1.0, 1.05), 1.3), ("wave", "1e-3", 3000, (1.6, 1.9), 2.0)):
    text = tv.prm_set(base, "material 0/pore liquid/hydraulic conductivity", k)
    dt, lo, hi = formula_dt(text, name)
    print(f"{name}: Eq. 4.129 dt = {dt:.6g} s; measured limit {lo:.4f}-{hi:.4f} x")
    tv.check(lim[0] <= lo and hi <= lim[1] + 0.02,
             f"{name}: measured limit {lo:.3f}-{hi:.3f} x Eq. 4.129 lies in [{lim[0]}, {lim[1]}]")
    t = tv.prm_set(text, "time/maximum steps", str(steps))
    t = tv.prm_set(t, "output/directory", f"{name}_stable")
    t = tv.prm_set(t, "time/time step", f"{0.95 * dt:.10g}")
    tv.run_tool(tool, t, work, f"{name}_stable", expect_rc=0)
    s = tv.read_csv(f"{work}/{name}_stable/series.csv")
    tv.check(s["step"][-1] == steps, f"{name}: 0.95 x Eq. 4.129 ran {int(s['step'][-1])} steps stably")
    t = tv.prm_set(t, "output/directory", f"{name}_forced")
    t = tv.prm_set(t, "time/time step", f"{forced * dt:.10g}")
    t = tv.prm_set(t, "time/force time step", "true")
    rc, out, err = tv.run_tool(tool, t, work, f"{name}_forced", expect_rc=None)
    tv.check(rc == 3 and "unstable" in (out + err).lower(),
             f"{name}: {forced} x Eq. 4.129 forced is detected unstable (exit {rc}): {(out + err).strip()[-160:]}")
tv.finish()
