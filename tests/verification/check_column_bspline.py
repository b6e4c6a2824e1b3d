"""Quadratic B-splines against cell crossing (issue 12 verification).

The elastic column under gravity (elastic_column_gravity.prm: E = 1e6 Pa,
nu = 0.3, rho = 2000 kg/m3, H = 1 m, released stress-free), 3 cells across
(B-splines need 3) and 20 cells high, with 4 points per direction so that the
points near the top cross cell faces while the column oscillates. Run with
linear shape functions and with quadratic B-splines at the same resolution:
  err    time average of the top probe displacement over the last full period
         vs the static rho g H^2 / (2 E_c);
  noise  RMS residual of a quartic fit of sigma_yy(y) of all points at the end,
         divided by rho g H.
Criteria: both runs end normally; the B-spline error is at least 3 x smaller
than the linear one, and the B-spline stress noise is smaller than the linear.
Quasi-static variant (printed and checked too): cells of 0.025 m, local damping
0.7 until t = 1.5 s; B-spline top settlement closer to the static solution than
the linear one and within 1 %.
Usage: check_column_bspline.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
E, nu, rho, g, H = 1e6, 0.3, 2000.0, 9.81, 1.0
Ec = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
u_static = -rho * g * H * H / (2 * Ec)


def run(name, edits):
    text = tv.prm_set(base, "output/directory", "out_" + name)
    text = tv.prm_set(text, "output/final particles csv", "true")
    for k, v in edits.items():
        text = tv.prm_set(text, k, v)
    tv.run_tool(tool, text, work, name)
    return tv.read_csv(f"{work}/out_{name}/series.csv"), tv.read_csv(f"{work}/out_{name}/particles_final.csv")


SHAPES = ("linear", "quadratic bspline")
dynamic = {"grid/cells": "3, 20", "grid/upper corner": "0.1875, 1.25", "body 0/upper corner": "0.1875, 1",
           "body 0/particles per direction": "4", "output/probes": "0.09375, 0.99"}
res = {}
for shape in SHAPES:
    s, p = run("dynamic_" + shape.split()[-1], dict(dynamic, **{"numerics/shape function": shape}))
    err = abs(tv.time_average_last_period(s["time"], s["probe0_uy"])[0] - u_static) / abs(u_static)
    noise = tv.polyfit_noise(p["pos_y"], p["stress_yy"]) / (rho * g * H)
    res[shape] = (err, noise)
    print(f"dynamic column, 4 points per direction, {shape:17s}: settlement error {err:.3e}, "
          f"stress noise {noise:.3e} rho g H")
(el, nl), (eb, nb) = res["linear"], res["quadratic bspline"]
tv.check(eb * 3 <= el, f"B-spline settlement error {eb:.3e} at least 3 x smaller than linear {el:.3e} "
                       f"(ratio {el / max(eb, 1e-300):.1f})")
tv.check(nb < nl, f"B-spline stress noise {nb:.3e} below linear {nl:.3e}")

qs = {"grid/cells": "3, 50", "grid/upper corner": "0.075, 1.25", "body 0/upper corner": "0.075, 1",
      "damping/local damping": "0.7", "time/end time": "1.5", "output/probes": "0.0375, 0.99375"}
y0 = 0.99375
u_ref = -rho * g * (H * y0 - 0.5 * y0 * y0) / Ec
qres = {}
for shape in SHAPES:
    s, p = run("quasi_static_" + shape.split()[-1], dict(qs, **{"numerics/shape function": shape}))
    qres[shape] = (s["probe0_uy"][-1] - u_ref) / abs(u_ref)
    print(f"quasi-static column, {shape:17s}: top point settlement error {100 * qres[shape]:+.3f} %, "
          f"stress noise {tv.polyfit_noise(p['pos_y'], p['stress_yy']) / (rho * g * H):.3e} rho g H")
tv.check(abs(qres["quadratic bspline"]) < abs(qres["linear"]),
         "quasi-static: B-spline settlement closer to the static solution than linear")
tv.check(abs(qres["quadratic bspline"]) < 0.01, f"quasi-static: B-spline settlement within 1 % "
                                                f"({100 * qres['quadratic bspline']:+.3f} %)")
tv.finish()
