"""One initial-stress entry, three tools (issue 37): the elastic column of
parameter_files/verification/initial_stress/column.inc starts from the K0
procedure of 'body 0/initial stress' (sigma_v = -rho g depth, sigma_h = K0
sigma_v, K0 = 0.5), which is the discrete equilibrium of the column: every
family must keep it at rest. Each family's .prm includes the fragment as
shipped and is run twice, from the K0 state and released stress-free:
  * talus-explicit (dynamic, no damping, 0.2 s): the largest kinetic energy
    from K0 below KE_TOL of the stress-free run's;
  * talus-semi-implicit (a dry soil column, dynamic, 0.2 s): the same with the
    soil's kinetic energy;
  * talus-implicit (one static step with the full gravity): the largest
    |u_y| from K0 below U_TOL of the stress-free settlement, which itself must
    be within 2 % of rho g H^2 / (2 E_oed) at the top.
In every family sigma_xx / sigma_yy of the K0 run stays within 1e-3 of K0 at
the end (points with sigma_yy < -1 Pa). Then the refusals of the shared
entry: a negative K0 and K0 = auto on a Neo-Hookean material (all three
tools), a water level on points without pore water (talus-implicit,
talus-explicit with a drained material, a talus-semi-implicit soil body), the
old semi-implicit spelling 'initial state/geostatic': exit 2, the entry named,
no output directory written.
Usage: check_initial_stress_families.py TOOLS_DIR PRM_DIR WORKDIR
"""
import os
import sys

import talus_verify as tv

tools, prm_dir, work = sys.argv[1:4]
KE_TOL, U_TOL, K0 = 1e-4, 1e-6, 0.5
rho, g, H, E, nu = 2000.0, 9.81, 1.0, 1e7, 0.3
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
scene = os.path.join(prm_dir, "verification", "initial_stress")
os.makedirs(work, exist_ok=True)
local_inc = os.path.join(work, "column.inc")
if not os.path.exists(local_inc):
    os.symlink(os.path.join(scene, "column.inc"), local_inc)

families = {"talus-explicit": "column_explicit.prm", "talus-implicit": "column_implicit.prm",
            "talus-semi-implicit": "column_semi_implicit.prm"}
text = {tool: open(os.path.join(scene, name)).read() for tool, name in families.items()}


def run(tool, k0, extra=None):
    name = tool + ("_k0" if k0 else "_free")
    out = os.path.abspath(os.path.join(work, name))
    t = tv.prm_set(text[tool], "output/directory", out)
    if not k0:
        t = tv.prm_set(t, "body 0/initial stress/K0 procedure", "false")
    tv.run_tool(os.path.join(tools, tool), t, work, name)
    return out


def k0_ratio(rows, tool):
    worst = max(abs(sx / sy - K0) for sx, sy in zip(rows["stress_xx"], rows["stress_yy"]) if sy < -1.0)
    tv.check(worst < 1e-3, f"{tool}: sigma_xx / sigma_yy stays within 1e-3 of K0 = {K0} (worst {worst:.2e})")


# dynamic families: at rest from K0, against the stress-free release
for tool, ke, final in (("talus-explicit", "kinetic_energy", "particles_final.csv"),
                        ("talus-semi-implicit", "kinetic_energy_soil", "soil_final.csv")):
    peak = {}
    for k0 in (True, False):
        out = run(tool, k0)
        peak[k0] = max(tv.read_csv(os.path.join(out, "series.csv"))[ke])
        if k0:
            k0_ratio(tv.read_csv(os.path.join(out, final)), tool)
    r = peak[True] / peak[False]
    print(f"{tool}: largest {ke} {peak[True]:.3e} J from K0, {peak[False]:.3e} J stress-free (ratio {r:.2e})")
    tv.check(r < KE_TOL, f"{tool}: the column from K0 stays at rest (kinetic energy ratio {r:.2e} < {KE_TOL:g})")

# implicit: one static step
u = {}
for k0 in (True, False):
    out = run("talus-implicit", k0)
    rows = tv.read_csv(os.path.join(out, "particles_final.csv"))
    u[k0] = max(abs(v) for v in rows["u_y"])
    if k0:
        k0_ratio(rows, "talus-implicit")
s = rho * g * H * H / (2 * E_oed)
top = u[False]
print(f"talus-implicit: largest |u_y| {u[True]:.3e} m from K0, {top:.3e} m stress-free "
      f"(analytic top settlement {s:.4e} m)")
tv.check(abs(top - s) < 0.02 * s, f"talus-implicit: stress-free settlement within 2 % of rho g H^2 / (2 E_oed) "
         f"({100 * (top - s) / s:+.2f} %)")
tv.check(u[True] < U_TOL * top, f"talus-implicit: the column from K0 does not move (|u_y| {u[True]:.2e} m "
         f"< {U_TOL:g} x {top:.2e} m)")

# refusals: exit 2, the entry named, nothing written
cases = [(tool, "K0 negative", {"body 0/initial stress/K0": "-0.1"}, "body 0/initial stress/K0")
         for tool in families]
cases += [(tool, "K0 auto on neo hookean", {"body 0/initial stress/K0": "auto"}, "body 0/initial stress/K0")
          for tool in families]
cases += [("talus-implicit", "water level, one-phase", {"body 0/initial stress/water level": "0.8"},
           "body 0/initial stress/water level"),
          ("talus-explicit", "water level, drained material", {"body 0/initial stress/water level": "0.8"},
           "body 0/initial stress/water level"),
          ("talus-semi-implicit", "water level, soil body", {"body 0/initial stress/water level": "0.8"},
           "body 0/initial stress/water level"),
          ("talus-semi-implicit", "old spelling", {"initial state/geostatic": "true"}, "geostatic")]
for i, (tool, what, settings, entry) in enumerate(cases):
    name = f"bad_{i}"
    out = os.path.abspath(os.path.join(work, name + "_out"))
    t = tv.prm_set(text[tool], "output/directory", out)
    for k, v in settings.items():
        t = tv.prm_set(t, k, v)
    _, o, e = tv.run_tool(os.path.join(tools, tool), t, work, name, expect_rc=2)
    tv.check(entry in o + e, f"{tool}, {what}: exit 2 naming '{entry}'")
    tv.check(not os.path.exists(out), f"{tool}, {what}: nothing written")
tv.finish()
