"""Nor-Sand landslide, dense vs loose, double- vs single-point: the paper's §5.4
(seed 002, issue 14; Tables 5-6, Figs. 9-10).

Four runs of the same .prm (parameter_files/verification/semi_implicit_landslide.prm):
dense (v0 = 1.55, to END_DENSE) and loose (v0 = 1.70, to END_LOOSE), each with
`point sets = double` and `single`. The end times include the 1 s App. B.4
initialisation (the paper: 12 s dense, 6 s loose after it).

Measures, from <set>_final.csv:
  run-out   = advance of the soil front: largest x of the soil points now minus the
              largest initial x (x - u) of the soil points;
  gap       = the largest height by which the soil surface stands above the water
              surface: in every column of width h that holds soil, top of the soil
              points minus top of the water points (the 95th percentile over the
              columns, so that one stray point does not decide it); 0 in a
              single-point run, where the water points sit on the soil points.
Checks (the paper's findings, §5.4):
  1. dense: run-out(double) > RATIO x run-out(single)  (the single-point run
     "cannot fully generate" the landslide; RATIO = 1.10 by default);
  2. dense double: the gap opens, gap > GAP_MIN = h / 4 (half the point spacing at
     2 x 2 points per cell), and exceeds the loose double-point gap;
  3. loose: |run-out(double) - run-out(single)| <= 10 % of their mean;
  4. every run reaches its end time with no point lost and finite fields;
  5. every run ends with bounded effective stresses: no soil point's mean effective
     stress exceeds STRESS_FACTOR = 2 x the largest geostatic one of the initial slope,
     (1 - n0)(rho_s - rho_w) g H0, H0 the height of the highest soil point at t = 0
     (the deposit is lower than the slope and near rest at the end; a point whose
     stress is not its volume's, the 2026-12-04 modified F-bar bug, had 17 x);
  6. every Nor-Sand soil point carries its model's Kirchhoff stress over its own J:
     mean(sigma') V/V0 = p_ref exp(-(eps_v^e - eps_v,ref) / kappa) with eps_v^e =
     ln det(b_e) / 2 from the stored b_e (history 0-5, 11, 12), to TAU_TOL relative
     (the points above the gas-like cut-off, tau = 0, are left out). The modified
     F-bar bug broke it by up to 16 x on the 0.1 m grid (docs/semi-implicit.md).
With --resume (the runs at the paper's resolution, hours each): every run writes a
checkpoint every RESUME wall-clock seconds (default 900) and starts from its newest
checkpoint if there is one, so an interrupted campaign goes on where it stopped; a run
whose final CSVs already reach its end time is not run again. Each segment's output is
appended to WORKDIR/<run>/<run>.log, and check 4 reads every segment's summary there.
Usage: check_semi_landslide.py TOOL PRM WORKDIR [--set=entry=value ...]
       [--dense-end=T] [--loose-end=T] [--ratio=R] [--only=dense|loose]
       [--resume[=SECONDS]] [--runs=dense_double,dense_single,...]
"""
import math
import os
import sys

import talus_verify as tv

opts = {a[2:].split("=", 1)[0]: (a.split("=", 1)[1] if "=" in a else "") for a in sys.argv
        if a.startswith("--") and not a.startswith("--set=")}
sets = [a[len("--set="):].split("=", 1) for a in sys.argv if a.startswith("--set=")]
args = [a for a in sys.argv if not a.startswith("--")]
tool, prm_path, work = args[1], args[2], args[3]
dense_end = float(opts.get("dense-end", 13.0))
loose_end = float(opts.get("loose-end", 7.0))
ratio_min = float(opts.get("ratio", 1.10))
only = opts.get("only")
resume = "resume" in opts
resume_seconds = float(opts.get("resume") or 900)
selected = opts.get("runs", "").split(",") if opts.get("runs") else None

base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
for entry, value in sets:
    base = tv.prm_set(base, entry.strip(), value.strip())


def grid_h(text):
    lo = hi = cells = None
    for line in text.splitlines():
        s = line.split("#", 1)[0].strip()
        if s.startswith("set lower corner"):
            lo = [float(v) for v in s.split("=", 1)[1].split(",")]
        elif s.startswith("set upper corner"):
            hi = [float(v) for v in s.split("=", 1)[1].split(",")]
        elif s.startswith("set cells"):
            cells = [int(v) for v in s.split("=", 1)[1].split(",")]
    return (hi[0] - lo[0]) / cells[0]


