"""One scene, three tools (issue 37): the elastic layer of
parameter_files/verification/rigid_plate/layer.inc loaded through a
frictionless rigid plate by a total force, solved by talus-explicit (to
quasi-static rest), talus-implicit (static) and talus-semi-implicit (drained,
at the end of consolidation), each from its own .prm that includes the same
fragment (grid, walls, plate, load, material, body) and adds only its own
sections. Analytic plate settlement (oedometric): s = q H / E_oed with
q = 1 kPa, H = 1 m, E_oed = E (1 - nu) / ((1 + nu) (1 - 2 nu)), E = 1 MPa,
nu = 0.3: 7.4286e-4 m. Checks: each family's final plate_0_displacement
within TOL of -s, the three within TOL of each other (largest minus smallest
over s), and each family's final plate_0_force equal to the applied -1 kN
(to 1e-9 relative: force control). The fragment is used as shipped: each
.prm is run where it lies (its `include layer.inc` resolved relative to it),
only its output directory is redirected.
Usage: check_rigid_plate_families.py TOOLS_DIR PRM_DIR WORKDIR TOL
"""
import os
import sys

import talus_verify as tv

tools, prm_dir, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
E, nu, q, H = 1e6, 0.3, 1e3, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
s = q * H / E_oed
scene = os.path.join(prm_dir, "verification", "rigid_plate")
families = [("talus-explicit", "layer_explicit.prm"), ("talus-implicit", "layer_implicit.prm"),
            ("talus-semi-implicit", "layer_semi_implicit.prm")]

settlement = {}
for tool, name in families:
    path = os.path.join(scene, name)
    text = open(path).read()
    tv.check("include layer.inc" in text, f"{name} includes the shared fragment layer.inc")
    out = os.path.abspath(os.path.join(work, tool))
    # the .prm is written next to the fragment's copy so that the include resolves as shipped
    os.makedirs(work, exist_ok=True)
    local_inc = os.path.join(work, "layer.inc")
    if not os.path.exists(local_inc):
        os.symlink(os.path.join(scene, "layer.inc"), local_inc)
    tv.run_tool(os.path.join(tools, tool), tv.prm_set(text, "output/directory", out), work, tool)
    ser = tv.read_csv(os.path.join(out, "series.csv"))
    u, f = ser["plate_0_displacement"][-1], ser["plate_0_force"][-1]
    settlement[tool] = u
    err = abs(u + s) / s
    print(f"{tool}: plate settlement {u:.6e} m vs analytic {-s:.6e} m: error {100 * err:.3f} %; "
          f"plate force {f:.6e} N")
    tv.check(err < tol, f"{tool}: settlement within {100 * tol:g} % of q H / E_oed ({100 * err:.3f} %)")
    tv.check(abs(f + q) < 1e-9 * q, f"{tool}: the plate force is the applied -1 kN ({f:.9e})")

spread = (max(settlement.values()) - min(settlement.values())) / s
tv.check(spread < tol, f"the three families agree within {100 * tol:g} % of s (spread {100 * spread:.3f} %)")

# one command line: every formulation tool accepts --restart (here with --check
# on a scene of its own without checkpoints: refused because there is nothing
# to resume, naming 'checkpoint/restart', not as an unknown option)
import subprocess

for tool, base in [("talus-explicit", "verification/oedometer_traction.prm"),
                   ("talus-fem", "verification/oedometer_traction.prm"),
                   ("talus-implicit", "implicit/block_top_traction.prm"),
                   ("talus-semi-implicit", "verification/semi_implicit_hydrostatic.prm")]:
    text = open(os.path.join(prm_dir, base)).read()
    prm = os.path.join(work, tool + "_restart.prm")
    with open(prm, "w") as fh:
        fh.write(tv.prm_set(text, "output/directory", os.path.join(work, "restart_" + tool)))
    p = subprocess.run([os.path.join(tools, tool), "--check", "--restart", prm], capture_output=True, text=True,
                       env=tv.child_env(), cwd=work)
    both = p.stdout + p.stderr
    last = (both.strip().splitlines() or [""])[-1]
    tv.check(p.returncode == 2 and "checkpoint/restart" in both and "unknown" not in both,
             f"{tool} --restart: accepted, refused for the missing checkpoint (exit {p.returncode}: {last[:160]})")
tv.finish()
