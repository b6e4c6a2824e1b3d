"""talus-explicit from talus-mesh files == the box scene (issue 4, item 3).

The elastic column of parameter_files/verification/elastic_column_gravity.prm
(box grid 1 x 20 cells, box body, 2 x 2 points per cell) and of
elastic_column_gravity_3d.prm (1 x 1 x 20 hexahedra, 2 x 2 x 2 points) are made
again with talus-mesh from parameter_files/mesh/elastic_column_{2,3}d.prm (gmsh
grids of meshes/elastic_column_{2,3}d.geo, body = the grid cells of the group
"column"), and talus-explicit runs both versions. Checked (2D and 3D):
  - same number of material points and the same probe displacement history as
    the box scene to round-off (max |du| <= 1e-12 x max |u|);
  - the same under mpirun -np 2 (talus-mesh and talus-explicit) to 1e-10;
  - the time-averaged top displacement within 2 % of rho g H^2 / (2 E_c), as
    tests/verification/check_column.py requires of the box scene;
  - the initial stress of a particle file reaches the solver: with the K0 stress
    of the column at rest (k0 = nu / (1 - nu), density 2000, surface y = 1)
    the column stays at rest (max |u| < 1e-3 u_s); with the stress of density
    1900 it oscillates about the remaining 5 % of the settlement, so max |u| is
    2 x 0.05 u_s within 10 %.
Usage: check_mesh_column.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import shutil
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
explicit = os.path.join(tools, "talus-explicit")


def file_scene(box, files, out):
    t = tv.prm_set(box, "grid/source", "file")
    t = tv.prm_set(t, "grid/file", f"{files}/grid.msh")
    t = t.replace("set shape                   = box", f"set shape = file\n  set particle file = {files}/particles.h5")
    return tv.prm_set(t, "output/directory", out)


def compare(dim):
    """Box scene vs the scene from talus-mesh files (1 and 2 ranks); returns the file run's series."""
    mesh_prm = open(os.path.join(repo, "parameter_files", "mesh", f"elastic_column_{dim}d.prm")).read()
    mesh_prm = mesh_prm.replace("meshes/", os.path.join(repo, "meshes") + "/")
    box = open(os.path.join(repo, "parameter_files", "verification",
                            "elastic_column_gravity.prm" if dim == 2 else "elastic_column_gravity_3d.prm")).read()
    d = f"{dim}d"
    tv.run_tool(os.path.join(tools, "talus-mesh"), mesh_prm.replace(f"output/mesh/elastic_column_{d}", f"files_{d}"),
                work, "mesh_" + d)
    tv.run_tool(os.path.join(tools, "talus-mesh"),
                mesh_prm.replace(f"output/mesh/elastic_column_{d}", f"files_np2_{d}"), work, "mesh_np2_" + d, np=2)
    tv.run_tool(explicit, tv.prm_set(box, "output/directory", "box_" + d), work, "box_" + d)
    tv.run_tool(explicit, file_scene(box, "files_" + d, "file_" + d), work, "file_" + d)
    tv.run_tool(explicit, file_scene(box, "files_np2_" + d, "file_np2_" + d), work, "file_np2_" + d, np=2)
    a = tv.read_csv(f"{work}/box_{d}/series.csv")
    b = tv.read_csv(f"{work}/file_{d}/series.csv")
    c = tv.read_csv(f"{work}/file_np2_{d}/series.csv")
    n = 64 if dim == 2 else 128
    tv.check(a["n_particles"][0] == b["n_particles"][0] == n,
             f"{d}: material points: box {a['n_particles'][0]:.0f}, from the files {b['n_particles'][0]:.0f} ({n})")
    tv.check(len(a["time"]) == len(b["time"]) == len(c["time"]), f"{d}: same number of steps ({len(a['time'])})")
    key = "probe0_uy" if dim == 2 else "probe0_uz"
    umax = max(abs(x) for x in a[key])
    d_box = max(abs(x - y) for x, y in zip(a[key], b[key]))
    d_np2 = max(abs(x - y) for x, y in zip(b[key], c[key]))
    print(f"{d}: max |u_box - u_file| = {d_box:.3e} m, max |u_np1 - u_np2| = {d_np2:.3e} m, max |u| = {umax:.3e} m")
    tv.check(d_box <= 1e-12 * umax, f"{d}: file scene == box scene (max difference {d_box:.1e} m)")
    tv.check(d_np2 <= 1e-10 * umax, f"{d}: file scene on 2 ranks == 1 rank (max difference {d_np2:.1e} m)")
    return b, mesh_prm, box


compare(3)
b, mesh_prm, box = compare(2)
t, u = b["time"], b["probe0_uy"]
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_static = -rho * g * H * H / (2 * Ec)
avg, period = tv.time_average_last_period(t, u)
tv.check(period == period, "at least two upward crossings of the mean")
if period == period:
    err = abs(avg - u_static) / abs(u_static)
    tv.check(err < 0.02, f"time-averaged top displacement {avg:.6e} m within 2 % of {u_static:.6e} m (error {err:.2e})")

# initial stress from the particle file (K0 written by talus-mesh)
k0 = nu / (1 - nu)
for rho_k0, name in ((2000.0, "k0_rest"), (1900.0, "k0_low")):
    text = mesh_prm.replace("output/mesh/elastic_column_2d", name) + (
        f"subsection body 0\n  set k0 = {k0!r}\n  set k0 density = {rho_k0}\n  set surface level = 1\nend\n")
    tv.run_tool(os.path.join(tools, "talus-mesh"), text, work, "mesh_" + name)
    tv.run_tool(explicit, file_scene(box, name, name + "_run"), work, name + "_run")
    s = tv.read_csv(f"{work}/{name}_run/series.csv")
    umax_k0 = max(abs(x) for x in s["probe0_uy"])
    if rho_k0 == 2000.0:
        tv.check(umax_k0 < 1e-3 * abs(u_static),
                 f"K0 stress of the column at rest from the file: max |u| {umax_k0:.2e} m < 1e-3 x {abs(u_static):.3e} m")
    else:
        expect = 2 * 0.05 * abs(u_static)
        tv.check(abs(umax_k0 - expect) < 0.1 * expect,
                 f"K0 stress of density 1900: max |u| {umax_k0:.3e} m == 2 x 5 % of u_s = {expect:.3e} m within 10 %")
tv.finish()
