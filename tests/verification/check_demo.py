"""The demo scene (Mohr-Coulomb granular column collapse, plane strain) — a
consistency check of a real large-deformation run:
  * the run ends normally (exit 0) with every material point still in the grid;
  * no energy is created: kinetic + strain + potential energy never exceeds its
    initial value by more than 1 % (plasticity only dissipates);
  * the column has collapsed and come to rest: the potential energy dropped by
    more than 40 % (height of the centre of mass), the final kinetic energy is below
    5 % of its peak, and the run-out (99th percentile of the point positions) exceeds twice the
    initial column width;
  * the run drew its final deposit (a PNG, output/png snapshots = final);
  * the final picture has no point separated from the deposit (beyond its contiguous
    front, tv.deposit_front, for 4 bin origins as check_column_collapse.py), and the
    deposit is that of seed 001 Table 6.5 for a = 3 (Lube et al.): d_inf within 15 %
    of 0.505 m, h_inf within 10 % of 0.14 m (measured -10.1 % and -4.4 %: the demo's
    grid is d_i/12, docs/explicit.md "The demo's option set").
Usage: check_demo.py TOOL PRM WORKDIR
"""
import csv
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
text = tv.prm_set(text, "output/final particles csv", "true")
text = tv.prm_set(text, "output/progress", "false")
tv.run_tool(tool, text, work, "demo")
s = tv.read_csv(f"{work}/out/series.csv")
e = [k + w + p for k, w, p in zip(s["kinetic_energy"], s["strain_energy"], s["gravity_potential_energy"])]
tv.check(max(s["lost_particles"]) == 0, f"no material point left the grid (lost {max(s['lost_particles']):.0f})")
tv.check(max(e) <= 1.01 * e[0], f"no energy created: max total / initial = {max(e) / e[0]:.4f}")
pe = s["gravity_potential_energy"]
tv.check(pe[-1] < 0.6 * pe[0], f"collapsed: potential energy {pe[-1]:.2f} J vs initial {pe[0]:.2f} J")
ke = s["kinetic_energy"]
tv.check(ke[-1] < 0.05 * max(ke), f"at rest: final kinetic energy {ke[-1]:.3g} J, peak {max(ke):.3g} J")
parts = tv.read_csv(f"{work}/out/particles_final.csv")
xs = sorted(parts["pos_x"])
runout = xs[int(0.99 * len(xs))]
tv.check(runout > 0.2, f"run-out (99th percentile of x) {runout:.3f} m beyond twice the initial width 0.1 m")
# the deposit against seed 001 Table 6.5 (a = 3), measured as check_column_collapse.py does
cells = [int(c) for c in tv.prm_get(text, "grid/cells").split(",")]
g_hi = [float(c) for c in tv.prm_get(text, "grid/upper corner").split(",")]
hx = g_hi[0] / cells[0]
spacing = hx / float(tv.prm_get(text, "body 0/particles per direction"))
fronts = [tv.deposit_front(parts["pos_x"], hx, -q * hx / 4) for q in range(4)]
d_inf = sum(f for f, _ in fronts) / 4 + 0.5 * spacing
h_inf = max(parts["pos_y"]) + 0.5 * spacing
n_beyond = max(n for _, n in fronts)
tv.check(n_beyond == 0, f"no point separated from the deposit in the final picture ({n_beyond} beyond its front)")
tv.check(abs(d_inf - 0.505) < 0.15 * 0.505, f"d_inf = {d_inf:.4f} m within 15 % of 0.505 m "
         f"({100 * (d_inf / 0.505 - 1):+.1f} %)")
tv.check(abs(h_inf - 0.14) < 0.10 * 0.14, f"h_inf = {h_inf:.4f} m within 10 % of 0.14 m "
         f"({100 * (h_inf / 0.14 - 1):+.1f} %)")
# the .prm draws the final deposit (output/png snapshots = final, issue 17)
import glob
pngs = glob.glob(f"{work}/out/png/snapshot_plastic_strain_*.png")
tv.check(len(pngs) == 1 and open(pngs[0], "rb").read(8) == b"\x89PNG\r\n\x1a\n",
         f"the final deposit is drawn: {', '.join(pngs) or 'no PNG'}")
print(f"run-out: 99th percentile {runout:.3f} m, farthest point {xs[-1]:.3f} m; final height {max(parts['pos_y']):.3f} m")
tv.finish()
