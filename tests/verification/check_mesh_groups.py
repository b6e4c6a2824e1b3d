"""talus-mesh on a gmsh quad mesh with named physical groups (issue 4, item 1).

parameter_files/mesh/layered_block_2d.prm: grid meshes/test_domain_2d.geo
(10 x 10 square cells in two transfinite blocks; groups in every naming form),
body 0 from the triangle mesh meshes/body_triangles_2d.geo (materials from its
groups, 4 points per triangle at the centroids of its 4 sub-triangles, K0 stress), body 1 a disk from the .prm.
Checked against numbers derived here, not by talus:
  - boundary ids and face counts of the grid file: 1 (base, "boundary 1 base"),
    7 (left, unnamed group tag 7), 5 (right, named "right", mapped), 4 (top);
    no face left with the default id 0;
  - material ids and cell counts: 1 ("material 1 sand", 40 cells), 2 ("clay",
    mapped, 60 cells);
  - the grid file is MSH 2.2 ASCII with one quad per cell (what deal.II's
    GridIn::read_msh reads; tests/unit/test_mesh_io.cc reads it with deal.II);
  - body 0: 4 points per triangle of the "block" group (triangles counted in a
    mesh of the same .geo made by the gmsh executable), total volume = the
    body area 0.4 m^2 to 1e-12, per material 0.16 / 0.24 to 1e-12, every point
    of material 1 below y = 0.3 and of material 2 above;
  - K0 stress: sigma_yy = -2000 * 9.81 * (0.7 - y), sigma_xx = sigma_zz = 0.5 sigma_yy;
  - body 1: the points are the centres of the 2 x 2 sub-cells of every 0.1 m
    cell inside the disk (counted here), each with volume 0.0025 m^2;
  - under mpirun -np 2 the grid file and the particle CSV are byte-identical.
Usage: check_mesh_groups.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
tool = os.path.join(tools, "talus-mesh")
shutil.rmtree(work, ignore_errors=True)
text = open(os.path.join(repo, "parameter_files", "mesh", "layered_block_2d.prm")).read()
text = text.replace("meshes/", os.path.join(repo, "meshes") + "/").replace("output/mesh/layered_block_2d/", "out/")
rc, out, err = tv.run_tool(tool, text, work, "mesh")
print(out.strip())
rc2, out2, _ = tv.run_tool(tool, text.replace("out/", "out_np2/"), work, "mesh_np2", np=2)


def read_msh(path):
    nodes, elements = {}, []
    lines = open(path).read().splitlines()
    i = 0
    while i < len(lines):
        if lines[i] == "$Nodes":
            n = int(lines[i + 1])
            for k in range(n):
                t, x, y, z = lines[i + 2 + k].split()
                nodes[int(t)] = (float(x), float(y))
            i += n + 2
        elif lines[i] == "$Elements":
            n = int(lines[i + 1])
            for k in range(n):
                v = [int(x) for x in lines[i + 2 + k].split()]
                elements.append((v[1], v[3], v[3 + v[2] - 1 + 1:]))
            i += n + 2
        else:
            i += 1
    return nodes, elements


nodes, elements = read_msh(os.path.join(work, "out", "grid.msh"))
faces, cells = {}, {}
for etype, phys, nl in elements:
    if etype == 1:
        faces[phys] = faces.get(phys, 0) + 1
    elif etype == 3:
        cells[phys] = cells.get(phys, 0) + 1
tv.check(set(t for t, _, _ in elements) == {1, 3}, f"grid file holds lines and quadrangles only")
tv.check(faces == {1: 10, 4: 10, 5: 10, 7: 10}, f"boundary ids/face counts {faces} == {{1: 10, 4: 10, 5: 10, 7: 10}}")
tv.check(cells == {1: 40, 2: 60}, f"material ids/cell counts {cells} == {{1: 40, 2: 60}}")
# every boundary face where it belongs
side = {1: lambda x, y: abs(y) < 1e-12, 7: lambda x, y: abs(x) < 1e-12, 5: lambda x, y: abs(x - 1) < 1e-12,
        4: lambda x, y: abs(y - 1) < 1e-12}
ok = all(all(side[phys](*nodes[n]) for n in nl) for etype, phys, nl in elements if etype == 1)
tv.check(ok, "each boundary face lies on the side of its group")
ok = all((sum(nodes[n][1] for n in nl) / 4 < 0.4) == (phys == 1) for etype, phys, nl in elements if etype == 3)
tv.check(ok, "material 1 cells below y = 0.4, material 2 above")

# triangles of the body mesh, counted in a mesh made by the gmsh executable
body_msh = os.path.join(work, "body.msh")
subprocess.run(["gmsh", "-2", os.path.join(repo, "meshes", "body_triangles_2d.geo"), "-o", body_msh, "-format",
                "msh22"], capture_output=True, check=True)
names = dict((m.group(2), int(m.group(1))) for m in re.finditer(r'^2 (\d+) "(.*)"$', open(body_msh).read(), re.M))
_, belements = read_msh(body_msh)
n_tri = sum(1 for etype, phys, _ in belements if etype == 2 and phys == names["block"])
print(f"gmsh: {n_tri} triangles in group 'block'")

p = tv.read_csv(os.path.join(work, "out", "particles.csv"))
n = len(p["x"])
b0 = [i for i in range(n) if p["body_id"][i] == 0]
b1 = [i for i in range(n) if p["body_id"][i] == 1]
tv.check(len(b0) == 4 * n_tri, f"body 0: {len(b0)} points == 4 x {n_tri} triangles")
vol = sum(p["volume"][i] for i in b0)
tv.check(abs(vol - 0.4) < 1e-12, f"body 0: total volume {vol:.17g} == 0.4 to 1e-12 (error {abs(vol - 0.4):.1e})")
for m, area, below in ((1, 0.16, True), (2, 0.24, False)):
    idx = [i for i in b0 if p["material_id"][i] == m]
    v = sum(p["volume"][i] for i in idx)
    tv.check(abs(v - area) < 1e-12, f"body 0, material {m}: volume {v:.17g} == {area} to 1e-12")
    tv.check(all((p["y"][i] < 0.3) == below for i in idx), f"material {m} points {'below' if below else 'above'} y = 0.3")
err_k0 = max(max(abs(p["stress_yy"][i] + 2000 * 9.81 * (0.7 - p["y"][i])),
                 abs(p["stress_xx"][i] - 0.5 * p["stress_yy"][i]), abs(p["stress_zz"][i] - 0.5 * p["stress_yy"][i]),
                 abs(p["stress_xy"][i])) for i in b0)
tv.check(err_k0 < 1e-8, f"body 0: K0 stress sigma_yy = -rho g (0.7 - y), sigma_h = 0.5 sigma_v (max error {err_k0:.1e} Pa)")
tv.check(all(p["stress_yy"][i] == 0 for i in b1), "body 1 (no K0): zero stress")

expected = sorted((round(x, 12), round(y, 12)) for x in [0.025 + 0.05 * k for k in range(20)]
                  for y in [0.025 + 0.05 * k for k in range(20)] if (x - 0.5) ** 2 + (y - 0.85) ** 2 <= 0.01)
got = sorted((round(p["x"][i], 12), round(p["y"][i], 12)) for i in b1)
tv.check(got == expected, f"body 1 (disk): {len(got)} points at the sub-cell centres inside the disk ({len(expected)})")
tv.check(all(abs(p["volume"][i] - 0.0025) < 1e-15 for i in b1), "body 1: every volume 0.0025 m^2")

for f in ("grid.msh", "particles.csv"):
    same = open(os.path.join(work, "out", f), "rb").read() == open(os.path.join(work, "out_np2", f), "rb").read()
    tv.check(same, f"mpirun -np 2: {f} byte-identical to the 1-rank file")
tv.finish()
