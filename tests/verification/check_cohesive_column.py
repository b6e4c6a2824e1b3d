"""Cohesive soil column (seed 001 §4.5.3; issue 39 item 4): docs/implicit.md, "Cohesive soil column".

The scene is parameter_files/verification/cohesive_column/column.inc (Hencky Mohr-Coulomb,
c = 5 kPa, phi = 25 deg, E = 1.8 MPa, nu = 0.3, psi = 0, rho = 1850 kg/m^3; a column of width W
against a smooth wall at x = 0 on a rough base, released stress-free under gravity), solved by
talus-implicit (parameter_files/implicit/cohesive_column.prm: Newmark 1/2, 1/4) and by
talus-explicit (column_explicit.prm beside the fragment).

Analytic yardstick: the critical height of a vertical unsupported cut,
    H_c = 3.83 c / gamma tan(45 + phi / 2)   (Chen's log-spiral upper bound; 1.656 m here)
(the planar-wedge value 4 c / gamma tan(45 + phi / 2) = 1.730 m and the rigorous lower bound of the
uniaxial stress field 2 c / gamma tan(45 + phi / 2) = 0.865 m are printed beside it).

Usage:
  check_cohesive_column.py bracket TOOLS_DIR PRM_ROOT WORKDIR CELLS RATIO:EXPECT[,RATIO:EXPECT...]
                           [--set=entry=value ...]
      For each RATIO a square column (W = H = RATIO x H_c: the cut's failure wedge, 0.64 H wide at
      the top, stays clear of the wall) on CELLS cells per H, talus-implicit to t = 2 s with
      dt = 0.01 s. EXPECT is 'stand' or 'collapse':
        stand:    every point moved less than 2 % of H (so did the front and the top surface),
                  and at most 10 % of the points carry an accumulated plastic strain above 1 % (no
                  plastic flow through the column);
        collapse: the front ran out more than 25 % of H beyond the initial face, the initial
                  top surface settled more than 10 % of H (mean of its points), and a failure
                  surface: at least 10 % of the points carry a plastic strain above 10 % while at
                  least 10 % moved less than 2 % of H (a mass slid on a band past a part that
                  stayed).
      --set entries are applied to the scene (e.g. the mutant material 0/hencky mohr
      coulomb/cohesion=2500).
  check_cohesive_column.py gravity TOOLS_DIR PRM_ROOT WORKDIR RATIO CELLS[,CELLS...] LOW HIGH [--set=...]
      The square column of RATIO x H_c on CELLS cells per H, static, the gravity ramped over 100
      load steps until Newton fails (exit 3): the last converged gravity factor lambda_c gives the
      numerical critical height lambda_c x RATIO x H_c (similar columns fail at one gamma H / c).
      Checks per grid: the run stops before the full gravity, and at lambda_c the column is a
      mechanism (the centre of mass's sideways shift at least 3 x its elastic extrapolation from
      lambda_c / 2), not a Newton stall; on the finest grid the critical height lies within
      [LOW, HIGH] x H_c; with several grids it falls as the grid is refined. Also printed: the
      plastic band's inclination and where it meets the top (Culmann's plane: 45 + phi/2).
  check_cohesive_column.py deposit TOOLS_DIR PRM_ROOT WORKDIR REFINE[,REFINE...] TOL_FAMILIES TOL_MESH
                           [--set=entry=value ...]
      The scene as given (h = 0.05 m / REFINE; implicit dt = 5e-3 s / REFINE) by talus-implicit and
      talus-explicit: both must collapse (as above); the run-out r = d_inf - W of the deposit at
      t = 2 s of the two families within TOL_FAMILIES x r_explicit of each other at every REFINE;
      with two REFINE values, each family's run-out on the two grids within TOL_MESH x r of each
      other (the mesh convergence). --set entries change the talus-implicit run only (a mutant).
"""
import glob
import importlib.machinery
import importlib.util
import math
import os
import re
import sys
import time

import talus_verify as tv

# talus-plot's VTU reader (the accumulated plastic strain is a history field: in the VTU files, not in
# particles_final.csv)
_loader = importlib.machinery.SourceFileLoader(
    "talus_plot", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "talus-plot"))
_spec = importlib.util.spec_from_loader("talus_plot", _loader)
talus_plot = importlib.util.module_from_spec(_spec)
_loader.exec_module(talus_plot)

