"""talus-semi-implicit with a body read from a talus-mesh particle file == the box body (issue 14).

The saturated column of parameter_files/verification/semi_implicit_hydrostatic.prm
(box grid 3 x 44 cells of 0.025 m, a box body of 2 x 2 points per cell, phase
saturated, geostatic start) is made again with talus-mesh from
parameter_files/mesh/semi_column_2d.prm (gmsh, meshes/semi_column_2d.geo: the
grid cells of the group "column" filled with 2 x 2 regular points), and
talus-semi-implicit runs the scene with `shape = file` in place of the box.
Both sets of the saturated body (soil and water) are seeded from the file's rows.
Checked:
  - the same number of soil and water points as the box body (480 + 480);
  - the final soil and water points (matched by their initial position x - u)
    equal the box run's to round-off: max |difference| <= 1e-10 x the scale of
    the quantity: H for positions, g t_end for velocities (the column is at rest:
    its velocities are round-off in both runs, so their own size is no scale),
    the largest |sigma'_yy| for stresses, rho_w g H for pore pressures, 1 for the
    porosity (the points enter in another order, so sums are taken in another
    order);
  - the same on 2 ranks (talus-semi-implicit under mpirun -np 2);
  - the single-point variant (point sets = single) from the file equals its box
    run to the same tolerance;
  - the material of each point is its file row's, not the body's 'material'
    entry: a scene with two materials, the body's entry 0 (another porosity and
    density) and the file's rows 1 (the column's material), equals the box run;
  - the hydrostatic answer of the file run: pore pressure within 1 % of
    rho_w g d (as check_semi_hydrostatic.py requires of the box scene);
  - bad input: a file body id the file does not have, and a particle file whose
    material id exceeds the scene's materials: exit 2, a message naming the
    entry, no output directory.
Usage: check_semi_file_body.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import shutil
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
semi = os.path.join(tools, "talus-semi-implicit")
g, H, rw = 9.81, 1.0, 1000.0

mesh_prm = open(os.path.join(repo, "parameter_files", "mesh", "semi_column_2d.prm")).read()
mesh_prm = mesh_prm.replace("meshes/", os.path.join(repo, "meshes") + "/")
tv.run_tool(os.path.join(tools, "talus-mesh"), mesh_prm.replace("output/mesh/semi_column_2d", "files"), work, "mesh")
box = open(os.path.join(repo, "parameter_files", "verification", "semi_implicit_hydrostatic.prm")).read()


def file_scene(text):
    old = "set shape                   = box"
    assert old in text
    return text.replace(old, f"set shape = file\n  set particle file = {work}/files/particles.h5")


def run(name, text, np=1):
    tv.run_tool(semi, tv.prm_set(text, "output/directory", name), work, name, np=np)
    return {s: tv.read_csv(f"{work}/{name}/{s}_final.csv") for s in ("soil", "water")}


def by_initial_position(t):
    keys = [(round(x - ux, 9), round(y - uy, 9))
            for x, y, ux, uy in zip(t["pos_x"], t["pos_y"], t["displacement_x"], t["displacement_y"])]
    return {k: i for i, k in enumerate(keys)}


def difference(a, b, scales):
    """max over columns of max |a - b| / scale, points matched by initial position"""
    ia, ib = by_initial_position(a), by_initial_position(b)
    if set(ia) != set(ib):
        return float("inf")
    return max(max(abs(a[c][ia[k]] - b[c][ib[k]]) for k in ia) / scale for c, scale in scales.items())


end_time = 0.15


def scales_of(box_soil):
    s_ref = max(abs(v) for v in box_soil["stress_yy"])
    v_ref = g * end_time
    return {"soil": {"pos_x": H, "pos_y": H, "velocity_x": v_ref, "velocity_y": v_ref, "stress_xx": s_ref,
                     "stress_yy": s_ref, "stress_xy": s_ref, "porosity": 1.0},
            "water": {"pos_x": H, "pos_y": H, "velocity_x": v_ref, "velocity_y": v_ref, "pore_pressure": rw * g * H}}


def compare(label, a, b):
    for s in ("soil", "water"):
        n_a, n_b = len(a[s]["pos_x"]), len(b[s]["pos_x"])
        tv.check(n_a == n_b == 480, f"{label}: {s} points: box {n_a}, from the file {n_b} (480)")
        d = difference(a[s], b[s], scales_of(a["soil"])[s])
        tv.check(d <= 1e-10, f"{label}: {s} points equal the box run's to {d:.2e} (<= 1e-10)")


base = tv.prm_set(box, "time/end time", str(end_time))
boxed = run("box", base)
filed = run("file", file_scene(base))
compare("double point, 1 rank", boxed, filed)
compare("double point, 2 ranks", boxed, run("file_np2", file_scene(base), np=2))
single = tv.prm_set(base, "semi implicit/point sets", "single")
compare("single point", run("box_single", single), run("file_single", file_scene(single)))

# two materials: the entry says 0, the file's rows say 1 (the column's material)
mesh_m1 = mesh_prm.replace("output/mesh/semi_column_2d", "files_m1").replace("set material             = 0",
                                                                              "set material             = 1")
tv.run_tool(os.path.join(tools, "talus-mesh"), mesh_m1, work, "mesh_m1")
start = base.index("subsection material 0")
end = base.index("\nend\n", base.index("subsection pore liquid", start)) + len("\nend\n")
column_material = base[start:end]
other = column_material.replace("set porosity               = 0.3", "set porosity               = 0.45")
other = other.replace("set density = 2650", "set density = 2000")
assert other != column_material and other.count("0.45") == 1 and other.count("2000") == 1
two = base.replace("set number of materials = 1", "set number of materials = 2")
two = two.replace(column_material, other + "\n" + column_material.replace("material 0", "material 1"))
two = file_scene(two).replace(f"{work}/files/", f"{work}/files_m1/")
compare("materials from the file's rows", boxed, run("file_m1", two))

w = filed["water"]
ep = max(abs(p + rw * g * (H - y)) for p, y in zip(w["pore_pressure"], w["pos_y"])) / (rw * g * H)
tv.check(ep < 0.01, f"file body: pore pressure within 1 % of rho_w g d (error {ep:.2e})")

# bad input: exit 2, the entry named, nothing written
text = file_scene(base)
_, out, err = tv.run_tool(semi, tv.prm_set(tv.prm_set(text, "body 0/file body id", "3"), "output/directory",
                                           "bad_rows"), work, "bad_rows", expect_rc=2)
tv.check("body 0/file body id" in out + err and "no material point with body id 3" in out + err,
         "a file body id without rows: exit 2, 'body 0/file body id' named")
tv.check(not os.path.exists(f"{work}/bad_rows"), "a file body id without rows: no output directory")
# a particle file whose points use material 1 in a scene of one material
_, out, err = tv.run_tool(semi, tv.prm_set(text.replace(f"{work}/files/", f"{work}/files_m1/"),
                                           "output/directory", "bad_material"), work, "bad_material", expect_rc=2)
tv.check("body 0/particle file" in out + err and "material id 1" in out + err,
         "a file's material id beyond the scene's materials: exit 2, 'body 0/particle file' named")
tv.check(not os.path.exists(f"{work}/bad_material"), "a file's material id beyond the scene's: no output directory")
tv.finish()
