"""Bad input to talus-explicit gives one clear message and exit code 2, and no output.

Usage: check_bad_input.py TOOL PRM WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)  # "nothing written" is judged on a fresh directory
base = tv.prm_set(open(prm_path).read(), "output/directory", "must_not_exist")
lines = base.splitlines()

cases = {
    "unknown entry": (base.replace("set end time", "set end tiem", 1), ["end tiem", "Line"]),
    "wrong type": (tv.prm_set(base, "time/courant number", "fast"), ["courant number", "fast", "Line"]),
    "out of range": (tv.prm_set(base, "time/courant number", "3"), ["courant number", "0...1"]),
    "unknown model": (tv.prm_set(base, "material 0/model", "granite"), ["granite", "linear elastic"]),
    "bad poisson": (tv.prm_set(base, "material 0/linear elastic/poisson ratio", "0.5"), ["poisson ratio", "0.5"]),
    "undefined material": (tv.prm_set(base, "body 0/material", "3"), ["body 0/material", "not defined"]),
    "wrong vector length": (tv.prm_set(base, "gravity/acceleration", "0, 0, -9.81"), ["gravity/acceleration", "2"]),
    "body outside grid": (tv.prm_set(tv.prm_set(base, "body 0/lower corner", "5, 5"), "body 0/upper corner", "6, 6"),
                          ["body 0", "no material point"]),
    "unknown boundary id": (tv.prm_set(base, "boundary conditions/roller", "2, 3, 9"), ["boundary id 9"]),
    # issue 16: a body partly outside the grid (y up to 0.05 in a grid ending at 0.03125) is refused,
    # naming the body, the coordinate and the grid's extent; so are balls and polygons
    "box partly outside grid": (tv.prm_set(base, "body 0/upper corner", "1, 0.05"),
                                ["body 0", "upper corner", "y = 0.05", "y from 0 to 0.03125", "clip to grid"]),
    "ball partly outside grid": (tv.prm_set(tv.prm_set(tv.prm_set(base, "body 0/shape", "ball"), "body 0/center",
                                                       "1.2, 0.015"), "body 0/radius", "0.1"),
                                 ["body 0", "center + radius", "x = 1.3", "x from 0 to 1.25"]),
    "polygon partly outside grid": (tv.prm_set(tv.prm_set(base, "body 0/shape", "polygon"), "body 0/vertices",
                                               "-0.1, 0; 1, 0; 1, 0.03"),
                                    ["body 0", "vertices", "x = -0.1", "x from 0 to 1.25"]),
    # issue 16: an output directory that cannot be created (root may write everywhere but /proc)
    "output directory cannot be created": (tv.prm_set(base, "output/directory", "/proc/talus_x"),
                                           ["output/directory", "/proc/talus_x", "cannot be created"]),
    # issue 16: a valid integer is not an 'id'; a grid too large for the machine names the memory
    "grid too large for the memory": (tv.prm_set(base, "grid/cells", "100000, 100000"),
                                      ["grid/cells", "1e+10 cells", "need about", "available"]),
    "cells not an integer": (tv.prm_set(base, "grid/cells", "40.5, 1"), ["grid/cells", "'40.5'", "positive integer"]),
    "unknown subsection": (base + "subsection nonsense\n  set a = 1\nend\n", ["nonsense"]),
    # an initial velocity function with an undefined constant: one message, ours (deal.II 9.4's
    # FunctionParser prints muparser's diagnosis to std::cerr first; talus keeps it out)
    "undefined function constant": ("\n".join(l for l in lines if "function constants" not in l) + "\n",
                                    ["body 0/initial velocity function", "v0"]),
}
# numerics/velocity transfer = apic with the passes it is not available with (issue 12; load
# balancing, tractions, point loads, friction and body velocities are allowed since issue 38:
# check_apic_features.py): refused with the entry named
apic = tv.prm_set(base, "numerics/velocity transfer", "apic")
apic_bs = tv.prm_set(tv.prm_set(tv.prm_set(apic, "numerics/shape function", "quadratic bspline"), "grid/cells", "40, 3"),
                     "grid/upper corner", "1.25, 0.09375")
cases.update({
    "apic with mpm-mixed": (tv.prm_set(apic_bs, "numerics/integration", "mpm-mixed"),
                            ["numerics/integration", "velocity transfer = apic"]),
    "apic with fem": (tv.prm_set(apic_bs, "numerics/integration", "fem"), ["numerics/integration", "velocity transfer = apic"]),
    "apic with linear shape functions": (apic, ["numerics/velocity transfer", "quadratic bspline"]),
    "unknown velocity transfer": (tv.prm_set(base, "numerics/velocity transfer", "pic"),
                                  ["velocity transfer", "pic", "flip|apic"]),
})
# APIC with contact runs (each body its own v^L_b), but not with a prescribed velocity of a body
# (its re-projection of v_p, C_p uses the combined field): the sliding block of the contact checks
sliding = open(os.path.join(os.path.dirname(prm_path), "block_sliding_contact.prm")).read()
sliding = tv.prm_set_args(sliding, ["output/directory=must_not_exist", "numerics/shape function=quadratic bspline",
                                    "numerics/velocity transfer=apic", "contact/pairs=0, 1, 0.3, 0",
                                    "loads/number of velocity conditions=1", "loads/velocity 0/apply to=body",
                                    "loads/velocity 0/body=1", "loads/velocity 0/velocity=0, 0"])
cases["apic with contact and a body velocity"] = (sliding, ["loads/velocity k/apply to", "apply to = body",
                                                            "velocity transfer = apic", "APIC with contact"])
# contact moves every body with its own nodal fields: a rigid plate's balance sums the combined field
plate = tv.prm_set_args(open(os.path.join(os.path.dirname(prm_path), "block_sliding_contact.prm")).read(),
                        ["output/directory=must_not_exist", "boundary conditions/number of rigid plates=1"])
plate = plate.replace("subsection boundary conditions\n", """subsection boundary conditions
  subsection rigid plate 0
    set apply to    = boundary
    set boundary id = 3
    set direction   = y
    set total force = -1e3
  end
