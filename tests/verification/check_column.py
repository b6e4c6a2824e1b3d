"""Elastic column under gravity (2D and 3D) — issue 2 verification.

Released stress-free, the column oscillates about the static settlement
u_s = rho g H^2 / (2 E_c). The time average of the top probe displacement over
the last full oscillation period (between two upward crossings of the mean) must
be within 2 % of u_s.
Usage: check_column.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
tv.run_tool(tool, text, work, "column")
s = tv.read_csv(f"{work}/out/series.csv")
t = s["time"]
u = s["probe0_uz"] if "probe0_uz" in s else s["probe0_uy"]  # vertical: y in 2D, z in 3D
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_static = -rho * g * H * H / (2 * Ec)
avg, period = tv.time_average_last_period(t, u)
tv.check(period == period, "at least two upward crossings of the mean")
err = abs(avg - u_static) / abs(u_static)
print(f"period {period:.5f} s (analytic {4 * H / (Ec / rho) ** 0.5:.5f} s); "
      f"mean top displacement {avg:.6e} m, static {u_static:.6e} m, rel. error {err:.2e}")
tv.check(err < 0.02, f"time-averaged top displacement within 2 % of rho g H^2/(2 E_c) (error {err:.2e})")
tv.finish()
