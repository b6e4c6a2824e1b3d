"""Local damping of the separate (2-phase / traction) step, seed 000 §6.3 (issue 5).

The elastic column of check_column.py is run through the separate step (a zero
traction on its top face selects it) with 'two phase/local damping' alpha. For a
single mode, f_damp = -alpha |f| sign(v) makes the amplitude about the static state
shrink by sqrt((1 - alpha)/(1 + alpha)) every half period (the force is reduced by
alpha while moving towards equilibrium and increased while moving away). The
column is close to its first mode: the mean ratio of successive extrema over the
first four half periods must be within 5 % of that value for alpha = 0.1 (0.9045),
and within 2 % of 1 for alpha = 0.
Usage: check_local_damping.py TOOL PRM WORKDIR   (PRM: elastic_column_gravity.prm)
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_static = -rho * g * H * H / (2 * Ec)
base = open(prm_path).read()
base = tv.prm_set(base, "body 0/traction face", "y+")
base = tv.prm_set(base, "body 0/traction", "0, 0")
for alpha in (0.0, 0.1):
    text = tv.prm_set(base, "two phase/local damping", str(alpha))
    text = tv.prm_set(text, "output/directory", f"alpha_{alpha}")
    tv.run_tool(tool, text, work, f"alpha_{alpha}")
    u = tv.read_csv(f"{work}/alpha_{alpha}/series.csv")["probe0_uy"]
    ext = [-u_static] + [u[i] - u_static for i in range(1, len(u) - 1) if (u[i] - u[i - 1]) * (u[i + 1] - u[i]) < 0]
    ratios = [abs(ext[i + 1] / ext[i]) for i in range(4)]
    mean = sum(ratios) / 4
    expected = ((1 - alpha) / (1 + alpha)) ** 0.5
    print(f"alpha = {alpha}: extrema about the static state {['%.4e' % e for e in ext[:5]]}; "
          f"ratios {['%.4f' % r for r in ratios]}, mean {mean:.4f}, single-mode value {expected:.4f}")
    tol = 0.02 if alpha == 0 else 0.05
    tv.check(abs(mean - expected) <= tol * expected,
             f"alpha = {alpha}: mean amplitude ratio per half period {mean:.4f} within {100 * tol:.0f} % of {expected:.4f}")
tv.finish()
