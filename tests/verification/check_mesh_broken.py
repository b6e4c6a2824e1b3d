"""Broken meshes and particle files are refused (issue 4, item 2).

Each case runs talus-mesh (or talus-explicit on files talus-mesh wrote) in a
fresh directory and requires exit status 2, a message naming the cell,
element, particle or group (checked by keywords), and no output file.
Usage: check_mesh_broken.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import shutil
import subprocess
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
mesh_tool = os.path.join(tools, "talus-mesh")
explicit = os.path.join(tools, "talus-explicit")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)


def write(name, text):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def msh22(nodes, elements):
    """MSH 2.2 ASCII: nodes [(x, y)], elements [(type, phys, elementary, [node ids])]."""
    s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(nodes)
    s += "".join(f"{i + 1} {x} {y} 0\n" for i, (x, y) in enumerate(nodes))
    s += "$EndNodes\n$Elements\n%d\n" % len(elements)
    s += "".join(f"{i + 1} {t} 2 {p} {e} " + " ".join(map(str, n)) + "\n" for i, (t, p, e, n) in enumerate(elements))
    return s + "$EndElements\n"


# a 2 x 1 strip of unit squares, nodes 1..6
strip = [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)]


def mesh_prm(grid_file, bodies=None, extra_grid="", out="out"):
    """talus-mesh .prm: grid from grid_file, bodies as (source, settings) pairs."""
    bodies = bodies or [("grid", "")]
    s = f"set dimension = 2\nsubsection grid\n  set source = gmsh\n  set file = {grid_file}\n{extra_grid}end\n"
    s += f"subsection output\n  set grid file = {out}/grid.msh\n  set particle file = {out}/particles.h5\nend\n"
    s += f"set number of bodies = {len(bodies)}\n"
    for k, (source, body) in enumerate(bodies):
        s += f"subsection body {k}\n  set source = {source}\n{body}end\n"
    return s


def expect_refused(name, tool, prm_text, needles, outputs=("out/grid.msh", "out/particles.h5")):
    d = os.path.join(work, name)
    os.makedirs(d)
    rc, out, err = tv.run_tool(tool, prm_text, d, name, expect_rc=None)
    msg = (out + err).strip().splitlines()
    msg = msg[-1] if msg else ""
    tv.check(rc == 2, f"{name}: exit status 2 (got {rc})")
    missing = [n for n in needles if n.lower() not in (out + err).lower()]
    tv.check(not missing, f"{name}: message names {needles} (missing {missing}): {msg}")
    written = [o for o in outputs if os.path.exists(os.path.join(d, o))]
    tv.check(not written, f"{name}: no output written (found {written})")
    for bad in ("terminate called", "Traceback", "An error occurred in line", "Stacktrace"):
        tv.check(bad not in out + err, f"{name}: no '{bad}' in the output")
    print(f"   {name}: {msg}")


# 1. an inverted cell: the second quad's nodes run clockwise
inv = write("inverted.msh", msh22(strip, [(3, 1, 1, [1, 2, 5, 4]), (3, 1, 1, [2, 5, 6, 3])]))
expect_refused("inverted_cell", mesh_tool, mesh_prm(inv), ["cell 1", "gmsh element 2", "inverted"])

# 2. a degenerate (self-intersecting, bow-tie) cell
bow = write("bowtie.msh", msh22(strip, [(3, 1, 1, [1, 2, 5, 4]), (3, 1, 1, [2, 3, 5, 6])]))
expect_refused("degenerate_cell", mesh_tool, mesh_prm(bow), ["cell 1", "gmsh element 2", "degenerate"])

# 3. second-order elements (gmsh -order 2 of the oedometer mesh)
geo = os.path.join(repo, "meshes", "oedometer_2d.geo")
second = os.path.join(work, "second_order.msh")
p = subprocess.run(["gmsh", "-2", "-order", "2", geo, "-o", second, "-format", "msh22"], capture_output=True, text=True)
tv.check(p.returncode == 0 and os.path.exists(second), "gmsh wrote a second-order mesh")
expect_refused("second_order", mesh_tool, mesh_prm(second), ["order 2", "first-order"])

# 4. a physical group the .prm names that the mesh does not have
expect_refused("missing_body_group", mesh_tool, mesh_prm(geo, [("grid", "  set groups = sand\n")]),
               ["'sand'", "does not exist", "column"])
expect_refused("missing_boundary_group", mesh_tool, mesh_prm(geo, extra_grid="  set boundary groups = rigth = 5\n"),
               ["'rigth'", "does not exist", "boundary 1 right"])

# 5. triangles in the background grid (no recombination)
expect_refused("triangles_in_grid", mesh_tool,
               mesh_prm(os.path.join(repo, "meshes", "body_triangles_2d.geo"), extra_grid="  set recombine = false\n"),
               ["triangle", "quadrangles", "recombine"])

# 6. a zero-volume material point: a body element with three collinear nodes
grid = os.path.join(repo, "meshes", "test_domain_2d.geo")
map5 = "  set boundary groups = right = 5\n"
flat = write("flat_body.msh", msh22([(0.2, 0.2), (0.4, 0.2), (0.6, 0.2), (0.2, 0.4)],
                                    [(2, 1, 1, [1, 2, 4]), (2, 1, 1, [1, 2, 3])]))
expect_refused("zero_volume_particle", mesh_tool,
               mesh_prm(grid, [("gmsh", f"  set file = {flat}\n  set positions = gauss\n")], map5),
               ["material point", "gmsh element 2", "zero volume"])

# 7. a material point outside the grid
outside = write("outside_body.msh", msh22([(0.9, 0.9), (1.5, 0.9), (0.9, 1.5)], [(2, 1, 1, [1, 2, 3])]))
expect_refused("particle_outside_grid", mesh_tool,
               mesh_prm(grid, [("gmsh", f"  set file = {outside}\n  set points per direction = 2\n")], map5),
               ["material point", "outside the background grid", "gmsh element 1"])

# 8. duplicated points: two bodies from the same body mesh
body = os.path.join(repo, "meshes", "body_triangles_2d.geo")
expect_refused("duplicated_points", mesh_tool,
               mesh_prm(grid, [("gmsh", f"  set file = {body}\n"), ("gmsh", f"  set file = {body}\n")], map5),
               ["duplicated", "body 0", "body 1"])

# 9. a cell that is not an axis-aligned box: refused by talus-mesh for MPM ...
par = write("parallelogram.msh", msh22([(0, 0), (1, 0), (2, 0), (0.3, 1), (1.3, 1), (2.3, 1)],
                                       [(3, 1, 1, [1, 2, 5, 4]), (3, 1, 1, [2, 3, 6, 5])]))
expect_refused("distorted_cell", mesh_tool, mesh_prm(par), ["cell 0", "axis-aligned"])
# ... written with 'allow distorted cells', then refused by talus-explicit
d = os.path.join(work, "distorted_ok")
tv.run_tool(mesh_tool, mesh_prm(par, extra_grid="  set allow distorted cells = true\n"), d, "mesh")
col = open(os.path.join(repo, "parameter_files", "verification", "elastic_column_gravity.prm")).read()


def explicit_prm(grid_file, particle_file, out="out"):
    t = tv.prm_set(col, "grid/source", "file")
    t = tv.prm_set(t, "grid/file", grid_file)
    t = t.replace("set shape                   = box", f"set shape = file\n  set particle file = {particle_file}")
    t = tv.prm_set(t, "boundary conditions/roller", "")
    t = tv.prm_set(t, "boundary conditions/fixed", "0")
    t = tv.prm_set(t, "output/probes", "")
    return tv.prm_set(t, "output/directory", out)


expect_refused("explicit_distorted_grid", explicit,
               explicit_prm(os.path.join(d, "out", "grid.msh"), os.path.join(d, "out", "particles.h5")),
               ["grid/file", "axis-aligned", "MPM"], outputs=("out",))

# 10. talus-explicit: a particle file made for another grid (points outside)
d2 = os.path.join(work, "oedometer_files")
oed = open(os.path.join(repo, "parameter_files", "mesh", "oedometer_2d.prm")).read()
oed = oed.replace("meshes/oedometer_2d.geo", geo).replace("output/mesh/oedometer_2d", "out")
tv.run_tool(mesh_tool, oed, d2, "mesh")
d3 = os.path.join(work, "column_files")
cm = open(os.path.join(repo, "parameter_files", "mesh", "elastic_column_2d.prm")).read()
cm = cm.replace("meshes/", os.path.join(repo, "meshes") + "/").replace("output/mesh/elastic_column_2d", "out")
tv.run_tool(mesh_tool, cm, d3, "mesh")
expect_refused("explicit_particles_outside", explicit,
               explicit_prm(os.path.join(d3, "out", "grid.msh"), os.path.join(d2, "out", "particles.h5")),
               ["material point", "outside the grid"], outputs=("out",))
# 11. talus-explicit: a boundary id the grid file does not have
t = tv.prm_set(explicit_prm(os.path.join(d3, "out", "grid.msh"), os.path.join(d3, "out", "particles.h5")),
               "boundary conditions/fixed", "7")
expect_refused("explicit_missing_boundary_id", explicit, t, ["boundary id 7", "ids present: 0, 1, 2, 3"],
               outputs=("out",))
tv.finish()