h = grid_h(base)
gap_min = h / 4
STRESS_FACTOR = 2.0
TAU_TOL = 1e-6


def tops(t, width):
    top = {}
    for x, y in zip(t["pos_x"], t["pos_y"]):
        b = math.floor(x / width)
        top[b] = max(top.get(b, -1e30), y)
    return top


def percentile(values, q):
    v = sorted(values)
    if not v:
        return 0.0
    k = min(len(v) - 1, max(0, int(round(q * (len(v) - 1)))))
    return v[k]


def reached(d, end):
    """Whether the run in output directory d has its final CSVs at its end time."""
    try:
        series = tv.read_csv(os.path.join(d, "series.csv"))
    except (OSError, IndexError):
        return False
    return (os.path.exists(os.path.join(d, "soil_final.csv")) and os.path.exists(os.path.join(d, "water_final.csv"))
            and bool(series["time"]) and abs(series["time"][-1] - end) < 1e-6 * end)


def run_resumable(text, name, end, d):
    """Runs (or resumes) one run; returns the output of all its segments."""
    run_dir = os.path.join(work, name)
    log = os.path.join(run_dir, name + ".log")
    if not reached(d, end):
        text = tv.prm_set(text, "checkpoint/restart", "if available")
        text = tv.prm_set(text, "checkpoint/wall clock interval", str(resume_seconds))
        text = tv.prm_set(text, "checkpoint/keep", "1")
        print(f"{name}: running (or resuming) to t = {end} s; checkpoints every {resume_seconds:g} s of wall time", flush=True)
        os.makedirs(run_dir, exist_ok=True)
        # the output goes straight to the log, so that a segment that is stopped keeps its lines
        tv.run_tool(tool, text, run_dir, name, timeout=48 * 3600, log=log)
    else:
        print(f"{name}: already at t = {end} s; reading its output", flush=True)
    return open(log).read() if os.path.exists(log) else ""


results = {}
cases = [("dense", 1.55, dense_end), ("loose", 1.70, loose_end)]
if only:
    cases = [c for c in cases if c[0] == only]
