"""Strain smoothing by nodal mixed discretisation (seed 000 §6.7.1) — issue 5 verification.

A near-incompressible elastic layer (G = 1 MPa fixed, nu = 0.49 and 0.499) under a
stiff heavy strip footing, released under gravity; the footing settlement is the
time average of its probe displacement over the last 3/4 of the run (the system
oscillates about its static state, no damping). Volumetric locking makes the
plain scheme too stiff, increasingly so as nu -> 0.5, while the settlement of the
physical layer tends to a finite limit at fixed G. Criteria:
  * nu = 0.49:  settlement with smoothing >= 1.15 x without;
  * nu = 0.499: settlement with smoothing >= 1.5 x without;
  * limit behaviour: from nu = 0.49 to 0.499 the smoothed settlement changes by
    less than 15 %, the plain one drops by more than 40 % (locking).
Usage: check_smoothing.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
G = 1.0e6


def settlement(nu, smoothing):
    name = f"footing_{nu}_{smoothing}"
    text = open(prm_path).read()
    text = tv.prm_set(text, "material 0/linear elastic/young modulus", repr(2 * G * (1 + nu)))
    text = tv.prm_set(text, "material 0/linear elastic/poisson ratio", str(nu))
    text = tv.prm_set(text, "numerics/strain smoothing", smoothing)
    text = tv.prm_set(text, "output/directory", name)
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    t, u = s["time"], s["probe0_uy"]
    sel = [x for tt, x in zip(t, u) if tt >= 0.25 * t[-1]]
    return -sum(sel) / len(sel)


s = {}
for nu in (0.49, 0.499):
    for sm in ("none", "nodal"):
        s[nu, sm] = settlement(nu, sm)
        print(f"  nu = {nu}, strain smoothing = {sm}: footing settlement {s[nu, sm]:.4e} m")
r49 = s[0.49, "nodal"] / s[0.49, "none"]
r499 = s[0.499, "nodal"] / s[0.499, "none"]
tv.check(r49 >= 1.15, f"nu = 0.49: smoothed / plain settlement {r49:.3f} >= 1.15")
tv.check(r499 >= 1.5, f"nu = 0.499: smoothed / plain settlement {r499:.3f} >= 1.5")
ds = abs(s[0.499, "nodal"] / s[0.49, "nodal"] - 1)
dp = 1 - s[0.499, "none"] / s[0.49, "none"]
tv.check(ds < 0.15 and dp > 0.40,
         f"nu 0.49 -> 0.499: smoothed settlement changes by {ds:.1%} (< 15 %), plain drops by {dp:.1%} (> 40 %)")
tv.finish()
