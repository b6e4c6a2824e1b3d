"""talus-explicit from talus-mesh files == the box scene (issue 4, item 3).

The elastic column of parameter_files/verification/elastic_column_gravity.prm
(box grid 1 x 20 cells, box body, 2 x 2 points per cell) is made again with
talus-mesh from parameter_files/mesh/elastic_column_2d.prm (gmsh grid of
meshes/elastic_column_2d.geo, body = the grid cells of the surface "column"),
and talus-explicit runs both. Checked:
  - same number of material points and the same probe displacement history as
    the box scene to round-off (max |du| <= 1e-12 x max |u|);
  - the same under mpirun -np 2 (talus-mesh and talus-explicit) to 1e-10;
  - the time-averaged top displacement within 2 % of rho g H^2 / (2 E_c), as
    tests/verification/check_column.py requires of the box scene.
Usage: check_mesh_column.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import shutil
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
mesh_prm = open(os.path.join(repo, "parameter_files", "mesh", "elastic_column_2d.prm")).read()
mesh_prm = mesh_prm.replace("meshes/", os.path.join(repo, "meshes") + "/")
box = open(os.path.join(repo, "parameter_files", "verification", "elastic_column_gravity.prm")).read()


def file_scene(files, out):
    t = tv.prm_set(box, "grid/source", "file")
    t = tv.prm_set(t, "grid/file", f"{files}/grid.msh")
    t = t.replace("set shape                   = box", f"set shape = file\n  set particle file = {files}/particles.h5")
    return tv.prm_set(t, "output/directory", out)


tv.run_tool(os.path.join(tools, "talus-mesh"), mesh_prm.replace("output/mesh/elastic_column_2d", "files"), work, "mesh")
tv.run_tool(os.path.join(tools, "talus-mesh"), mesh_prm.replace("output/mesh/elastic_column_2d", "files_np2"), work,
            "mesh_np2", np=2)
explicit = os.path.join(tools, "talus-explicit")
tv.run_tool(explicit, tv.prm_set(box, "output/directory", "box"), work, "box")
tv.run_tool(explicit, file_scene("files", "file"), work, "file")
tv.run_tool(explicit, file_scene("files_np2", "file_np2"), work, "file_np2", np=2)
a = tv.read_csv(f"{work}/box/series.csv")
b = tv.read_csv(f"{work}/file/series.csv")
c = tv.read_csv(f"{work}/file_np2/series.csv")
tv.check(a["n_particles"][0] == b["n_particles"][0] == 64,
         f"material points: box {a['n_particles'][0]:.0f}, from the files {b['n_particles'][0]:.0f} (64)")
tv.check(len(a["time"]) == len(b["time"]) == len(c["time"]), f"same number of steps ({len(a['time'])})")
umax = max(abs(x) for x in a["probe0_uy"])
d_box = max(abs(x - y) for x, y in zip(a["probe0_uy"], b["probe0_uy"]))
d_np2 = max(abs(x - y) for x, y in zip(b["probe0_uy"], c["probe0_uy"]))
print(f"max |u_box - u_file| = {d_box:.3e} m, max |u_np1 - u_np2| = {d_np2:.3e} m, max |u| = {umax:.3e} m")
tv.check(d_box <= 1e-12 * umax, f"file scene == box scene (max difference {d_box:.1e} m)")
tv.check(d_np2 <= 1e-10 * umax, f"file scene on 2 ranks == 1 rank (max difference {d_np2:.1e} m)")

t, u = b["time"], b["probe0_uy"]
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_static = -rho * g * H * H / (2 * Ec)
mean = sum(u) / len(u)
up = tv.zero_crossings(t, [x - mean for x in u], direction=+1)
tv.check(len(up) >= 2, f"at least two upward crossings of the mean (got {len(up)})")
if len(up) >= 2:
    ta, tb = up[-2], up[-1]
    num = 0.0
    for i in range(1, len(t)):
        lo, hi = max(t[i - 1], ta), min(t[i], tb)
        if hi > lo:
            f = lambda x: u[i - 1] + (u[i] - u[i - 1]) * (x - t[i - 1]) / (t[i] - t[i - 1])
            num += 0.5 * (f(lo) + f(hi)) * (hi - lo)
    avg = num / (tb - ta)
    err = abs(avg - u_static) / abs(u_static)
    tv.check(err < 0.02, f"time-averaged top displacement {avg:.6e} m within 2 % of {u_static:.6e} m (error {err:.2e})")
tv.finish()