for density, v0, end in cases:
    for sets_name in ("double", "single"):
        name = f"{density}_{sets_name}"
        text = tv.prm_set(base, "material 0/nor sand/initial specific volume", str(v0))
        text = tv.prm_set(text, "semi implicit/point sets", sets_name)
        text = tv.prm_set(text, "time/end time", str(end))
        if selected and name not in selected:
            continue
        d = os.path.join(work, name, "out")
        if resume:
            out = run_resumable(text, name, end, d)
        else:
            rc, out, err = tv.run_tool(tool, text, os.path.join(work, name), name, timeout=4 * 3600)
        soil = tv.read_csv(os.path.join(d, "soil_final.csv"))
        water = tv.read_csv(os.path.join(d, "water_final.csv"))
        series = tv.read_csv(os.path.join(d, "series.csv"))
        finite = all(math.isfinite(v) for col in ("pos_x", "pos_y", "stress_xx", "stress_yy") for v in soil[col])
        tv.check(finite, f"{name}: finite soil fields")
        tv.check(abs(series["time"][-1] - end) < 1e-6 * end, f"{name}: reached t = {series['time'][-1]:.4g} (end {end})")
        lost = [l for l in out.splitlines() if "lost points" in l]
        tv.check(bool(lost) and all("lost points 0" in l for l in lost),
                 f"{name}: no point lost ({len(lost)} run segment(s); last: {lost[-1].strip() if lost else 'no summary line'})")
        # check 5: (1 - n0) rho_s = m / V0 of a soil point; rho_w g H0 from the .prm
        rho_w = float(tv.prm_get(text, "semi implicit/water density"))
        g = abs(float(tv.prm_get(text, "gravity/acceleration").split(",")[-1]))
        H0 = max(y - v for y, v in zip(soil["pos_y"], soil["displacement_y"]))
        geostatic = max((m / V0 - (1 - n0) * rho_w) * g * H0
                        for m, V0, n0 in zip(soil["mass"], soil["initial_volume"], soil["initial_porosity"]))
        mean_stress = [-(a + b + c) / 3 for a, b, c in zip(soil["stress_xx"], soil["stress_yy"], soil["stress_zz"])]
        tv.check(max(mean_stress) <= STRESS_FACTOR * geostatic,
                 f"{name}: largest mean effective stress {max(mean_stress):.0f} Pa <= {STRESS_FACTOR} x the geostatic "
                 f"{geostatic:.0f} Pa (H0 = {H0:.3f} m)")
        # check 6: sigma' J = tau of the model, from b_e
        kappa = float(tv.prm_get(text, "material 0/nor sand/swelling index"))
        try:
            gas = float(tv.prm_get(text, "material 0/nor sand/gas cutoff factor"))
        except KeyError:
            gas = 1.6  # the tool's default
        worst, counted = 0.0, 0
        for i in range(len(soil["pos_x"])):
            if soil["history_7"][i] > 0.999 * gas * v0:
                continue
            b = [[soil[f"history_{k}"][i] for k in row] for row in ((0, 3, 5), (3, 1, 4), (5, 4, 2))]
            tau = soil["history_11"][i] * math.exp(-(0.5 * math.log(tv.det3(b)) - soil["history_12"][i]) / kappa)
            if abs(tau) < 1e-3:
                continue
            sigma = (soil["stress_xx"][i] + soil["stress_yy"][i] + soil["stress_zz"][i]) / 3
            worst = max(worst, abs(sigma * soil["volume"][i] / soil["initial_volume"][i] - tau) / abs(tau))
            counted += 1
        tv.check(counted > 0 and worst < TAU_TOL,
                 f"{name}: mean(sigma') V/V0 = the model's tau from b_e at {counted} points, worst {worst:.2e} relative "
                 f"(< {TAU_TOL:g})")
        runout = max(soil["pos_x"]) - max(x - u for x, u in zip(soil["pos_x"], soil["displacement_x"]))
        st, wt = tops(soil, h), tops(water, h)
        gaps = [st[b] - wt[b] for b in st if b in wt]
        gap = percentile(gaps, 0.95)
        crest = max(soil["pos_y"])
        results[name] = (runout, gap)
        wall = [l for l in out.splitlines() if "done:" in l]
        print(f"{name}: v0 = {v0}, t = {end} s, run-out {runout:.4f} m, gap (95th pct over columns) {gap:.4f} m, "
              f"max gap {max(gaps) if gaps else 0:.4f} m, highest soil point {crest:.4f} m, "
              f"max soil speed at end {series['max_speed_soil'][-1]:.3g} m/s")
        if wall:
            print("   ", wall[-1].strip())

print(f"grid h = {h} m; gap threshold {gap_min:.4f} m; dense ratio threshold {ratio_min}")
if "dense_double" in results and "dense_single" in results:
    dd, ds = results["dense_double"], results["dense_single"]
    tv.check(dd[0] > ratio_min * ds[0],
             f"dense: double-point run-out {dd[0]:.4f} m > {ratio_min} x single-point {ds[0]:.4f} m (ratio {dd[0] / max(ds[0], 1e-12):.3f})")
    tv.check(dd[1] > gap_min, f"dense double: soil-water gap {dd[1]:.4f} m > {gap_min:.4f} m")
    tv.check(ds[1] < 1e-9, f"dense single: no gap ({ds[1]:.2e} m; the water points ride on the soil)")
    if "loose_double" in results:
        tv.check(dd[1] > results["loose_double"][1],
                 f"dense double gap {dd[1]:.4f} m > loose double gap {results['loose_double'][1]:.4f} m")
if "loose_double" in results and "loose_single" in results:
    ld, lsg = results["loose_double"], results["loose_single"]
    mean = 0.5 * (ld[0] + lsg[0])
    tv.check(abs(ld[0] - lsg[0]) <= 0.10 * mean,
             f"loose: run-outs {ld[0]:.4f} m (double) and {lsg[0]:.4f} m (single) within 10 % of their mean "
             f"({abs(ld[0] - lsg[0]) / max(mean, 1e-12) * 100:.1f} %)")
tv.finish()
