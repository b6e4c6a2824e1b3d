"""3D elastic column under gravity (hexahedra) with fem, ul-fem and mpm (issue 4):
the top point's settlement against u(z) = -rho g (H z - z^2/2) / E_oed within 1 %
at the quasi-static state (local damping 0.7 + convergence), and talus-compare of
FEM vs MPM (grid displacement, relative L2 <= 1e-2).
Usage: check_fem_column_3d.py TOOLS_DIR PRM WORKDIR
"""
import subprocess
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
text = open(prm_path).read()
for k, v in {"damping/local damping": "0.7", "convergence/enabled": "true",
             "convergence/force ratio tolerance": "1e-6", "convergence/energy ratio tolerance": "1e-8",
             "time/end time": "20", "output/final particles csv": "true", "output/results file": "results.h5",
             "output/series interval": "0.01"}.items():
    text = tv.prm_set(text, k, v)
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
for mode in ("fem", "ul-fem", "mpm"):
    t = tv.prm_set(tv.prm_set(text, "numerics/integration", mode), "output/directory", mode)
    _, out, _ = tv.run_tool(f"{tools}/talus-fem", t, work, mode)
    tv.check("converged" in out, f"{mode}: ended by the convergence criterion")
    p = tv.read_csv(f"{work}/{mode}/particles_final.csv")
    Z = [z - u for z, u in zip(p["pos_z"], p["u_z"])]
    k = max(range(len(Z)), key=lambda i: (Z[i], -p["id"][i]))
    ref = -rho * g * (H * Z[k] - Z[k] ** 2 / 2) / E_oed
    err = abs(p["u_z"][k] - ref) / abs(ref)
    tv.check(err < 0.01, f"{mode}: top settlement at z = {Z[k]:.5f}: {p['u_z'][k]:.6e} m vs {ref:.6e} m "
                         f"(error {err:.2e} < 1e-2)")
r = subprocess.run([f"{tools}/talus-compare", f"{work}/fem/results.h5", f"{work}/mpm/results.h5",
                    "--quantities=grid:displacement", "--time=final"], capture_output=True, text=True)
print(r.stdout + r.stderr)
tv.check(r.returncode == 0, f"talus-compare 3D FEM vs MPM: exit {r.returncode}")
tv.finish()
