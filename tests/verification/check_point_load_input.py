"""Bad point-load input in every family (issue 37): the entries of
'loads/point load k' (declared and parsed once, loads/settings.cc) are refused
by talus-explicit, talus-implicit and talus-semi-implicit alike, with exit 2, a
message naming the entry and what is allowed, and nothing written (no output
directory), both with --check and with a run; and what one family cannot
honour (talus-implicit: a point load with geometry = axisymmetric; talus-
semi-implicit: a point load on a body of phase water) is refused the same way.
The base of each family is its .prm of the point-load block
(parameter_files/verification/point_load/block_<family>.prm) with the fragment
block.inc pasted in place of its include line.
Usage: check_point_load_input.py TOOLS_DIR PRM_DIR WORKDIR
"""
import os
import sys

import talus_verify as tv

tools, prm_dir, work = sys.argv[1], sys.argv[2], sys.argv[3]
scene = os.path.join(prm_dir, "verification", "point_load")
fragment = open(os.path.join(scene, "block.inc")).read()
pl = "loads/point load 0/"
shared = {
    "position outside the grid": ({pl + "position": "0.5, 3"}, ["loads/point load 0/position", "outside the grid"]),
    "position with one number": ({pl + "position": "0.5"}, ["loads/point load 0/position", "needs exactly 2"]),
    "force with three numbers": ({pl + "force": "0, -100, 0"}, ["loads/point load 0/force", "needs exactly 2"]),
    "force missing": ({pl + "force": ""}, ["loads/point load 0/force", "needs exactly 2"]),
    "bad time function": ({pl + "time function": "wobble 3"}, ["loads/point load 0/time function"]),
    "body that does not exist": ({pl + "body": "4"}, ["loads/point load 0/body", "not a body", "any"]),
    "too many point loads": ({"loads/number of point loads": "17"}, ["number of point loads"]),
}
own = {
    "talus-implicit": {
        "axisymmetric": ({"implicit/geometry": "axisymmetric"}, ["loads/point load 0", "axisymmetric", "allowed"]),
    },
    "talus-semi-implicit": {
        "water body": ({"body 0/phase": "water", "body 1/phase": "soil", pl + "body": "0",
                        "number of bodies": "2", "body 1/shape": "box", "body 1/lower corner": "0, 0",
                        "body 1/upper corner": "1, 0.5"},
                       ["loads/point load 0/body", "phase = water"]),
    },
}
for tool, name in [("talus-explicit", "block_explicit.prm"), ("talus-implicit", "block_implicit.prm"),
                   ("talus-semi-implicit", "block_semi_implicit.prm")]:
    base = open(os.path.join(scene, name)).read().replace("include block.inc", fragment)
    for label, (settings, expected) in list(shared.items()) + list(own.get(tool, {}).items()):
        text = base
        for k, v in settings.items():
            text = tv.prm_set(text, k, v)
        tv.check_refused(os.path.join(tools, tool), text, label, expected,
                         os.path.join(work, tool, label.replace(" ", "_")))
tv.finish()
