"""Mandel's problem in talus-semi-implicit (issue 40; docs/semi-implicit.md
'Mandel's problem'): the quarter of a saturated rectangle under an impermeable
rigid plate, drained at its free side (parameter_files/verification/mandel/
mandel_semi_implicit.prm), against the series solution (mandel_series.py).

Runs the scene to the times t_i (one run each, the final water points) and
measures, with p0 = q / 2 the undrained pore pressure:
  centre   the mean pore pressure of the water points of the first cell column
           (x < h) minus the series at their positions, over p0;
  profile  the normalised L2 error of the water points inside the sample
           (x < a), sqrt(sum (p - p_ref)^2 / sum p_ref^2);
  y spread the largest difference of the pore pressure along y within a column
           of points of x < a / 2, over p0 (Mandel's field does not depend on y).
Modes:
  fast     h = a / 10, the default step (courant 0.8), t = 0.6, 1.2, 2.4 s
           (T = 0.122, 0.245, 0.489; the load is ramped over 0.2 s): |centre| < 0.05, profile < 0.08,
           y spread < 0.01 at every time (measured 0.027, 0.044, 0.002 at worst); and the
           variant drained through the grid's face x = a (grid_face below): |centre| < 0.03,
           profile < 0.03, y spread < 0.01 (measured 0.0074, 0.013, 0.003); both variants
           on 1 and 2 ranks to t = 0.6 s: every water point's position and pore pressure
           within 1e-8 (of a, of p0; measured 0 and 2e-12).
  verify   h = a / 20 (the grid 28 x 10), courant 0.8, the same times:
           |centre| < 0.025, profile < 0.03, y spread < 0.01 (measured 0.013,
           0.020, 0.002 at worst); the grid-face variant: |centre| < 0.015, profile < 0.015,
           y spread < 0.01 (measured 0.0075, 0.0072, 0.003).
  measure  prints the measures for h = a / 10 at courant 0.8, 0.4, 0.2 and
           h = a / 20 at courant 0.8 and t = 0.3, 0.6, 1.2, 2.4 s, both variants (no check).
Usage: check_semi_mandel.py MODE TOOL PRM WORKDIR
"""
import math
import os
import shutil
import sys

import talus_verify as tv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mandel_series import Mandel  # noqa: E402

mode, tool, prm, work = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
text = open(prm).read()

a, q, E, nu, k, rho_w, g = 1.0, 1e3, 1e6, 0.0, 2e-3, 1000.0, 9.81
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
c = k * E_oed / (rho_w * g)
ref = Mandel(a, q, c, nu, ramp=0.2)
p0 = ref.p0