STAND_MOVE, STAND_PLASTIC_SHARE, STAND_PLASTIC = 0.02, 0.10, 0.01
COLLAPSE_RUNOUT, COLLAPSE_DROP, BAND_STRAIN, BAND_SHARE, STAYED_SHARE = 0.25, 0.10, 0.10, 0.10, 0.10


def inline_includes(path):
    """The .prm text with every `include FILE` line replaced by FILE's text (relative to the file)."""
    out = []
    for line in open(path).read().splitlines():
        m = re.match(r"\s*include\s+(\S+)\s*$", line)
        out.append(inline_includes(os.path.join(os.path.dirname(path), m.group(1))) if m else line)
    return "\n".join(out) + "\n"


def floats(text, path):
    return [float(x) for x in tv.prm_get(text, path).split(",")]


def material(text):
    rho = floats(text, "material 0/density")[0]
    g = abs(floats(text, "gravity/acceleration")[1])
    c = floats(text, "material 0/hencky mohr coulomb/cohesion")[0]
    phi = math.radians(floats(text, "material 0/hencky mohr coulomb/friction angle")[0])
    return rho * g, c, phi


def critical_heights(text):
    gamma, c, phi = material(text)
    kp = math.tan(math.pi / 4 + phi / 2)
    return {"chen": 3.83 * c / gamma * kp, "wedge": 4 * c / gamma * kp, "lower": 2 * c / gamma * kp}


def run(tool, text, work, name, allow_unstable=False, vtu_interval="0"):
    text = tv.prm_set(text, "output/directory", "out")
    text = tv.prm_set(text, "output/final particles csv", "true")
    text = tv.prm_set(text, "output/progress", "false")
    text = tv.prm_set(text, "output/vtu interval", vtu_interval)
    rc, out, err = tv.run_tool(tool, text, f"{work}/{name}", name, expect_rc=None)
    if rc != 0 and not (allow_unstable and rc == 3):
        sys.stdout.write(out[-3000:])
        sys.stderr.write(err[-3000:])
        tv.fail(f"{name}: exit code {rc}")
    with open(f"{work}/{name}/log.txt", "w") as f:
        f.write(out + err)
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    cut = re.search(r"cut-backs (\d+)", out)
    s["cut_backs"] = int(cut.group(1)) if cut else 0
    if rc != 0:  # an unstable static run: the series and the VTU output up to its last converged step
        return s, None, out
    p = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    # the last VTU output (the final state) of every rank: history_7 by point id
    last = sorted(glob.glob(f"{work}/{name}/out/particles_*.pvtu"))[-1][: -len(".pvtu")]
    eps = {}
    for piece in glob.glob(last + ".*.vtu"):
        _, arrays = talus_plot.read_vtu(piece, ["id", "history_7"])
        eps.update(zip((int(i) for i in arrays["id"][1]), arrays["history_7"][1]))
    tv.check(len(eps) == len(p["id"]), f"{name}: the final VTU holds every point ({len(eps)} of {len(p['id'])})")
    p["eps_p"] = [eps[int(i)] for i in p["id"]]
    return s, p, out


def final_vtu_field(work, name, field):
    """{point id: value} of `field` in the last VTU output of a run (every rank's piece)."""
    last = sorted(glob.glob(f"{work}/{name}/out/particles_*.pvtu"))[-1][: -len(".pvtu")]
    values = {}
    for piece in glob.glob(last + ".*.vtu"):
        pts, arrays = talus_plot.read_vtu(piece, ["id", field])
        values.update(zip((int(i) for i in arrays["id"][1]), zip(pts, arrays[field][1])))
    return values


def square_column(text, ratio, cells):
    """The scene with a square column H = W = ratio x H_c on `cells` cells per H (grid 3 H x (H + 2 h))."""
    H = ratio * critical_heights(text)["chen"]
    h = H / cells
    nx, ny = 3 * cells, cells + 2
    text = tv.prm_set(text, "body 0/upper corner", f"{H!r}, {H!r}")
    text = tv.prm_set(text, "grid/upper corner", f"{nx * h!r}, {ny * h!r}")
    return tv.prm_set(text, "grid/cells", f"{nx}, {ny}")


