"""Bingham slump (issue 5: Bingham fluids usable as liquids).

A square Bingham column a x a (bingham_slump.prm) spreads on a no-slip base and
stops. Reference: the shallow-layer (lubrication) final profile of a plane Bingham
slump, h(x) = sqrt(2 tau_y (L - x) / (rho g)) (Liu & Mei 1989, J. Fluid Mech. 207,
505-529; the frictionless wall is the symmetry plane), whose area a^2 gives
L = (3 a^2 / (2 sqrt(2 tau_y / (rho g))))^(2/3). The column is only moderately
shallow at rest (h/L ~ 1/6), so the tolerance is 15 %. Checks: the front (largest x
plus half a point spacing) within 15 % of L; at rest (final kinetic energy < 1 % of
its peak); a Newtonian liquid of the same viscosity would reach the far wall, so the
yield stress must have stopped it well inside the box (front < 0.45 m).
Usage: check_bingham_slump.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
a, tau_y, rho, g = 0.1, 40.0, 1000.0, 9.81
L = (3 * a * a / (2 * (2 * tau_y / (rho * g)) ** 0.5)) ** (2.0 / 3.0)
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
tv.run_tool(tool, text, work, "slump")
s = tv.read_csv(f"{work}/out/series.csv")
front = s["extent_x_max"][-1] + 0.5 * 0.005 / 2
ke = s["kinetic_energy"]
err = abs(front - L) / L
print(f"final front {front:.4f} m, lubrication estimate {L:.4f} m, error {100 * err:.1f} %; "
      f"front 0.2 s before the end {s['extent_x_max'][-21] + 0.00125:.4f} m; final KE {ke[-1]:.3e} J, peak {max(ke):.3e} J")
tv.check(ke[-1] < 0.01 * max(ke), f"at rest: final kinetic energy {ke[-1]:.2e} J < 1 % of the peak {max(ke):.2e} J")
tv.check(front < 0.45, f"stopped inside the box by the yield stress (front {front:.3f} m < 0.45 m)")
tv.check(err <= 0.15, f"final run-out within 15 % of the lubrication estimate {L:.3f} m (error {100 * err:.1f} %)")
tv.finish()
