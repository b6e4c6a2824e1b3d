"""Bad input and failing runs of talus-implicit (issue 13): one clear message,
the right exit code, no NaN written.
  * input errors (exit 2, one message starting 'talus-implicit: error:' naming
    the entry, nothing written): a model without a finite-strain form, a zero
    time step, gamma out of range, nu = 0.5, an entry of a feature not built yet,
    mixed u-p without the split Neo-Hookean energy or with a pressure-dependent
    yield (hencky mohr coulomb), in a dynamic run or with an
    iterative solver, a traction with both 'traction' and 'total force';
    the shared 'damping' it cannot honour (local damping; any damping in a
    static run; stiffness damping with mixed u-p) and a pore liquid other than
    drained;
    'geometry = axisymmetric' (on thick_cylinder_axisymmetric.prm beside PRM) in
    3D, with mixed u-p, on a grid reaching x < 0, with a radial gravity, with a
    'total force' traction, restarted with tractions;
  * the pressure on a circle (loads/traction 0/pressure centre, on
    lame_cylinder_plane_strain.prm beside PRM; --check and a run): on a body face,
    with a traction, radius 0, a circle missing the region or crossing it twice,
    a pressure without its centre, with 'geometry = axisymmetric';
  * rigid plates: a force and a displacement, a boundary id the grid lacks, a
    region holding no grid node, the axis held by a wall at every node, two
    plates sharing a node;
  * the rigid footing: its span reversed, with two values in 2D, not a number; normal z in 2D;
    penalty 0; with contact walls on the nodes;
  * contact walls on the nodes: a negative or infinite Coulomb coefficient;
  * contact walls on the points: a misspelt 'contact method', 'points' without
    contact walls, a penalty <= 0 or not a number, a penalty with the node
    method, a negative or malformed Coulomb coefficient, the node method's
    'contact gap'/'contact passes' with points, Coulomb friction with cg amg;
  * the linear solver: mixed u-p with 'cg amg' or 'gmres amg' (allowed: direct, gmres
    block amg), 'gmres block amg' with the displacement formulation;
  * Newton that cannot converge (max iterations 1 with a tolerance no single
    iteration meets): every step is cut back max_cut_backs times, then the run
    stops with exit 3 and says so; series.csv holds only finite values;
  * a singular system (static analysis of a body touching no fixed wall): the
    run stops with exit 3 naming the failed linear solve, no NaN written.
Usage: check_implicit_bad_input.py TOOLS_DIR PRM WORKDIR
"""
import math
import os
import shutil
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
tool = f"{tools}/talus-implicit"
shutil.rmtree(work, ignore_errors=True)
base = tv.prm_set(open(prm_path).read(), "output/directory", "must_not_exist")
points_base = tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"), "boundary conditions/contact method",
                        "points")
footing_base = base
for entry, value in (("rigid footing/enabled", "true"), ("rigid footing/level", "1"),
                     ("rigid footing/lower corner", "0"), ("rigid footing/upper corner", "0.5"),
                     ("rigid footing/velocity", "-0.001")):
    footing_base = tv.prm_set(footing_base, entry, value)


def plate(entries):
    """base with one rigid plate whose entries are `entries` ("entry=value")"""
    t = tv.prm_set(base, "boundary conditions/number of rigid plates", "1")
    return tv.prm_set_args(t, ["boundary conditions/rigid plate 0/" + e for e in entries])