def band_angle(values, W, H, rows):
    """Inclination [deg] of the plastic band: per row of height H / rows (its middle 80 %), the
    plastic-strain-weighted x of the points above half the row's largest strain; a line fitted
    through those centres (the band runs from the toe (W, 0) up towards the wall); also the x where
    it meets the top row."""
    by_row = {}
    for (x, y, _), e in values.values():
        k = int(y / H * rows)
        if 0 <= k < rows:
            by_row.setdefault(k, []).append((e, x))
    xs, ys = [], []
    for k, pts in sorted(by_row.items()):
        top = max(e for e, _ in pts)
        if top <= 0:
            continue
        sel = [(e, x) for e, x in pts if e > 0.5 * top]
        xc = sum(e * x for e, x in sel) / sum(e for e, _ in sel)
        yc = (k + 0.5) * H / rows
        if 0.1 * H < yc < 0.9 * H:
            xs.append(xc)
            ys.append(yc)
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return math.degrees(math.atan(-slope)), mx + (H - my) / slope


def measures(text, s, p):
    """Final-state figures of a run: H, W, front, crest, moved and plastic shares."""
    lo, up = floats(text, "body 0/lower corner"), floats(text, "body 0/upper corner")
    W, H = up[0] - lo[0], up[1] - lo[1]
    cells = floats(text, "grid/cells")
    g_lo, g_hi = floats(text, "grid/lower corner"), floats(text, "grid/upper corner")
    hx = (g_hi[0] - g_lo[0]) / cells[0]
    spacing = hx / floats(text, "body 0/particles per direction")[0]
    xs, ys = p["pos_x"], p["pos_y"]
    fronts = [tv.deposit_front(xs, hx, g_lo[0] - q * hx / 4)[0] for q in range(4)]
    front = sum(fronts) / 4 + 0.5 * spacing
    crest = max(ys) + 0.5 * spacing
    # the settlement of the initial top surface: the mean -u_y of the points of the top row
    top = [-uy for y, uy in zip(ys, p["u_y"]) if y - uy > lo[1] + H - spacing]
    u = [math.hypot(a, b) for a, b in zip(p["u_x"], p["u_y"])]
    eps = p["eps_p"]  # Hencky Mohr-Coulomb: accumulated plastic strain (history 7)
    n = len(xs)
    m = {"H": H, "W": W, "front": front, "runout": front - W, "crest": crest, "drop": sum(top) / len(top),
         "umax": max(u), "n": n, "eps_max": max(eps),
         "plastic_share": sum(1 for e in eps if e > STAND_PLASTIC) / n,
         "band_share": sum(1 for e in eps if e > BAND_STRAIN) / n,
         "stayed_share": sum(1 for v in u if v < STAND_MOVE * H) / n,
         "ke_end": s["kinetic_energy"][-1], "ke_peak": max(s["kinetic_energy"]),
         "steps": int(s["step"][-1]), "t_end": s["time"][-1], "cut_backs": s["cut_backs"]}
    return m


def describe(name, m):
    print(f"{name}: H = {m['H']:.4f} m, W = {m['W']:.4f} m, {m['n']} points, t = {m['t_end']:.3f} s, "
          f"{m['steps']} steps ({m['cut_backs']} cut-backs); front {m['front']:.4f} m "
          f"(run-out {m['runout']:+.4f} m = {m['runout'] / m['H']:+.3f} H), "
          f"crest {m['crest']:.4f} m, top surface settled {m['drop'] / m['H']:+.4f} H, largest |u| {m['umax']:.4g} m "
          f"({m['umax'] / m['H']:.4f} H); plastic strain max {m['eps_max']:.3g}, share > {STAND_PLASTIC:g}: "
          f"{m['plastic_share']:.3f}, > {BAND_STRAIN:g}: {m['band_share']:.3f}; moved < {STAND_MOVE:g} H: "
          f"{m['stayed_share']:.3f}; kinetic energy end / peak {m['ke_end']:.3g} / {m['ke_peak']:.3g} J")


def check_stand(name, m):
    tv.check(m["umax"] < STAND_MOVE * m["H"], f"{name} stands: largest displacement {m['umax'] / m['H']:.4f} H "
             f"< {STAND_MOVE} H")
    tv.check(abs(m["runout"]) < STAND_MOVE * m["H"] and m["drop"] < STAND_MOVE * m["H"],
             f"{name} stands: front moved {m['runout'] / m['H']:+.4f} H, "
             f"top surface settled {m['drop'] / m['H']:+.4f} H")
    tv.check(m["plastic_share"] <= STAND_PLASTIC_SHARE, f"{name}: no plastic flow through the column "
             f"({100 * m['plastic_share']:.1f} % of the points above {STAND_PLASTIC:g} plastic strain, "
             f"at most {100 * STAND_PLASTIC_SHARE:.0f} %)")


