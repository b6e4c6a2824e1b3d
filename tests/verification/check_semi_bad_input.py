"""Bad input of talus-semi-implicit (issue 14): each case must exit with code 2
before any output (the output directory is not even created), with one message
'talus-semi-implicit: error: ...' naming the entry. Both through --check and a
plain run.
Usage: check_semi_bad_input.py TOOL PRM WORKDIR   (PRM: the hydrostatic column)
"""
import os
import subprocess
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
cases = [
    # the shared 'material k/pore liquid' (materials/pore_liquid.h; issue 37)
    ("porosity above 1", [("material 0/pore liquid/porosity", "1.2")], "material 0/pore liquid/porosity"),
    ("porosity 0", [("material 0/pore liquid/porosity", "0")], "material 0/pore liquid/porosity"),
    ("zero conductivity", [("material 0/pore liquid/hydraulic conductivity", "0"),
                           ("material 0/pore liquid/intrinsic permeability", "0")],
     "material 0/pore liquid/intrinsic permeability"),
    ("negative conductivity", [("material 0/pore liquid/hydraulic conductivity", "-1e-5")],
     "hydraulic conductivity"),
    ("undrained pore liquid", [("material 0/pore liquid/drainage", "undrained")],
     "material 0/pore liquid/drainage: is 'undrained'"),
    ("liquid density other than the water's", [("material 0/pore liquid/liquid density", "1100")],
     "material 0/pore liquid/liquid density: is 1100 kg/m^3: talus-semi-implicit has one water"),
    ("liquid bulk modulus", [("material 0/pore liquid/liquid bulk modulus", "2.2e7")],
     "material 0/pore liquid/liquid bulk modulus: is 2.2e+07 Pa: talus-semi-implicit's water is incompressible"),
    ("zero liquid viscosity", [("material 0/pore liquid/liquid viscosity", "0")],
     "material 0/pore liquid/liquid viscosity"),
    # the shared 'damping' (loads/damping.h): the family has no damping term
    ("local damping", [("damping/local damping", "0.7")],
     "damping/local damping: is 0.7: talus-semi-implicit cannot honour it: talus-semi-implicit has no damping term"),
    ("viscous damping", [("damping/viscous damping", "1.5")],
     "damping/viscous damping: is 1.5: talus-semi-implicit cannot honour it"),
    ("stiffness damping", [("damping/stiffness damping", "1e-3")],
     "damping/stiffness damping: is 0.001: talus-semi-implicit cannot honour it"),
    # a water body alone: no soil, so no skeleton for the drag and the mixture
    ("water without soil", [("body 0/phase", "water")], "body 0/phase = water"),
    # (soil without water is a single-phase solid and allowed: the strip footing)
    ("modified f-bar without b_e", [("numerics/volumetric stabilisation", "modified f-bar")],
     "numerics/volumetric stabilisation"),
    ("bad stabilisation", [("numerics/volumetric stabilisation", "f bar")], "volumetric stabilisation"),
    ("write grid", [("output/write grid", "true")], "output/write grid"),
    ("patch size", [("semi implicit/patch size", "0.1")], "semi implicit/patch size"),
    ("single point with a water body", [("semi implicit/point sets", "single"), ("number of bodies", "2"),
                                        ("body 1/phase", "water"), ("body 1/upper corner", "0.075, 1.05"),
                                        ("body 1/lower corner", "0, 1")], "semi implicit/point sets"),
    ("one set with a water body", [("semi implicit/point sets", "one set"), ("number of bodies", "2"),
                                   ("body 1/phase", "water"), ("body 1/upper corner", "0.075, 1.05"),
                                   ("body 1/lower corner", "0, 1")], "one set needs every body"),
    ("bad point sets", [("semi implicit/point sets", "one")], "point sets"),
    ("smoothing fraction above 1", [("semi implicit/pressure smoothing fraction", "1.5")],
     "semi implicit/pressure smoothing fraction: is '1.5'; allowed: a number in [0, 1] or automatic"),
    ("smoothing fraction not a number", [("semi implicit/pressure smoothing fraction", "auto")],
     "semi implicit/pressure smoothing fraction: is 'auto'; allowed"),
    # the shared loads (issue 37, docs/boundary-conditions.md; the per-body
    # 'surface load' entries they replace are gone): a region upside down
    ("traction region upside down", [("loads/number of tractions", "1"), ("loads/traction 0/apply to", "region"),
                                     ("loads/traction 0/region lower corner", "0.05, 1"),
                                     ("loads/traction 0/region upper corner", "0, 0.9"),
                                     ("loads/traction 0/traction", "0, -1e4")], "loads/traction 0/region upper corner"),
    ("unknown phase", [("body 0/phase", "gas")], "phase"),
    ("free surface fraction", [("semi implicit/free surface volume fraction", "1")], "free surface volume fraction"),
    # checkpoints are built; a restart needs one (the foreign, other-scene and
    # other-dimension checkpoints: check_semi_restart.py)
    ("restart without a checkpoint", [("checkpoint/restart", "true")], "checkpoint/restart"),
    ("traction on a boundary id the box lacks", [("loads/number of tractions", "1"),
                                                 ("loads/traction 0/apply to", "boundary"),
                                                 ("loads/traction 0/boundary id", "5"),
                                                 ("loads/traction 0/traction", "0, -1e4")], "loads/traction 0/boundary id"),
    ("traction region outside the grid", [("loads/number of tractions", "1"), ("loads/traction 0/apply to", "region"),
                                          ("loads/traction 0/region lower corner", "1, 2"),
                                          ("loads/traction 0/region upper corner", "2, 3"),
                                          ("loads/traction 0/traction", "0, -1e4")],
     "loads/traction 0/region lower corner"),
    ("pressure on a circle", [("loads/number of tractions", "1"), ("loads/traction 0/apply to", "region"),
                              ("loads/traction 0/region lower corner", "0, 0.5"),
                              ("loads/traction 0/region upper corner", "0.075, 1"),
                              ("loads/traction 0/pressure centre", "0, 1"),
                              ("loads/traction 0/pressure radius", "0.05"),
                              ("loads/traction 0/pressure", "1000")], "loads/traction 0/pressure centre"),
    ("traction on a rigid skeleton", [("loads/number of tractions", "1"), ("loads/traction 0/traction", "0, -1e4"),
                                      ("semi implicit/rigid skeleton", "true")], "loads/traction 0"),
    ("velocity on a boundary id the box lacks", [("loads/number of velocity conditions", "1"),
                                                 ("loads/velocity 0/boundary id", "9")], "loads/velocity 0/boundary id"),
    ("velocity of material points", [("loads/number of velocity conditions", "1"),
                                     ("loads/velocity 0/apply to", "body")], "loads/velocity 0/apply to"),
    ("velocity region without a node", [("loads/number of velocity conditions", "1"),
                                        ("loads/velocity 0/apply to", "region"),
                                        ("loads/velocity 0/region lower corner", "0.01, 0.51"),
                                        ("loads/velocity 0/region upper corner", "0.02, 0.52")],
     "loads/velocity 0: holds no grid node"),
    ("velocity bad component", [("loads/number of velocity conditions", "1"),
                                ("loads/velocity 0/components", "z")], "loads/velocity 0/components"),
    ("velocity on a rigid skeleton", [("loads/number of velocity conditions", "1"),
                                      ("loads/velocity 0/boundary id", "3"),
                                      ("semi implicit/rigid skeleton", "true")], "loads/velocity 0"),
    ("drainage on a boundary id the box lacks", [("boundary conditions/number of drainage conditions", "1"),
                                                 ("boundary conditions/drainage 0/boundary id", "4")],
     "boundary conditions/drainage 0/boundary id"),
    ("drainage pressure without a value", [("boundary conditions/number of drainage conditions", "1"),
                                           ("boundary conditions/drainage 0/condition", "pressure")],
     "boundary conditions/drainage 0/pressure"),
    ("drainage pressure with drained", [("boundary conditions/number of drainage conditions", "1"),
                                        ("boundary conditions/drainage 0/pressure", "-100")],
     "boundary conditions/drainage 0/pressure"),
    ("drainage unknown condition", [("boundary conditions/number of drainage conditions", "1"),
                                    ("boundary conditions/drainage 0/condition", "open")], "condition"),
    ("drainage region outside the grid", [("boundary conditions/number of drainage conditions", "1"),
                                          ("boundary conditions/drainage 0/apply to", "region"),
                                          ("boundary conditions/drainage 0/region lower corner", "-2, -2"),
                                          ("boundary conditions/drainage 0/region upper corner", "-1, -1")],
     "boundary conditions/drainage 0/region lower corner"),
    ("drainage time function", [("boundary conditions/number of drainage conditions", "1"),
                                ("boundary conditions/drainage 0/condition", "pressure"),
                                ("boundary conditions/drainage 0/pressure", "-100"),
                                ("boundary conditions/drainage 0/time function", "ramp -1")],
     "boundary conditions/drainage 0/time function"),
    ("too many drainage conditions", [("boundary conditions/number of drainage conditions", "17")],
     "number of drainage conditions"),
    ("drained boundary of 3D in 2D", [("semi implicit/drained boundaries", "2, 4")], "semi implicit/drained boundaries"),
    ("drained boundary not a number", [("semi implicit/drained boundaries", "base")], "semi implicit/drained boundaries"),
    ("initialisation beyond the end", [("initial state/initialisation time", "5")], "initial state/initialisation time"),
    ("negative initialisation", [("initial state/initialisation time", "-0.1")], "initial state/initialisation time"),
    ("initialisation conductivity 0", [("initial state/initialisation time", "0.1"),
                                       ("initial state/initialisation conductivity", "0")],
     "initial state/initialisation conductivity"),
    # App. B.4 needs an elastic-only mode: hencky mohr coulomb has none
    ("initialisation with a plastic model", [("initial state/initialisation time", "0.1"),
                                             ("material 0/model", "hencky mohr coulomb")], "material 0/model"),
    ("traction acts at", [("semi implicit/traction acts at", "points")], "traction acts at"),
    # the AMG hierarchy's rebuild interval: an integer >= 1
    ("rebuild interval 0", [("semi implicit/pressure preconditioner rebuild interval", "0")],
     "pressure preconditioner rebuild interval"),
    ("rebuild interval negative", [("semi implicit/pressure preconditioner rebuild interval", "-5")],
     "pressure preconditioner rebuild interval"),
    ("rebuild interval not an integer", [("semi implicit/pressure preconditioner rebuild interval", "2.5")],
     "pressure preconditioner rebuild interval"),
    ("traction on water", [("loads/number of tractions", "1"), ("loads/traction 0/body", "1"),
                           ("loads/traction 0/traction", "0, -1e3"), ("number of bodies", "2"),
                           ("body 1/phase", "water"), ("body 1/upper corner", "0.075, 1.05"),
                           ("body 1/lower corner", "0, 1")], "loads/traction 0/body"),
    # the shared scene checks (formulations/common/scene_checks.h): the memory of
    # the grid and both point sets, a boundary id the box lacks
    ("grid too large for the memory", [("grid/cells", "100000, 100000")], "grid/cells: 1e+10 cells"),
    ("boundary id the box lacks", [("boundary conditions/fixed", "7")],
     "boundary conditions/fixed: boundary id 7 does not exist"),
    # rigid plates (issue 37): both controls; a boundary id the box lacks; a
    # region holding no grid node; the axis held by a wall at every plate node
    # (the base is a roller: it holds y); a rigid skeleton cannot be moved
    ("plate with force and displacement", [("boundary conditions/number of rigid plates", "1"),
                                           ("boundary conditions/rigid plate 0/boundary id", "3"),
                                           ("boundary conditions/rigid plate 0/total force", "-100"),
                                           ("boundary conditions/rigid plate 0/displacement", "-1e-3")],
     "boundary conditions/rigid plate 0"),
    ("plate on a boundary id the grid lacks", [("boundary conditions/number of rigid plates", "1"),
                                               ("boundary conditions/rigid plate 0/boundary id", "7"),
                                               ("boundary conditions/rigid plate 0/total force", "-100")],
     "boundary conditions/rigid plate 0/boundary id"),
    ("plate holding no node", [("boundary conditions/number of rigid plates", "1"),
                               ("boundary conditions/rigid plate 0/apply to", "region"),
                               ("boundary conditions/rigid plate 0/region lower corner", "0.01, 0.51"),
                               ("boundary conditions/rigid plate 0/region upper corner", "0.02, 0.52"),
                               ("boundary conditions/rigid plate 0/total force", "-100")],
     "boundary conditions/rigid plate 0: holds no grid node"),
    ("plate axis held by a wall", [("boundary conditions/number of rigid plates", "1"),
                                   ("boundary conditions/rigid plate 0/boundary id", "2"),
                                   ("boundary conditions/rigid plate 0/total force", "-100")],
     "boundary conditions/rigid plate 0: a fixed/roller wall holds its direction component at every one of its"),
    ("plates sharing a node", [("boundary conditions/number of rigid plates", "2"),
                               ("boundary conditions/rigid plate 0/boundary id", "3"),
                               ("boundary conditions/rigid plate 0/total force", "-100"),
                               ("boundary conditions/rigid plate 1/apply to", "region"),
                               ("boundary conditions/rigid plate 1/region lower corner", "0.07, 1.05"),
                               ("boundary conditions/rigid plate 1/region upper corner", "0.075, 1.1"),
                               ("boundary conditions/rigid plate 1/total force", "-100")],
     "boundary conditions/rigid plate 1: shares"),
    ("plate on a rigid skeleton", [("boundary conditions/number of rigid plates", "1"),
                                   ("boundary conditions/rigid plate 0/boundary id", "3"),
                                   ("boundary conditions/rigid plate 0/total force", "-100"),
                                   ("semi implicit/rigid skeleton", "true")], "boundary conditions/rigid plate 0"),
]
for name, edits, needle in cases:
    text = base
    for k, v in edits:
        text = tv.prm_set(text, k, v)
    wd = os.path.join(work, name.replace(" ", "_"))
    rc, out, err = tv.run_tool(tool, text, wd, "case", expect_rc=None)
    lines = [l for l in (out + err).strip().splitlines() if l.strip()]
    first_error = next((l for l in lines if ": error:" in l), "")
    tv.check(rc == 2 and needle in (out + err) and first_error.startswith("talus-semi-implicit: error:")
             and not os.path.exists(os.path.join(wd, "out")),
             f"{name}: exit {rc}, message names '{needle}', nothing written: {first_error}")
    p = subprocess.run([os.path.abspath(tool), "--check", os.path.join(wd, "case.prm")], cwd=wd,
                       capture_output=True, text=True, env=tv.child_env())
    tv.check(p.returncode == 2 and needle in (p.stdout + p.stderr), f"{name}: --check exits {p.returncode}")
# the good file passes --check and writes nothing
wd = os.path.join(work, "good")
os.makedirs(wd, exist_ok=True)
with open(os.path.join(wd, "case.prm"), "w") as f:
    f.write(base)
p = subprocess.run([os.path.abspath(tool), "--check", "case.prm"], cwd=wd, capture_output=True, text=True,
                   env=tv.child_env())
tv.check(p.returncode == 0 and not os.path.exists(os.path.join(wd, "out")), f"good file: --check exits {p.returncode}")
tv.finish()