cases = {
    "no finite-strain form": (tv.prm_set(base, "material 0/model", "linear elastic"),
                              ["material 0/model", "linear elastic", "finite-strain", "neo hookean"]),
    "zero time step": (tv.prm_set(base, "time/time step", "0"), ["time/time step", "> 0"]),
    "gamma out of range": (tv.prm_set(base, "implicit/newmark gamma", "0.4"), ["newmark gamma", "0.4"]),
    "incompressible": (tv.prm_set(base, "material 0/neo hookean/poisson ratio", "0.5"), ["poisson ratio", "0.5"]),
    "write grid (not written)": (tv.prm_set(base, "output/write grid", "true"),
                                 ["output/write grid", "not written by talus-implicit"]),
    "mass matrix misspelt": (tv.prm_set(base, "implicit/mass matrix", "consistant"),
                             ["mass matrix", "consistant", "lumped|consistent"]),
    # the shared 'damping' (loads/damping.h) and 'material k/pore liquid' (materials/pore_liquid.h)
    "damping in a static run": (tv.prm_set(base, "damping/viscous damping", "1"),
                                ["damping/viscous damping", "talus-implicit cannot honour it", "dynamic"]),
    "stiffness damping in a static run": (tv.prm_set(base, "damping/stiffness damping", "0.01"),
                                          ["damping/stiffness damping", "dynamic"]),
    "stiffness damping with mixed up": (
        tv.prm_set_args(base, ["implicit/analysis=dynamic", "implicit/formulation=mixed up",
                               "material 0/neo hookean/volumetric energy=split", "damping/stiffness damping=0.01"]),
        ["damping/stiffness damping", "irreducible", "mixed up"]),
    "negative stiffness damping": (tv.prm_set(base, "damping/stiffness damping", "-1"), ["stiffness damping", "-1"]),
    "local damping": (tv.prm_set_args(base, ["implicit/analysis=dynamic", "damping/local damping=0.7"]),
                      ["damping/local damping", "talus-implicit cannot honour it", "allowed: 0"]),
    "coupled pore liquid": (tv.prm_set(base, "material 0/pore liquid/drainage", "coupled"),
                            ["material 0/pore liquid/drainage", "is 'coupled'", "1-phase", "allowed: drained"]),
    "undrained pore liquid": (tv.prm_set(base, "material 0/pore liquid/drainage", "undrained"),
                              ["material 0/pore liquid/drainage", "is 'undrained'"]),
    "static without supports": (tv.prm_set(base, "boundary conditions/fixed", ""), ["boundary conditions", "static",
                                                                                   "singular"]),
    "mixed up without the split energy": (tv.prm_set(base, "implicit/formulation", "mixed up"),
                                          ["material 0/model", "mixed up", "volumetric energy = split"]),
    "mixed up with a pressure-dependent yield": (
        tv.prm_set(tv.prm_set(base, "implicit/formulation", "mixed up"), "material 0/model", "hencky mohr coulomb"),
        ["material 0/model", "mixed up", "hencky mohr coulomb", "j2 plasticity", "pressure"]),
    "f-bar with mixed up": (tv.prm_set(tv.prm_set(tv.prm_set(base, "implicit/formulation", "mixed up"),
                                                  "material 0/neo hookean/volumetric energy", "split"),
                                       "numerics/volumetric stabilisation", "f-bar"),
                            ["numerics/volumetric stabilisation", "irreducible", "mixed up"]),
    "volumetric stabilisation misspelt": (tv.prm_set(base, "numerics/volumetric stabilisation", "fbar"),
                                          ["volumetric stabilisation", "fbar", "none|f-bar"]),
    "f-bar with B-splines": (tv.prm_set(tv.prm_set(base, "numerics/shape function", "quadratic bspline"),
                                        "numerics/volumetric stabilisation", "f-bar"),
                             ["numerics/volumetric stabilisation", "quadratic bspline", "none"]),
    "shape function misspelt": (tv.prm_set(base, "numerics/shape function", "bspline"),
                                ["shape function", "bspline", "linear|quadratic bspline"]),
    "B-splines on a grid 2 cells high": (tv.prm_set(tv.prm_set(base, "numerics/shape function", "quadratic bspline"),
                                                    "grid/cells", "17, 2"),
                                         ["B-spline", "3 cells", "y"]),
    "negligible nodal mass out of range": (tv.prm_set(base, "implicit/negligible nodal mass", "2"),
                                           ["negligible nodal mass", "2"]),
    "negligible mass load limit out of range": (tv.prm_set(base, "implicit/negligible mass load limit", "1.5"),
                                                ["negligible mass load limit", "1.5"]),
    "negative ghost penalty": (tv.prm_set(base, "implicit/ghost penalty", "-1"), ["ghost penalty", "-1"]),
    "ghost penalty with B-splines": (tv.prm_set(tv.prm_set(base, "implicit/ghost penalty", "0.01"),
                                                "numerics/shape function", "quadratic bspline"),
                                     ["implicit/ghost penalty", "linear", "allowed with 'quadratic bspline': 0"]),
    "carry start imbalance not a bool": (tv.prm_set(base, "implicit/carry start imbalance", "maybe"),
                                         ["carry start imbalance", "maybe"]),
    "unknown direct package": (tv.prm_set(base, "linear solver/direct package", "superlu"),
                               ["direct package", "superlu"]),
    "moving velocity regions with restart": (
        tv.prm_set(tv.prm_set(base, "implicit/velocity regions follow", "true"), "checkpoint/restart", "if available"),
        ["implicit/velocity regions follow", "restart"]),
    "mixed up with cg amg": (tv.prm_set(tv.prm_set(base, "implicit/formulation", "mixed up"), "linear solver/method",
                                        "cg amg"), ["linear solver/method", "direct", "gmres block amg"]),
    "mixed up with gmres amg": (tv.prm_set(tv.prm_set(base, "implicit/formulation", "mixed up"),
                                           "linear solver/method", "gmres amg"),
                                ["linear solver/method", "direct", "gmres block amg"]),
    "gmres block amg without mixed up": (tv.prm_set(base, "linear solver/method", "gmres block amg"),
                                         ["linear solver/method", "mixed up", "direct | cg amg | gmres amg"]),
    "traction and total force": (tv.prm_set(tv.prm_set(tv.prm_set(base, "loads/number of tractions", "1"),
                                                       "loads/traction 0/traction", "0, -1"),
                                            "loads/traction 0/total force", "0, -1"),
                                 ["loads/traction 0/total force", "not both"]),
    "velocity of a body": (tv.prm_set(tv.prm_set(base, "loads/number of velocity conditions", "1"),
                                      "loads/velocity 0/apply to", "body"),
                           ["loads/velocity 0/apply to", "boundary | region"]),
    "contact friction negative (nodes)": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                                     "boundary conditions/contact friction", "-0.3"),
                                          ["boundary conditions/contact friction", "'-0.3'",
                                           "no slip | frictionless | a Coulomb coefficient mu >= 0"]),
    "contact friction infinite (nodes)": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                                     "boundary conditions/contact friction", "inf"),
                                          ["boundary conditions/contact friction", "'inf'"]),
    "contact friction misspelt": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                             "boundary conditions/contact friction", "noslip"),
                                  ["boundary conditions/contact friction", "noslip"]),
    "contact on a missing face": (tv.prm_set(base, "boundary conditions/contact", "7"),
                                  ["boundary conditions/contact", "7"]),
    "contact on a fixed wall": (tv.prm_set(base, "boundary conditions/contact", "0"),
                                ["boundary conditions/contact", "also fixed"]),
    "contact with load balancing": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                               "load balancing/interval", "10"),
                                    ["load balancing/interval", "contact walls"]),
    # contact walls on the points (contact method = points)
    "contact method misspelt": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                           "boundary conditions/contact method", "point"),
                                ["boundary conditions/contact method", "'point'", "nodes | points"]),
    "contact method points without walls": (tv.prm_set(base, "boundary conditions/contact method", "points"),
                                            ["boundary conditions/contact method", "needs contact walls"]),
    "contact penalty zero": (tv.prm_set(points_base, "boundary conditions/contact penalty", "0"),
                             ["boundary conditions/contact penalty", "'0'", "> 0"]),
    "contact penalty not a number": (tv.prm_set(points_base, "boundary conditions/contact penalty", "stiff"),
                                     ["boundary conditions/contact penalty", "'stiff'"]),
    "contact penalty on nodes": (tv.prm_set(tv.prm_set(base, "boundary conditions/contact", "2"),
                                            "boundary conditions/contact penalty", "10"),
                                 ["boundary conditions/contact penalty", "contact method = points"]),
    "contact friction negative": (tv.prm_set(points_base, "boundary conditions/contact friction", "-0.2"),
                                  ["boundary conditions/contact friction", "'-0.2'", "mu >= 0"]),
    "contact friction with trailing text": (tv.prm_set(points_base, "boundary conditions/contact friction", "0.3x"),
                                            ["boundary conditions/contact friction", "'0.3x'"]),
    "contact gap on points": (tv.prm_set(points_base, "boundary conditions/contact gap", "0.2"),
                              ["boundary conditions/contact gap", "contact method = nodes"]),
    "contact passes on points": (tv.prm_set(points_base, "boundary conditions/contact passes", "3"),
                                 ["boundary conditions/contact passes", "contact method = nodes"]),
    "coulomb friction with cg amg": (tv.prm_set(tv.prm_set(points_base, "boundary conditions/contact friction", "0.3"),
                                                "linear solver/method", "cg amg"),
                                     ["linear solver/method", "non-symmetric", "direct"]),
    # the rigid footing on the points
    "footing span reversed": (tv.prm_set(footing_base, "rigid footing/upper corner", "-1"),
                              ["rigid footing/upper corner", "lower corner"]),
    "footing span with two values in 2D": (tv.prm_set(footing_base, "rigid footing/lower corner", "0, 0"),
                                           ["rigid footing/lower corner", "1 value"]),
    "footing normal z in 2D": (tv.prm_set(footing_base, "rigid footing/normal axis", "z"),
                               ["rigid footing/normal axis", "x | y"]),
    "footing penalty zero": (tv.prm_set(footing_base, "rigid footing/penalty", "0"),
                             ["rigid footing/penalty", "> 0"]),
    "footing span not a number": (tv.prm_set(footing_base, "rigid footing/upper corner", "half"),
                                  ["rigid footing/upper corner", "half"]),
    "footing with contact walls on the nodes": (tv.prm_set(footing_base, "boundary conditions/contact", "3"),
                                                ["rigid footing/enabled", "contact method = points"]),
    # rigid plates (issue 37): both controls, a boundary id the grid lacks, a region
    # between grid nodes, a plate whose axis a wall holds at every node
    "plate with a force and a displacement": (plate(["total force=-1", "displacement=-0.01"]),
                                              ["boundary conditions/rigid plate 0", "not both"]),
    "plate on a missing boundary": (plate(["boundary id=7", "total force=-1"]),
                                    ["boundary conditions/rigid plate 0/boundary id", "does not exist"]),
    "plate holding no node": (plate(["apply to=region", "region lower corner=1.1, 1", "region upper corner=1.2, 1",
                                     "total force=-1"]),
                              ["boundary conditions/rigid plate 0", "holds no grid node"]),
    "plate held by a wall everywhere": (plate(["boundary id=0", "direction=x", "total force=-1"]),
                                        ["boundary conditions/rigid plate 0", "a fixed/roller wall holds its direction "
                                         "component at every one of its", "cannot move along x"]),
    "plates sharing a node": (
        tv.prm_set_args(plate(["apply to=region", "region lower corner=1, 1", "region upper corner=2, 1",
                               "total force=-1"]),
                        ["boundary conditions/number of rigid plates=2"] +
                        ["boundary conditions/rigid plate 1/" + e for e in
                         ["apply to=region", "region lower corner=2, 1", "region upper corner=3, 1", "total force=-1"]]),
        ["boundary conditions/rigid plate 1", "shares 1 node(s) with another rigid plate"]),
    "velocity on a missing boundary": (tv.prm_set(tv.prm_set(base, "loads/number of velocity conditions", "1"),
                                                  "loads/velocity 0/boundary id", "7"),
                                       ["loads/velocity 0/boundary id", "does not exist"]),
}
# axisymmetry (thick_cylinder_axisymmetric.prm beside PRM): what it does not cover is refused
axi = tv.prm_set(open(os.path.join(os.path.dirname(prm_path), "thick_cylinder_axisymmetric.prm")).read(),
                 "output/directory", "must_not_exist")