def grid_face(t, cells_x):
    """The variant drained through the grid's face x = a (the grid ends there; drainage 0 on
    boundary id 1, no wall) instead of the free surface beside dry cells."""
    t = tv.prm_set(t, "grid/upper corner", "%g, 0.5" % a)
    t = tv.prm_set(t, "boundary conditions/number of drainage conditions", "1")
    for key, v in (("apply to", "boundary"), ("boundary id", "1"), ("condition", "drained")):
        t = tv.prm_set(t, "boundary conditions/drainage 0/" + key, v)
    return tv.prm_set(t, "grid/cells", "%d, %d" % (cells_x, cells_x // 2))


def run(name, t_end, courant, cells, np=1):
    t = tv.prm_set(text, "output/directory", os.path.join(work, name))
    t = tv.prm_set(t, "time/end time", repr(t_end))
    t = tv.prm_set(t, "time/courant number", repr(courant))
    t = tv.prm_set(t, "grid/cells", cells)
    if name.startswith("face"):  # the same h: the grid's 1.4 a shortened to a
        t = grid_face(t, int(cells.split(",")[0]) * 10 // 14)
    tv.run_tool(tool, t, work, name, np=np)
    return tv.read_csv(os.path.join(work, name, "water_final.csv"))


def ranks(label, cells):
    """1 vs 2 ranks to t = 0.6 s: every water point's position and pore pressure (sorted by
    position) within 1e-8 (of a, of p0)"""
    pts = {}
    for np in (1, 2):
        w = run("%s_np%d" % (label, np), 0.6, 0.8, cells, np=np)
        pts[np] = sorted(zip(w["pos_x"], w["pos_y"], w["pore_pressure"]))
    a1, a2 = pts[1], pts[2]
    tv.check(len(a1) == len(a2), "%s: the same number of water points on 1 and 2 ranks" % label)
    dx = max(max(abs(u[0] - v[0]), abs(u[1] - v[1])) for u, v in zip(a1, a2)) / a
    dp = max(abs(u[2] - v[2]) for u, v in zip(a1, a2)) / p0
    print("%s: 1 vs 2 ranks: position %.2g a, pore pressure %.2g p0" % (label, dx, dp))
    tv.check(dx < 1e-8 and dp < 1e-8, "%s: 1 vs 2 ranks within 1e-8" % label)


def measures(w, t, h):
    xs, ys, ps = w["pos_x"], w["pos_y"], [-p for p in w["pore_pressure"]]  # compression positive
    inside = [i for i in range(len(xs)) if xs[i] < a]
    num = sum((ps[i] - ref.pressure(xs[i], t)) ** 2 for i in inside)
    den = sum(ref.pressure(xs[i], t) ** 2 for i in inside)
    first = [i for i in inside if xs[i] < h]
    centre = sum(ps[i] - ref.pressure(xs[i], t) for i in first) / len(first) / p0
    centre_p = sum(ps[i] for i in first) / len(first) / p0
    # columns of points: the water points start at x = (k + 1/2) h / 2 and move much less than h / 4
    cols = {}
    for i in inside:
        if xs[i] > a / 2:  # the columns near the drained side carry little pressure (and free water beside them)
            continue
        cols.setdefault(round(xs[i] / (h / 2) - 0.5), []).append(ps[i])
    spread = max(max(v) - min(v) for v in cols.values()) / p0
    return centre, centre_p, math.sqrt(num / den), spread


def case(label, courant, cells, h, times):
    out = []
    for t in times:
        w = run("%s_t%g" % (label, t), t, courant, cells)
        m = measures(w, t, h)
        print("%-15s t = %5.2f s (T = %.3f): centre p / p0 %.4f (series %.4f), centre error %+.4f p0, "
              "profile L2 %.4f, y spread %.4f p0" % (label, t, c * t / a**2, m[1], ref.pressure(h / 4, t) / p0,
                                                      m[0], m[2], m[3]))
        out.append(m)
    return out


times = [0.6, 1.2, 2.4]
if mode == "fast":
    for centre, _, prof, spread in case("h0.1_c0.8", 0.8, "14, 5", 0.1, times):
        tv.check(abs(centre) < 0.05, "centre error %.4f p0 < 0.05" % centre)
        tv.check(prof < 0.08, "profile L2 error %.4f < 0.08" % prof)
        tv.check(spread < 0.01, "y spread %.4f p0 < 0.01" % spread)
    for centre, _, prof, spread in case("face_h0.1_c0.8", 0.8, "14, 5", 0.1, times):
        tv.check(abs(centre) < 0.03, "grid face: centre error %.4f p0 < 0.03" % centre)
        tv.check(prof < 0.03, "grid face: profile L2 error %.4f < 0.03" % prof)
        tv.check(spread < 0.01, "grid face: y spread %.4f p0 < 0.01" % spread)
    ranks("h0.1", "14, 5")
    ranks("face_h0.1", "14, 5")
elif mode == "verify":
    for centre, _, prof, spread in case("h0.05_c0.8", 0.8, "28, 10", 0.05, times):
        tv.check(abs(centre) < 0.025, "centre error %.4f p0 < 0.025" % centre)
        tv.check(prof < 0.03, "profile L2 error %.4f < 0.03" % prof)
        tv.check(spread < 0.01, "y spread %.4f p0 < 0.01" % spread)
    for centre, _, prof, spread in case("face_h0.05_c0.8", 0.8, "28, 10", 0.05, times):
        tv.check(abs(centre) < 0.015, "grid face: centre error %.4f p0 < 0.015" % centre)
        tv.check(prof < 0.015, "grid face: profile L2 error %.4f < 0.015" % prof)
        tv.check(spread < 0.01, "grid face: y spread %.4f p0 < 0.01" % spread)
elif mode == "measure":
    times = [0.3, 0.6, 1.2, 2.4]
    for variant in ("", "face_"):
        case(variant + "h0.1_c0.8", 0.8, "14, 5", 0.1, times)
        case(variant + "h0.1_c0.4", 0.4, "14, 5", 0.1, times)
        case(variant + "h0.1_c0.2", 0.2, "14, 5", 0.1, times)
        case(variant + "h0.05_c0.8", 0.8, "28, 10", 0.05, times)
else:
    tv.fail("unknown mode " + mode)
tv.finish()
