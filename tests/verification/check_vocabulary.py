"""One .prm vocabulary (issue 37 item 2): the same fragment of the shared
'damping' section (loads/damping.h) or of 'material k/pore liquid'
(materials/pore_liquid.h), parameter_files/verification/vocabulary/*.inc, is
included from each tool's .prm of the shared rigid-plate layer
(parameter_files/verification/rigid_plate/layer_<family>.prm). A tool that
honours the fragment accepts it: --check exits 0 and a short run exits 0 and
shows the value in effect (the damping in the run's log; the coupled pore
liquid's porosity and conductivity in the points' output; the undrained one's
K_L / n in the critical time step the log reports, L / sqrt((E_oed + K_L / n) / rho)). A tool that cannot honour it refuses it: exit 2, one
message naming the entry and saying why, no output directory, with --check and
with a run.
Usage: check_vocabulary.py TOOLS_DIR PRM_DIR WORKDIR
"""
import math
import os
import shutil
import subprocess
import sys

import talus_verify as tv

tools, prm_dir, work = sys.argv[1], sys.argv[2], sys.argv[3]
shutil.rmtree(work, ignore_errors=True)
layer = os.path.join(prm_dir, "verification", "rigid_plate")
vocab = os.path.join(prm_dir, "verification", "vocabulary")
dynamic = {"implicit/analysis": "dynamic"}
# (fragment, tool, the tool's own settings, None = accepted or the needles of the refusal,
#  evidence of an accepted run: ("log", text) or (point file, column, value))
cases = [
    ("damping_viscous", "explicit", {}, None, ("log", "viscous damping 0.5 1/s")),
    ("damping_viscous", "implicit", dynamic, None, ("log", "Rayleigh alpha = 0.500000")),
    ("damping_viscous", "implicit", {}, ["damping/viscous damping: is 0.5", "analysis = dynamic"], None),
    ("damping_viscous", "semi-implicit", {}, ["damping/viscous damping: is 0.5", "no damping term"], None),
    ("damping_local", "explicit", {}, None, ("log", "local damping 0.6")),
    ("damping_local", "implicit", dynamic, ["damping/local damping: is 0.6", "explicit step"], None),
    ("damping_local", "semi-implicit", {}, ["damping/local damping: is 0.6", "no damping term"], None),
    ("damping_stiffness", "implicit", dynamic, None, ("log", "Rayleigh beta = 0.002000")),
    ("damping_stiffness", "implicit", {}, ["damping/stiffness damping: is 0.002", "analysis = dynamic"], None),
    ("damping_stiffness", "explicit", {}, ["damping/stiffness damping: is 0.002", "no stiffness matrix"], None),
    ("damping_stiffness", "semi-implicit", {}, ["damping/stiffness damping: is 0.002", "no damping term"], None),
    ("pore_liquid_coupled", "explicit", {}, None, ("particles_final.csv", "porosity", 0.3)),
    ("pore_liquid_coupled", "semi-implicit", {}, None, ("soil_final.csv", "conductivity", 2e-2)),
    ("pore_liquid_coupled", "implicit", {}, ["material 0/pore liquid/drainage: is 'coupled'", "allowed: drained"],
     None),
    # undrained: the P wave sees E_oed + K_L / n (seed 000 Eq. 4.52): critical step L / c
    ("pore_liquid_undrained", "explicit", {}, None,
     ("log", "critical time step %.5e s" % (0.125 / math.sqrt((1e6 * 0.7 / (1.3 * 0.4) + 2.2e9 / 0.3) / 2000)))),
    ("pore_liquid_undrained", "implicit", {}, ["material 0/pore liquid/drainage: is 'undrained'"], None),
    ("pore_liquid_undrained", "semi-implicit", {}, ["material 0/pore liquid/drainage: is 'undrained'",
                                                    "'phase'"], None),
]
# a few steps of each tool's layer (the explicit coupled step is limited by K_L)
short = {"explicit": {"time/end time": "2e-3", "output/final particles csv": "true"},
         "implicit": {"time/end time": "0.5"}, "semi-implicit": {"time/end time": "0.01"}}
for fragment, tool, own, refusal, evidence in cases:
    name = f"{fragment} in talus-{tool}{' (dynamic)' if own else ''}"
    base = open(os.path.join(layer, f"layer_{tool.replace('-', '_')}.prm")).read()
    base = base.replace("include layer.inc", "include " + os.path.join(layer, "layer.inc"))
    for k, v in {**own, **short[tool]}.items():
        base = tv.prm_set(base, k, v)
    text = base + "include " + os.path.join(vocab, fragment + ".inc") + "\n"
    for check in (True, False):
        d = os.path.join(work, name.replace(" ", "_").replace("(", "").replace(")", "") + ("_check" if check else "_run"))
        out = os.path.join(d, "out")
        os.makedirs(d)
        with open(os.path.join(d, "case.prm"), "w") as f:
            f.write(tv.prm_set(text, "output/directory", out))
        p = subprocess.run([os.path.join(tools, "talus-" + tool)] + (["--check"] if check else []) + ["case.prm"],
                           capture_output=True, text=True, env=tv.child_env(), cwd=d, timeout=600)
        both = p.stdout + p.stderr
        last = (p.stderr.strip().splitlines() or [""])[-1]
        how = " --check" if check else ""
        if refusal is None:
            ok = p.returncode == 0
            seen = ""
            if ok and not check:
                if evidence[0] == "log":
                    ok = evidence[1] in both
                    seen = f", log shows '{evidence[1]}'" if ok else f", log LACKS '{evidence[1]}'"
                else:
                    pts = tv.read_csv(os.path.join(out, evidence[0]))
                    col = pts.get(evidence[1], [])
                    # (a point's porosity follows its volume: strains of 1e-9 in these few steps)
                    ok = len(col) > 0 and all(abs(x - evidence[2]) <= 1e-6 * evidence[2] for x in col)
                    seen = f", {evidence[0]}: {evidence[1]} {'as given' if ok else 'WRONG'} ({len(col)} points)"
            tv.check(ok, f"{name}{how}: accepted, exit {p.returncode}{seen} {'' if ok else last[:200]}")
        else:
            missing = [n for n in refusal if n not in both]
            errors = [l for l in p.stderr.splitlines() if ": error:" in l]
            ok = p.returncode == 2 and not missing and not os.path.exists(out) and len(errors) == 1 and \
                errors[0].startswith(f"talus-{tool}: error:")
            tv.check(ok, f"{name}{how}: refused, exit {p.returncode}, "
                     f"{'named ' + str(refusal) if not missing else 'MISSING ' + str(missing)}, "
                     f"{'nothing written' if not os.path.exists(out) else 'OUTPUT WRITTEN'} ({last[:160]})")
tv.finish()