axi_3d = axi
for entry, value in (("dimension", "3"), ("grid/lower corner", "0, 0, 0"), ("grid/upper corner", "2.5, 0.5, 0.5"),
                     ("grid/cells", "10, 2, 2"), ("gravity/acceleration", "0, 0, 0"),
                     ("body 0/lower corner", "1, 0, 0"), ("body 0/upper corner", "2, 0.5, 0.5"),
                     ("loads/traction 0/traction", "1000, 0, 0")):
    axi_3d = tv.prm_set(axi_3d, entry, value)
cases.update({
    "axisymmetric in 3D": (axi_3d, ["implicit/geometry", "2D"]),
    "axisymmetric mixed up": (tv.prm_set(tv.prm_set(axi, "implicit/formulation", "mixed up"),
                                         "material 0/neo hookean/volumetric energy", "split"),
                              ["implicit/geometry", "irreducible"]),
    "B-splines with axisymmetric": (tv.prm_set(axi, "numerics/shape function", "quadratic bspline"),
                                    ["numerics/shape function", "axisymmetric", "linear"]),
    "f-bar with axisymmetric": (tv.prm_set(axi, "numerics/volumetric stabilisation", "f-bar"),
                                ["numerics/volumetric stabilisation", "axisymmetric", "none"]),
    "axisymmetric grid below x = 0": (tv.prm_set(axi, "grid/lower corner", "-0.5, 0"),
                                      ["implicit/geometry", "lower corner x >= 0"]),
    "axisymmetric radial gravity": (tv.prm_set(axi, "gravity/acceleration", "1, -9.81"),
                                    ["gravity/acceleration", "axis"]),
    "axisymmetric total force": (tv.prm_set(tv.prm_set(axi, "loads/traction 0/traction", "0, 0"),
                                            "loads/traction 0/total force", "1000, 0"),
                                 ["loads/traction 0", "total force", "axisymmetric"]),
    "axisymmetric restart with tractions": (tv.prm_set(axi, "checkpoint/restart", "if available"),
                                            ["checkpoint/restart", "axisymmetric"]),
})
# the pressure on a circle (loads/traction k/pressure centre; lame_cylinder_plane_strain.prm beside
# PRM), refused with --check and with a run alike
lame = open(os.path.join(os.path.dirname(prm_path), "lame_cylinder_plane_strain.prm")).read()
tr = "loads/traction 0/"
for label, settings, needles in (
        ("pressure on a body face", [tr + "apply to=body face"], [tr + "apply to", "region"]),
        ("pressure and traction", [tr + "traction=1, 0"], [tr + "pressure centre", "not both"]),
        ("pressure radius 0", [tr + "pressure radius=0"], [tr + "pressure radius", "> 0"]),
        ("circle missing the region", [tr + "pressure radius=5"], [tr + "pressure radius", "does not pass"]),
        ("circle in two arcs", [tr + "region lower corner=-0.5, -1.5", tr + "region upper corner=0.5, 1.5"],
         [tr + "region lower corner", "2 separate arcs"]),
        ("pressure without centre", [tr + "pressure centre="], [tr + "pressure", "without 'pressure centre'"]),
        ("pressure with axisymmetric", ["implicit/geometry=axisymmetric"],
         [tr + "pressure centre", "axisymmetric"])):
    tv.check_refused(tool, tv.prm_set_args(lame, settings), label, needles, os.path.join(work, label.replace(" ", "_")))
