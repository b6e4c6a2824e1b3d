"""Undrained effective-stress analysis (seed 000 §4.3.8, Eq. 4.52), issue 5.

The elastic column under gravity of check_column.py (roller sides: uniaxial
strain), now with 'pore liquid/drainage = undrained': the excess pore pressure
follows dp = -(K_L/n) tr(d eps), so the column is stiffer, E_c -> E_c + K_L/n, and
the time-averaged top displacement over the last oscillation period must be
within 2 % of rho g H^2 / (2 (E_c + K_L/n)). The drained column (same run with
drainage = drained) must give rho g H^2 / (2 E_c) instead (the check can fail).
Usage: check_undrained.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
KL, n = 3e5, 0.3
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def mean_top(text, name):
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    t, u = s["time"], s["probe0_uy"]
    avg, period = tv.time_average_last_period(t, u)
    tv.check(period == period, f"{name}: at least two upward crossings of the mean")
    return avg, period


base = open(prm_path).read()
base = tv.prm_set(base, "material 0/pore liquid/porosity", str(n))
base = tv.prm_set(base, "material 0/pore liquid/liquid bulk modulus", str(KL))
for mode, modulus in (("undrained", Ec + KL / n), ("drained", Ec)):
    text = tv.prm_set(base, "material 0/pore liquid/drainage", mode)
    text = tv.prm_set(text, "output/directory", mode)
    avg, period = mean_top(text, mode)
    ref = -rho * g * H * H / (2 * modulus)
    err = abs(avg - ref) / abs(ref)
    print(f"{mode}: mean top displacement {avg:.6e} m, rho g H^2/(2 M) = {ref:.6e} m (M = {modulus:.4g} Pa), "
          f"error {err:.2e}; period {period:.5f} s (4H/c = {4 * H / (modulus / rho) ** 0.5:.5f} s)")
    tv.check(err < 0.02, f"{mode}: time-averaged top displacement within 2 % (error {err:.2e})")
tv.finish()