def check_collapse(name, m, failure_surface=True):
    tv.check(m["runout"] > COLLAPSE_RUNOUT * m["H"], f"{name} collapses: run-out {m['runout'] / m['H']:.3f} H "
             f"> {COLLAPSE_RUNOUT} H")
    tv.check(m["drop"] > COLLAPSE_DROP * m["H"],
             f"{name} collapses: the top surface settled {m['drop'] / m['H']:.3f} H "
             f"> {COLLAPSE_DROP} H")
    if failure_surface:
        tv.check(m["band_share"] >= BAND_SHARE and m["stayed_share"] >= STAYED_SHARE,
                 f"{name}: a failure surface ({100 * m['band_share']:.1f} % of the points above "
                 f"{BAND_STRAIN:g} plastic strain, {100 * m['stayed_share']:.1f} % moved less than {STAND_MOVE} H; "
                 f"each at least {100 * BAND_SHARE:.0f} %)")


mode = sys.argv[1]
tools, prm_root, work = sys.argv[2:5]
base = inline_includes(f"{prm_root}/implicit/cohesive_column.prm")
hc = critical_heights(base)
print(f"critical height of a vertical cut: H_c = 3.83 c / gamma tan(45 + phi/2) = {hc['chen']:.4f} m "
      f"(planar wedge 4 c / gamma ...: {hc['wedge']:.4f} m; lower bound 2 c / gamma ...: {hc['lower']:.4f} m)")

if mode == "bracket":
    cells = int(sys.argv[5])
    cases = [(float(a), b) for a, b in (x.split(":") for x in sys.argv[6].split(","))]
    settings = [a[len("--set="):] for a in sys.argv[7:] if a.startswith("--set=")]
    for ratio, expect in cases:
        if expect not in ("stand", "collapse"):
            tv.fail(f"expectation '{expect}' is neither 'stand' nor 'collapse'")
        text = tv.prm_set(square_column(base, ratio, cells), "time/time step", "0.01")
        text = tv.prm_set_args(text, settings)
        name = f"ratio{ratio:g}"
        t0 = time.time()
        s, p, _ = run(f"{tools}/talus-implicit", text, work, name)
        m = measures(text, s, p)
        describe(f"H = {ratio:g} H_c ({time.time() - t0:.1f} s)", m)
        (check_stand if expect == "stand" else check_collapse)(f"H = {ratio:g} H_c", m)
elif mode == "gravity":
    ratio = float(sys.argv[5])
    cells_list = [int(x) for x in sys.argv[6].split(",")]
    low, high = float(sys.argv[7]), float(sys.argv[8])
    settings = [a[len("--set="):] for a in sys.argv[9:] if a.startswith("--set=")]
    results = []
    for cells in cells_list:
        text = square_column(base, ratio, cells)
        text = tv.prm_set(text, "implicit/analysis", "static")
        text = tv.prm_set(text, "time/end time", "1")
        text = tv.prm_set(text, "time/time step", "0.01")
        text = tv.prm_set_args(text, settings)
        hc_run = critical_heights(text)["chen"]  # of the material as run (a mutant's own H_c)
        name = f"cells{cells}"
        t0 = time.time()
        # a VTU file every load step: the last converged state is the last one written
        s, p, out = run(f"{tools}/talus-implicit", text, work, name, allow_unstable=True, vtu_interval="0.01")
        lam = s["load_factor"]
        H = ratio * hc["chen"]
        lam_c = lam[-1]
        # the mechanism: the centre of mass's sideways shift at lam_c against its elastic
        # extrapolation from the last row at or below lam_c / 2
        dx = [x - s["centre_of_mass_x"][0] for x in s["centre_of_mass_x"]]
        i_half = max(i for i in range(len(lam)) if lam[i] <= lam_c / 2)
        amplification = dx[-1] / (dx[i_half] * lam_c / lam[i_half]) if dx[i_half] > 0 else float("inf")
        angle, exit_x = band_angle(final_vtu_field(work, name, "history_7"), H, H, cells)
        h_num = lam_c * H
        results.append((cells, h_num))
        print(f"{cells} cells per H ({H / cells:.4g} m), H = {ratio:g} H_c = {H:.4f} m: last converged gravity "
              f"factor {lam_c:.5f} (steps {int(s['step'][-1])}), numerical critical height {h_num:.4f} m = "
              f"{h_num / hc_run:.4f} H_c of this material; sideways shift of the centre of mass "
              f"{dx[-1]:.3e} m, {amplification:.1f} x its elastic extrapolation; plastic band inclined "
              f"{angle:.1f} deg (planar wedge 45 + phi/2 = "
              f"{45 + math.degrees(material(text)[2]) / 2:.1f} deg), meeting the top {H - exit_x:.3f} m "
              f"= {(H - exit_x) / H:.3f} H behind the face ({time.time() - t0:.1f} s)")
        tv.check(lam_c < 1, f"{cells} cells: the column of {ratio:g} H_c fails before the full gravity "
                 f"(factor {lam_c:.5f})")
        tv.check(amplification >= 3, f"{cells} cells: at the last converged factor a mechanism (the sideways "
                 f"shift {amplification:.1f} x its elastic extrapolation, at least 3)")
    cells, h_num = results[-1]
    tv.check(low * hc["chen"] <= h_num <= high * hc["chen"],
             f"finest grid ({cells} cells per H): numerical critical height {h_num / hc['chen']:.4f} H_c "
             f"within [{low:g}, {high:g}] H_c of the scene's material")
    if len(results) > 1:
        tv.check(all(b[1] < a[1] for a, b in zip(results, results[1:])),
                 "the numerical critical height falls as the grid is refined (Q1 overestimates collapse loads): "
                 + ", ".join(f"{c}: {v / hc['chen']:.4f} H_c" for c, v in results))
    if len(results) > 1:
        print("change per refinement: " + ", ".join(f"{(b[1] - a[1]) / hc['chen']:+.4f} H_c"
                                                  for a, b in zip(results, results[1:])))