for name, (text, needles) in cases.items():
    rc, out, err = tv.run_tool(tool, text, work, name.replace(" ", "_"), expect_rc=None)
    msg = err.strip()
    ok = rc == 2 and all(n in msg for n in needles) and msg.count("\n") < 6 and msg.startswith("talus-implicit: error:")
    tv.check(ok, f"{name}: exit {rc}, message: {msg[:300]}")
tv.check(not os.path.exists(os.path.join(work, "must_not_exist")), "input errors wrote nothing")


def finite_series(path):
    s = tv.read_csv(path)
    return all(math.isfinite(v) for col in s.values() for v in col), len(s["time"])


# Newton that cannot converge: exit 3 after the cut-backs, finite series
text = tv.prm_set(base, "output/directory", "newton")
text = tv.prm_set(text, "newton/max iterations", "1")
text = tv.prm_set(text, "newton/residual relative", "1e-14")
text = tv.prm_set(text, "newton/residual absolute", "0")
rc, out, err = tv.run_tool(tool, text, work, "newton_fails", expect_rc=None)
tv.check(rc == 3, f"Newton failure: exit {rc} (expected 3)")
tv.check("cut back" in (out + err) and "max iterations" in (out + err), "the log reports the cut-backs and why")
ok, rows = finite_series(f"{work}/newton/series.csv")
tv.check(ok, f"Newton failure: series.csv ({rows} rows) holds only finite values")

# singular system: the only support is a roller on the right wall, which the body
# does not touch -> the tangent has rigid-body modes
text = tv.prm_set(base, "output/directory", "out_s")
text = tv.prm_set(text, "boundary conditions/fixed", "")
text = tv.prm_set(text, "boundary conditions/roller", "1")
rc, out, err = tv.run_tool(tool, text, work, "singular", expect_rc=None)
tv.check(rc == 3, f"singular system: exit {rc} (expected 3)")
tv.check("linear system is singular" in (out + err) and "boundary conditions" in (out + err),
         f"singular system: the log names the failed solve: {(out + err)[-400:]}")
ok, rows = finite_series(f"{work}/out_s/series.csv")
tv.check(ok, f"singular system: series.csv ({rows} rows) holds only finite values")
tv.finish()