""", 1)
cases["rigid plate with contact"] = (plate, ["boundary conditions/rigid plate 0", "contact pairs",
                                             "Contact and nodal loads"])
# numerics/volumetric stabilisation (issue 38): modified f-bar has no b_e to scale in the rate
# update; f-bar with the passes that replace the volume change themselves
fbar = tv.prm_set(base, "numerics/volumetric stabilisation", "f-bar")
cases.update({
    "modified f-bar": (tv.prm_set(base, "numerics/volumetric stabilisation", "modified f-bar"),
                       ["numerics/volumetric stabilisation", "modified f-bar", "allowed: none, f-bar"]),
    "f-bar with strain smoothing": (tv.prm_set(fbar, "numerics/strain smoothing", "nodal"),
                                    ["numerics/strain smoothing", "volumetric stabilisation = f-bar"]),
    "f-bar with mpm-mixed": (tv.prm_set(fbar, "numerics/integration", "mpm-mixed"),
                             ["numerics/integration", "volumetric stabilisation = f-bar"]),
})
# rigid plates (issue 37): each refused before any output, naming the plate
plate = tv.prm_set(base, "boundary conditions/number of rigid plates", "1")
plate = tv.prm_set(plate, "boundary conditions/rigid plate 0/boundary id", "1")
plate = tv.prm_set(plate, "boundary conditions/rigid plate 0/direction", "x")
plate = tv.prm_set(plate, "boundary conditions/rigid plate 0/total force", "-1")
region = tv.prm_set(tv.prm_set(plate, "boundary conditions/rigid plate 0/apply to", "region"),
                    "boundary conditions/rigid plate 0/region lower corner", "0.01, 0.005")
cases.update({
    "plate with a force and a displacement": (
        tv.prm_set(plate, "boundary conditions/rigid plate 0/displacement", "-1e-3"),
        ["boundary conditions/rigid plate 0", "not both"]),
    "plate on a boundary id the grid lacks": (
        tv.prm_set(plate, "boundary conditions/rigid plate 0/boundary id", "7"),
        ["boundary conditions/rigid plate 0/boundary id", "boundary id 7"]),
    "plate holding no node": (
        tv.prm_set(region, "boundary conditions/rigid plate 0/region upper corner", "0.02, 0.01"),
        ["boundary conditions/rigid plate 0", "holds no grid node"]),
    "plate whose axis a wall holds everywhere": (
        tv.prm_set(tv.prm_set(plate, "boundary conditions/rigid plate 0/boundary id", "3"),
                   "boundary conditions/rigid plate 0/direction", "y"),
        ["boundary conditions/rigid plate 0", "holds its direction component at every one of its 41 node(s)"]),
})
# the shared 'damping' (loads/damping.h; issue 37): stiffness damping needs a stiffness matrix
cases.update({
    "stiffness damping": (tv.prm_set(base, "damping/stiffness damping", "1e-3"),
                          ["damping/stiffness damping", "is 0.001", "talus-explicit cannot honour it", "allowed: 0"]),
    "local damping 1": (tv.prm_set(base, "damping/local damping", "1"), ["damping/local damping", "[0, 1)"]),
    "stage stiffness damping": (tv.prm_set(tv.prm_set(base, "number of stages", "1"),
                                           "stage 0/damping/stiffness damping", "1e-3"),
                                ["stiffness damping"]),
})
for name, (text, needles) in cases.items():
    rc, out, err = tv.run_tool(tool, text, work, name.replace(" ", "_"), expect_rc=None)
    msg = err.strip()
    ok = rc == 2 and all(n in msg for n in needles) and msg.count("\n") < 6 and \
        msg.startswith(os.path.basename(tool) + ": error:")
    tv.check(ok, f"{name}: exit {rc}, message: {msg[:300]}")
    if name in ("output directory cannot be created", "box partly outside grid", "grid too large for the memory",
                "stiffness damping"):
        # --check refuses it too (before any heavy work)
        prm = os.path.join(work, name.replace(" ", "_") + ".prm")
        p = subprocess.run([os.path.abspath(tool), "--check", prm], cwd=work, capture_output=True, text=True,
                           env=tv.child_env())
        tv.check(p.returncode == 2 and needles[0] in p.stderr, f"{name}: --check exit {p.returncode}")
tv.check(not any(n.startswith(".talus-probe") for n in os.listdir(work)), "the writability probe leaves nothing")

# 'clip to grid = true' runs the partly outside body, and the log says what was dropped: the body
# y in [0, 0.05] with 2 points per direction on cells of 0.03125 m has sub-cell centres at
# y = 0.0078125 + k 0.015625, k = 0..2 inside the body; k = 2 (y = 0.0390625) lies beyond the grid:
# 40 cells x 2 = 80 positions of 0.015625^2 m^2 each are dropped
clip = tv.prm_set(tv.prm_set(tv.prm_set(base, "body 0/upper corner", "1.25, 0.05"), "body 0/clip to grid", "true"),
                  "time/end time", "1e-5")
clip = tv.prm_set(clip, "output/directory", os.path.join(work, "clip_out"))
rc, out, err = tv.run_tool(tool, clip, work, "clip", expect_rc=None)
m = re.search(r"clip to grid: (\S+) seeding positions outside the grid dropped, volume lost ([0-9.eE+-]+)", out)
tv.check(rc == 0 and m is not None and float(m.group(1)) == 80 and abs(float(m.group(2)) - 80 * 0.015625 ** 2) < 1e-12,
         f"clip to grid = true: exit {rc}, log: {m.group(0) if m else (out + err)[-300:]}")

rc2 = os.system(f"{os.path.abspath(tool)} /nonexistent/file.prm > /dev/null 2>&1") >> 8
tv.check(rc2 == 2, f"missing parameter file: exit {rc2}")
rc3 = os.system(f"{os.path.abspath(tool)} --bogus > /dev/null 2>&1") >> 8
tv.check(rc3 == 2, f"unknown option: exit {rc3}")
tv.check(not os.path.exists(os.path.join(work, "must_not_exist")) and not os.path.exists("/proc/talus_x"),
         "no output written for any broken input")
tv.finish()