elif mode == "deposit":
    refines = [float(x) for x in sys.argv[5].split(",")]
    tol_families, tol_mesh = float(sys.argv[6]), float(sys.argv[7])
    settings = [a[len("--set="):] for a in sys.argv[8:] if a.startswith("--set=")]  # talus-implicit's only
    explicit = inline_includes(f"{prm_root}/verification/cohesive_column/column_explicit.prm")
    results = {}
    for r in refines:
        for family, text, tool in (("implicit", base, "talus-implicit"), ("explicit", explicit, "talus-explicit")):
            cells = [int(round(c * r)) for c in floats(text, "grid/cells")]
            text = tv.prm_set(text, "grid/cells", ", ".join(str(c) for c in cells))
            if family == "implicit":
                text = tv.prm_set(text, "time/time step", repr(floats(text, "time/time step")[0] / r))
                text = tv.prm_set_args(text, settings)
            t0 = time.time()
            s, p, _ = run(f"{tools}/{tool}", text, work, f"{family}_refine{r:g}")
            m = measures(text, s, p)
            hx = (floats(text, "grid/upper corner")[0] - floats(text, "grid/lower corner")[0]) / cells[0]
            describe(f"{family}, h = {hx:.4g} m ({time.time() - t0:.1f} s)", m)
            check_collapse(f"{family}, h = {hx:.4g} m", m, failure_surface=False)
            results[(family, r)] = m
        ri, re_ = results[("implicit", r)]["runout"], results[("explicit", r)]["runout"]
        ci, ce = results[("implicit", r)]["crest"], results[("explicit", r)]["crest"]
        tv.check(abs(ri - re_) <= tol_families * re_,
                 f"refine {r:g}: implicit run-out {ri:.4f} m vs explicit {re_:.4f} m ({100 * (ri - re_) / re_:+.2f} %, "
                 f"tolerance {100 * tol_families:.0f} %); crest {ci:.4f} vs {ce:.4f} m ({100 * (ci - ce) / ce:+.2f} %)")
    if len(refines) == 2:
        r0, r1 = refines
        for family in ("implicit", "explicit"):
            a, b = results[(family, r0)]["runout"], results[(family, r1)]["runout"]
            ca, cb = results[(family, r0)]["crest"], results[(family, r1)]["crest"]
            tv.check(abs(a - b) <= tol_mesh * b,
                     f"{family} mesh convergence: run-out {a:.4f} m (refine {r0:g}) vs {b:.4f} m (refine {r1:g}), "
                     f"{100 * (a - b) / b:+.2f} % (tolerance {100 * tol_mesh:.0f} %); crest {ca:.4f} vs {cb:.4f} m "
                     f"({100 * (ca - cb) / cb:+.2f} %)")
else:
    tv.fail(f"mode '{mode}' is neither 'bracket' nor 'deposit'")
tv.finish()
