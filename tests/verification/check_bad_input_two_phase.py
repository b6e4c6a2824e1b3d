"""Bad input of the liquid / 2-phase entries (issue 5, issue 12): each case must
exit with code 2 before any output, naming the entry.
Usage: check_bad_input_two_phase.py TOOL PRM WORKDIR   (PRM: the Terzaghi case)
"""
import os
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
cases = [
    ("porosity", [("material 0/pore liquid/porosity", "1.2")], "pore liquid/porosity"),
    ("zero permeability", [("material 0/pore liquid/hydraulic conductivity", "0"),
                           ("material 0/pore liquid/intrinsic permeability", "0")], "intrinsic permeability"),
    ("liquid as skeleton", [("material 0/model", "newtonian")], "pore liquid/drainage"),
    ("bad drainage", [("material 0/pore liquid/drainage", "partial")], "drainage"),
    ("traction size", [("body 0/traction", "0, 1, 2")], "body 0/traction"),
    ("traction on a ball", [("body 0/shape", "ball"), ("body 0/center", "0.05, 0.5"), ("body 0/radius", "0.04")],
     "traction face"),
    ("free surface factor", [("liquid/free surface factor", "1")], "free surface factor"),
    ("damping", [("two phase/local damping", "1")], "local damping"),
    # the shared loads work with 2-phase materials (check_two_phase_loads.py); what
    # is left: the alias given twice with different values, and mass scaling
    # below 1 (the drag relaxation time shrinks by beta, the step only by sqrt(beta))
    ("damping alias twice", [("two phase/local damping", "0.3"), ("damping/local damping", "0.5")],
     "two phase/local damping"),
    ("mass scaling below 1", [("mass scaling/factor", "0.5")], "mass scaling/factor"),
    # issue 38: coupled materials run on quadratic B-splines with the pore-pressure relaxation
    # (docs/shape-functions.md, "2-phase on B-splines"); its share C is a number in [0, 10]
    ("pressure relaxation", [("numerics/shape function", "quadratic bspline"),
                             ("two phase/pressure relaxation", "-1")], "pressure relaxation"),
    ("pressure relaxation word", [("two phase/pressure relaxation", "automatic")], "pressure relaxation"),
    # APIC keeps the 1-phase step only, on B-splines too
    ("B-splines + APIC", [("numerics/shape function", "quadratic bspline"), ("numerics/velocity transfer", "apic")],
     "numerics/velocity transfer"),
]
for name, edits, needle in cases:
    text = base
    for k, v in edits:
        text = tv.prm_set(text, k, v)
    rc, out, err = tv.run_tool(tool, text, os.path.join(work, name.replace(" ", "_")), "case", expect_rc=None)
    msg = (out + err).strip().splitlines()
    tv.check(rc == 2 and needle in (out + err) and not os.path.exists(os.path.join(work, name.replace(" ", "_"), "out", "series.csv")),
             f"{name}: exit {rc}, message names '{needle}': {msg[-1] if msg else ''}")
tv.finish()
