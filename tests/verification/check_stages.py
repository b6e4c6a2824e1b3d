"""Staged calculation (issue 5): a gravity stage with local damping that ends by
the quasi-static convergence criterion, then a release stage (no damping) with a
sudden top traction.
  * series.csv has a 'stage' column going 0 -> 1 once, never back;
  * stage 0 ended by convergence before its 10 s duration;
  * top settlement at the end of stage 0 within 1 % of rho g (H y - y^2/2) / E_oed;
  * stage 1 (undamped step load q): peak extra settlement within 5 % of the
    dynamic value 2 q y / E_oed.
Usage: check_stages.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
tv.run_tool(tool, text, work, "staged")
s = tv.read_csv(f"{work}/out/series.csv")
tv.check("stage" in s, "series.csv has a 'stage' column")
st, t, u = s["stage"], s["time"], s["probe0_uy"]
switches = [i for i in range(1, len(st)) if st[i] != st[i - 1]]
tv.check(len(switches) == 1 and st[0] == 0 and st[-1] == 1, f"one stage switch 0 -> 1 (switch rows {switches})")
i1 = switches[0]
t_switch = t[i1 - 1]
print(f"stage 0 ended at t = {t_switch:.4f} s (step {int(s['step'][i1 - 1])}), run ended at t = {t[-1]:.4f} s")
tv.check(t_switch < 9.9, f"stage 0 ended by convergence before its duration (t = {t_switch:.4f} s < 10 s)")
E, nu, rho, g, H, q, y = 1e7, 0.3, 2000.0, 9.81, 1.0, 1e4, 0.99375
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_g = -rho * g * (H * y - y * y / 2) / E_oed
u0 = u[i1 - 1]
e0 = abs(u0 - u_g) / abs(u_g)
tv.check(e0 < 0.01, f"settlement at the end of stage 0: {u0:.6e} m vs {u_g:.6e} m (error {e0:.2e} < 1e-2)")
peak = min(u[i1:]) - u0
ref = -2 * q * y / E_oed
e1 = abs(peak - ref) / abs(ref)
tv.check(e1 < 0.05, f"stage 1 peak extra settlement {peak:.6e} m vs 2 q y / E_oed = {ref:.6e} m (error {e1:.2e} < 5e-2)")
tv.check(abs(t[-1] - (t_switch + 0.4)) < 1e-6, f"stage 1 ran its duration 0.4 s (ended at {t[-1]:.6f} s)")
tv.finish()
