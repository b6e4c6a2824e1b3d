"""Bad rigid-plate input in every family (issue 37): the shared entries of
'boundary conditions/rigid plate k' (loads/rigid_plate.cc, scene_checks.cc)
are refused by talus-explicit, talus-implicit and talus-semi-implicit alike,
with exit 2, a message naming the entry and what is allowed, and nothing
written (no output directory), both with --check and with a run. The base of
each family is its .prm of the shared plate scene
(parameter_files/verification/rigid_plate/layer_<family>.prm) with the
fragment layer.inc pasted in place of its include line.
Usage: check_rigid_plate_input.py TOOLS_DIR PRM_DIR WORKDIR
"""
import os
import sys

import talus_verify as tv

tools, prm_dir, work = sys.argv[1], sys.argv[2], sys.argv[3]
scene = os.path.join(prm_dir, "verification", "rigid_plate")
fragment = open(os.path.join(scene, "layer.inc")).read()
plate = "boundary conditions/rigid plate 0/"
mutations = {
    "force and displacement": ({plate + "displacement": "-0.01"}, ["rigid plate 0", "not both"]),
    "neither force nor displacement": ({plate + "total force": ""}, ["rigid plate 0", "total force", "displacement"]),
    "boundary id the box grid lacks": ({plate + "boundary id": "9"}, ["rigid plate 0/boundary id", "does not exist"]),
    "region outside the grid": ({plate + "apply to": "region", plate + "region lower corner": "5, 5",
                                 plate + "region upper corner": "6, 6"}, ["rigid plate 0", "outside the grid"]),
    "region upside down": ({plate + "apply to": "region", plate + "region lower corner": "0, 1",
                            plate + "region upper corner": "1, 0.5"}, ["rigid plate 0/region upper corner"]),
    "direction z in 2D": ({plate + "direction": "z"}, ["direction", "x|y"]),
    "too many plates": ({"boundary conditions/number of rigid plates": "5"}, ["number of rigid plates"]),
    "unknown drainage": ({plate + "drainage": "leaky"}, ["drainage", "impermeable|permeable"]),
    "bad time function": ({plate + "time function": "wobble 3"}, ["rigid plate 0/time function"]),
    "force not a number": ({plate + "total force": "heavy"}, ["rigid plate 0/total force"]),
}
for tool, name in [("talus-explicit", "layer_explicit.prm"), ("talus-implicit", "layer_implicit.prm"),
                   ("talus-semi-implicit", "layer_semi_implicit.prm")]:
    base = open(os.path.join(scene, name)).read().replace("include layer.inc", fragment)
    for label, (settings, expected) in mutations.items():
        text = base
        for k, v in settings.items():
            text = tv.prm_set(text, k, v)
        tv.check_refused(os.path.join(tools, tool), text, label, expected,
                         os.path.join(work, tool, label.replace(" ", "_")))
tv.finish()
