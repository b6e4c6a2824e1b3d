#!/usr/bin/env python3
"""The verification campaign of `make verify` (issue 6).

1. convergence families (talus-convergence on parameter_files/convergence/*.prm);
2. the work-precision campaign across the families (issue 42: shared scenes, one
   talus-convergence family per tool and option set, tests/verification/work_precision.py);
3. stability stress tests, each pass/fail by a stated criterion (and the cell-crossing
   growth rate measured against the Floquet analysis):
   * Courant sweeps (talus-critical-dt --probe: bisection on forced runs) of the explicit
     formulations: 1-phase solid (bar), 1-phase liquid (water column), 2-phase (Terzaghi);
   * large deformation: the colliding elastic disks (points cross many cells) with the
     total energy balance;
   * near-incompressible elasticity (nu = 0.49, 0.499) with and without strain smoothing
     (tests/verification/check_smoothing.py);
4. regenerates docs/verification/README.md (+ csv/, png/) from the CSVs of this run.

Usage: verify_campaign.py BUILD_DIR [--only=a,b] [--readme-only]
Exit 0 if every criterion holds, 1 otherwise (the README is written in both cases).
"""
import csv
import glob
import math
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PRM = os.path.join(ROOT, "parameter_files")
DOCS = os.path.join(ROOT, "docs", "verification")

# (name of parameter_files/convergence/<name>.prm, criterion text, test on (summary, rows))
FAMILIES = [
    ("bar_displacement", "order >= 1.8", lambda s, r: s["observed_order"] >= 1.8),
    ("bar_period", "order >= 1.8", lambda s, r: s["observed_order"] >= 1.8),
    ("bar_points_per_cell", "error <= 1e-3 for every n (no order expected: the h error dominates)",
     lambda s, r: max(x["error"] for x in r) <= 1e-3),
    ("column_settlement", "error <= 1 % for N <= 16 (no point crosses a cell face); from N = 32 on the top "
     "points cross a face at the peak settlement (0.015 m > h/4) and the cell-crossing error appears",
     lambda s, r: max(x["error"] for x in r if x["value"] <= 16) <= 0.01),
    ("bar_courant", "order >= 1.8 (central differences in time; Richardson against the finest run)",
     lambda s, r: s["observed_order"] >= 1.8),
    ("oedometer", "error <= 1 % at every resolution and order >= 0.8 (first order expected: the traction acts on "
     "the points of the top layer, h/4 below the face)",
     lambda s, r: max(x["error"] for x in r) <= 0.01 and s["observed_order"] >= 0.8),
    ("terzaghi", "error <= 3 % at every resolution and order >= 0.8 (first order expected: load and drainage act "
     "on the points of the top layer)",
     lambda s, r: max(x["error"] for x in r) <= 0.03 and s["observed_order"] >= 0.8),
    ("translating_bar", "order < 1 (predicted loss of convergence under cell crossing)",
     lambda s, r: s["observed_order"] < 1.0),
    ("translating_bar_courant", "error at Courant 0.1 below the error at 0.4 (crossing error depends on dt)",
     lambda s, r: {x["value"]: x["error"] for x in r}[0.1] < {x["value"]: x["error"] for x in r}[0.4]),
    # Courant sweeps run to the end time (stress tests; no order expected)
    ("courant_solid_bar", "Courant sweep to the end time: every run completes and error <= 1e-3 up to 1.0 x Eq. 4.120",
     lambda s, r: len(r) == 4 and max(x["error"] for x in r) <= 1e-3),
    ("courant_liquid", "Courant sweep to the end time: every run completes and the pressure is within 2 % of "
     "rho g (H - Y) at every point, up to 1.0 x the viscous limit",
     lambda s, r: len(r) == 4 and max(x["error"] for x in r) <= 0.02),
    ("courant_two_phase", "Courant sweep to the end time: every run completes and the pore-pressure error is "
     "<= 3 % up to 1.0 x Eq. 4.129", lambda s, r: len(r) == 4 and max(x["error"] for x in r) <= 0.03),
]

# the final state of the large-deformation case, drawn by the run itself (talus-plot)
LARGE_DEFORMATION_PNG = "large_deformation_disks.png"

# Courant sweeps: (name, .prm, formulation)
# (name, .prm, formulation, the analysed limit the measured one is compared with)
SWEEPS = [
    ("solid_bar", "verification/bar_vibration.prm", "1-phase solid", "dt_scheme"),
    ("solid_disks_moving", "verification/disks_collision.prm", "1-phase solid (points crossing cells)",
     "dt_scheme_moved"),
    ("liquid_water_column", "verification/hydrostatic_water_1phase.prm", "1-phase liquid", ""),
    ("two_phase_terzaghi", "verification/terzaghi_consolidation.prm", "2-phase coupled", ""),
]


def env():
    e = dict(os.environ)
    e.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMP_NUM_THREADS": "1",
              "PYTHONPATH": os.path.join(ROOT, "tests", "verification")})
    return e


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))

    def v(x):
        try:
            return float(x)
        except ValueError:
            return x
    return [{k: v(x) for k, x in r.items()} for r in rows]


def write_atomic(path, text):
    with open(path + ".part", "w") as f:
        f.write(text)
    os.replace(path + ".part", path)


def run_families(build, work, only):
    tool = os.path.join(build, "tools", "talus-convergence")
    for name, _, _ in FAMILIES:
        if only and name not in only:
            continue
        prm = os.path.join(PRM, "convergence", name + ".prm")
        print(f"== convergence: {name}", flush=True)
        p = subprocess.run([tool, prm], cwd=work, capture_output=True, text=True, env=env())
        print(p.stdout[-2000:], p.stderr[-2000:])
        if p.returncode != 0:
            print(f"FAIL: talus-convergence {name}: exit {p.returncode}")
            continue
        out = os.path.join(work, "convergence", name)
        for f in (name + ".csv", name + "_summary.csv"):
            shutil.copy(os.path.join(out, f), os.path.join(DOCS, "csv", f))
        for f in (name + "_error.png", name + "_work.png"):
            shutil.copy(os.path.join(out, f), os.path.join(DOCS, "png", f))


def _wp():
    sys.path.insert(0, os.path.join(ROOT, "tests", "verification"))
    import work_precision
    return work_precision


WP_CSV = os.path.join(DOCS, "csv", "work_precision")


def wp_rows(name):
    p = os.path.join(WP_CSV, name + ".csv")
    return read_csv(p) if os.path.isfile(p) else None


def wp_summary(name):
    p = os.path.join(WP_CSV, name + "_summary.csv")
    return read_csv(p)[0] if os.path.isfile(p) else None


def plot_work_precision(wp, scene, work):
    """One figure per scene: error against the wall time of the time loop, log-log, one line
    per family and option set (from the CSVs in csv/work_precision/)."""
    d = os.path.join(work, "work_precision")
    os.makedirs(d, exist_ok=True)
    plots = []
    for i, f in enumerate(scene.families):
        rows = wp_rows(f.name)
        if not rows:
            continue
        data = os.path.join(d, f"{scene.name}_{f.name}.dat")
        write_atomic(data, "".join(f"{r['solver_wall_s']:.10g} {r['error']:.10g}\n" for r in rows
                                   if r["error"] > 0 and r["solver_wall_s"] > 0))
        plots.append(f"'{data}' using 1:2 with linespoints lw 2 pt {5 + i} title '{f.tool}: {f.options}'")
    if not plots:
        return
    out = os.path.join(DOCS, "png", wp.figure_name(scene))
    script = ("set terminal pngcairo size 720,520 noenhanced\nset logscale xy\nset grid\nset key top right\n"
              "set format y '%.0e'\n"
              f"set output '{out}.part'\nset title 'work-precision: {scene.name} ({scene.kind})'\n"
              "set xlabel 'wall time of the time loop [s]'\nset ylabel 'error'\n"
              "plot " + ", ".join(plots) + "\n")
    p = subprocess.run(["gnuplot"], input=script, text=True, capture_output=True)
    if p.returncode != 0:
        print("FAIL: gnuplot: " + p.stderr[-500:])
        return
    os.replace(out + ".part", out)


def run_work_precision(build, work, only):
    """The work-precision campaign across the families (issue 42): every family of every
    scene (tests/verification/work_precision.py) by talus-convergence; CSVs to
    csv/work_precision/, one figure per scene to png/."""
    wp = _wp()
    tool = os.path.join(build, "tools", "talus-convergence")
    os.makedirs(WP_CSV, exist_ok=True)
    for scene in wp.SCENES:
        if only and "work_precision" not in only and scene.name not in only:
            continue
        for f in scene.families:
            print(f"== work-precision: {scene.name}: {f.name}", flush=True)
            p = subprocess.run([tool, os.path.join(wp.PRM_DIR, f.name + ".prm")], cwd=work, capture_output=True,
                               text=True, env=env())
            print(p.stdout[-2000:], p.stderr[-2000:])
            if p.returncode != 0:
                print(f"FAIL: talus-convergence {f.name}: exit {p.returncode}")
                continue
            out = os.path.join(work, "work_precision", f.name)
            for x in (f.name + ".csv", f.name + "_summary.csv"):
                shutil.copy(os.path.join(out, x), os.path.join(WP_CSV, x))
        plot_work_precision(wp, scene, work)
    if only and "work_precision" not in only and "terzaghi_k1e-7" not in only:
        return
    for name, _, _ in wp.LOW_K:  # the cost probes of Terzaghi at k = 1e-7
        print(f"== work-precision: terzaghi_k1e-7 cost probe: {name}", flush=True)
        p = subprocess.run([tool, os.path.join(wp.PRM_DIR, name + ".prm")], cwd=work, capture_output=True,
                           text=True, env=env())
        print(p.stdout[-1500:], p.stderr[-1500:])
        if p.returncode != 0:
            print(f"FAIL: talus-convergence {name}: exit {p.returncode}")
            continue
        out = os.path.join(work, "work_precision", name)
        for x in (name + ".csv", name + "_summary.csv"):
            shutil.copy(os.path.join(out, x), os.path.join(WP_CSV, x))


def run_sweeps(build, work, only):
    tool = os.path.join(build, "tools", "talus-critical-dt")
    rows = []
    for name, prm, formulation, limit in SWEEPS:
        if only and "sweeps" not in only:
            continue
        print(f"== Courant sweep: {name}", flush=True)
        d = os.path.join(work, "sweeps", name)
        os.makedirs(d, exist_ok=True)
        out = os.path.join(d, "critical_dt.csv")
        t0 = time.perf_counter()
        p = subprocess.run([tool, "--probe", "--csv=" + out, os.path.join(PRM, prm)], cwd=d, capture_output=True,
                           text=True, env=env())
        wall = time.perf_counter() - t0
        print(p.stdout[-1500:], p.stderr[-1500:])
        if p.returncode != 0:
            rows.append({"name": name, "formulation": formulation, "prm": prm, "ok": 0, "note": f"exit {p.returncode}"})
            continue
        r = [x for x in read_csv(out) if x["controlling"] == 1][0]
        f_meas = r["probe_stable_factor"]
        ok = f_meas >= 1.0
        dt_lim = r[limit] if limit else 0.0
        if dt_lim > 0:
            ok = ok and abs(r["dt_measured"] / dt_lim - 1) <= 0.10
        rows.append({"name": name, "formulation": formulation, "prm": prm, "phase": r["phase"],
                     "formula": r["formula"], "dt_formula": r["dt_critical_formula"], "dt_scheme": dt_lim,
                     "limit": limit or "none",
                     "probe_stable_factor": f_meas, "probe_unstable_factor": r["probe_unstable_factor"],
                     "dt_measured": r["dt_measured"], "wall_s": wall, "ok": int(ok)})
    if rows:
        cols = ["name", "formulation", "prm", "phase", "formula", "dt_formula", "limit", "dt_scheme", "probe_stable_factor",
                "probe_unstable_factor", "dt_measured", "wall_s", "ok"]
        import io
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        for x in rows:
            w.writerow([f"{x[c]:.10g}" if isinstance(x.get(c), float) else x.get(c, "") for c in cols])
        write_atomic(os.path.join(DOCS, "csv", "courant_sweeps.csv"), buf.getvalue())


def run_large_deformation(build, work, only):
    if only and "large" not in only:
        return
    print("== large deformation: colliding disks", flush=True)
    d = os.path.join(work, "large_deformation")
    os.makedirs(d, exist_ok=True)
    text = open(os.path.join(PRM, "verification", "disks_collision.prm")).read()
    sys.path.insert(0, os.path.join(ROOT, "tests", "verification"))
    import talus_verify as tv
    text = tv.prm_set(text, "output/directory", ".")
    text = tv.prm_set(text, "output/final particles csv", "true")
    # the run draws its final state (talus-plot), embedded in the README
    text = tv.prm_set(text, "output/png snapshots", "final")
    text = tv.prm_set(text, "output/png field", "velocity magnitude")
    for old in glob.glob(os.path.join(d, "png", "snapshot_*.png")):
        os.remove(old)
    with open(os.path.join(d, "disks.prm"), "w") as f:
        f.write(text)
    t0 = time.perf_counter()
    p = subprocess.run([os.path.join(build, "tools", "talus-explicit"), "disks.prm"], cwd=d, capture_output=True,
                       text=True, env=env())
    wall = time.perf_counter() - t0
    s = read_csv(os.path.join(d, "series.csv")) if p.returncode == 0 else []
    e = [r["kinetic_energy"] + r["strain_energy"] for r in s]
    ratio_max = max(e) / e[0] if e else float("nan")
    ratio_end = e[-1] / e[0] if e else float("nan")
    # cell changes per point (relocation counter of the solver log)
    import re
    m = re.search(r"particles moved cell (\d+)", p.stdout)
    n_p = s[0]["n_particles"] if s else 1
    cells_crossed = int(m.group(1)) / n_p if m else float("nan")
    ok = p.returncode == 0 and ratio_max <= 1.02 and cells_crossed >= 5
    snaps = sorted(glob.glob(os.path.join(d, "png", "snapshot_*.png")))
    if snaps:
        shutil.copy(snaps[-1], os.path.join(DOCS, "png", LARGE_DEFORMATION_PNG))
    else:
        print("FAIL: the disks run drew no snapshot (output/png snapshots = final)")
        ok = False
    write_atomic(os.path.join(DOCS, "csv", "large_deformation.csv"),
                 "case,exit_code,energy_max_over_initial,energy_end_over_initial,cell_changes_per_point,"
                 f"wall_s,ok\ndisks_collision,{p.returncode},{ratio_max:.10g},{ratio_end:.10g},{cells_crossed:.10g},"
                 f"{wall:.10g},{int(ok)}\n")


def run_crossing_growth(build, work, only):
    """Growth rate of the parasitic mode under cell crossing: measured on the translating bar
    at 256 cells vs the Floquet analysis (talus-critical-dt --crossing-velocity)."""
    if only and "crossing" not in only:
        return
    sys.path.insert(0, os.path.join(ROOT, "tests", "verification"))
    import talus_verify as tv
    rows = []
    for C in (0.3, 0.5, 0.8):
        print(f"== cell-crossing growth, Courant {C}", flush=True)
        d = os.path.join(work, "crossing_growth", f"C{C}")
        os.makedirs(d, exist_ok=True)
        text = open(os.path.join(PRM, "verification", "translating_bar.prm")).read()
        for k, v in (("grid/cells", "768, 1"), ("grid/upper corner", "3, 0.00390625"),
                     ("body 0/upper corner", "1.5, 0.00390625"), ("output/directory", "."),
                     ("time/courant number", str(C)), ("time/end time", "0.25")):
            text = tv.prm_set(text, k, v)
        with open(os.path.join(d, "run.prm"), "w") as f:
            f.write(text)
        p = subprocess.run([os.path.join(build, "tools", "talus-explicit"), "run.prm"], cwd=d, capture_output=True,
                           text=True, env=env())
        q = subprocess.run([os.path.join(build, "tools", "talus-critical-dt"), "--crossing-velocity=2",
                            "--csv=dt.csv", "run.prm"], cwd=d, capture_output=True, text=True, env=env())
        if p.returncode != 0 or q.returncode != 0:
            rows.append(f"{C},nan,nan,nan,0,0")
            continue
        r = read_csv(os.path.join(d, "dt.csv"))[0]
        s = tv.read_csv(os.path.join(d, "series.csv"))
        rate, n_fit = tv.parasitic_growth_rate(s)
        pred = r["crossing_growth_rate"]
        ok = n_fit > 50 and abs(rate / pred - 1) <= 0.10
        rows.append(f"{C},{r['crossing_growth_per_step']:.10g},{pred:.10g},{rate:.10g},{n_fit},{int(ok)}")
    write_atomic(os.path.join(DOCS, "csv", "crossing_growth.csv"),
                 "courant,growth_per_step_predicted,rate_predicted,rate_measured,steps_fitted,ok\n" +
                 "".join(x + "\n" for x in rows))


def run_smoothing(build, work, only):
    if only and "smoothing" not in only:
        return
    print("== near-incompressible elasticity, strain smoothing", flush=True)
    d = os.path.join(work, "smoothing")
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, os.path.join(ROOT, "tests", "verification", "check_smoothing.py"),
                        os.path.join(build, "tools", "talus-explicit"),
                        os.path.join(PRM, "verification", "footing_incompressible.prm"), d],
                       capture_output=True, text=True, env=env())
    wall = time.perf_counter() - t0
    print(p.stdout[-3000:])
    lines = [l for l in p.stdout.splitlines() if l.startswith(("PASS:", "FAIL:"))]
    write_atomic(os.path.join(DOCS, "csv", "smoothing.csv"),
                 "criterion,ok\n" + "".join('"{}",{}\n'.format(l[5:].strip().replace('"', "'"), int(l.startswith("PASS")))
                                            for l in lines) + f'"check_smoothing.py exit code {p.returncode}, {wall:.1f} s",'
                 f"{int(p.returncode == 0)}\n")


# ------------------------------------------------------------------ README
def e3(x):
    return f"{x:.3e}"


def f2(x):
    return "-" if isinstance(x, str) or not math.isfinite(x) else f"{x:.2f}"


def readme():
    L = ["# Verification campaign (generated by `make verify`, scripts/verify_campaign.py)", "",
         "Do not edit: regenerated from the CSVs in `csv/` (which `tests/verification/check_readme.py` "
         "compares with this file in ctest). Run times are wall-clock seconds on the machine of the run "
         "(2 cores shared with other jobs: indicative only); `run time` is the whole process, `loop` the "
         "solver's time loop, `ns/pt-step` the time loop per material point and step. The runs are small "
         "(16 to a few thousand points), so `ns/pt-step` includes the per-step overheads (series output, "
         "stability check) and varies with the load of the machine; `make bench` measures throughput.", ""]
    ok_all = True
    L += ["## Convergence families and Courant sweeps", "",
          "Observed order: least-squares slope of log(error) over log(abscissa) over all runs (Richardson "
          "families: all but the finest). Definitions of the references: `talus-convergence --help`; the "
          "family inputs are in `parameter_files/convergence/`. The `courant_*` families are stability stress "
          "tests of the three explicit formulations run to the end time (no order expected).", ""]
    for name, crit, test in FAMILIES:
        sp, cp = os.path.join(DOCS, "csv", name + "_summary.csv"), os.path.join(DOCS, "csv", name + ".csv")
        if not os.path.isfile(sp):
            L += [f"### {name}", "", "not run", ""]
            ok_all = False
            continue
        s, r = read_csv(sp)[0], read_csv(cp)
        ok = test(s, r)
        ok_all = ok_all and ok
        L += [f"### {name}", "",
              f"Family: {s['parameter']}; reference: {s['solution']} ({s['reference']}).", "",
              f"Observed order: **{f2(s['observed_order'])}**. Criterion: {crit}: **{'PASS' if ok else 'FAIL'}**.", "",
              "| value | abscissa | error | pairwise order | run time [s] | loop [s] | points | steps | ns/pt-step |",
              "|---|---|---|---|---|---|---|---|---|"]
        for x in r:
            L.append(f"| {x['value']:g} | {x['abscissa']:.4g} | {e3(x['error'])} | {f2(x['pair_order'])} | "
                     f"{x['run_time_s']:.2f} | {x['solver_wall_s']:.4f} | {int(x['n_particles'])} | {int(x['n_steps'])} | "
                     f"{x['ns_per_particle_step']:.0f} |")
        L += ["", f"![error]({'png/' + name + '_error.png'}) ![work-precision]({'png/' + name + '_work.png'})", ""]
    wp_lines, wp_ok = _wp().section(wp_rows, wp_summary)
    L += wp_lines
    ok_all = ok_all and wp_ok
    L += ["## Stability stress tests", "", "### Courant sweeps (talus-critical-dt --probe)", "",
          "Bisection on the factor f of forced runs at f x the formula step (400 steps each, blow-up detected by "
          "energy growth or a non-finite state). Criterion: the measured limit is at least the formula (the "
          "default step is safe), and where a scheme limit of docs/stability-analysis.md applies the measured "
          "limit is within 10 % of it: `dt_scheme` (points at their regular positions: the bar) or "
          "`dt_scheme_moved` (the worst uniform shift of the points: the disks travel many cells during "
          "the probe runs). The liquid (viscous limit) and the 2-phase step are not analysed.", ""]
    sw = os.path.join(DOCS, "csv", "courant_sweeps.csv")
    if os.path.isfile(sw):
        L += ["| case | formulation | formula | dt formula [s] | scheme limit [s] | stable f | unstable f | "
              "measured / scheme limit | result |",
              "|---|---|---|---|---|---|---|---|---|"]
        for x in read_csv(sw):
            ok_all = ok_all and x["ok"] == 1
            L.append(f"| {x['name']} | {x['formulation']} | {x['formula']} | {e3(x['dt_formula'])} | "
                     f"{(e3(x['dt_scheme']) + ' (' + x['limit'] + ')') if x['dt_scheme'] else 'not analysed'} | "
                     f"{x['probe_stable_factor']:.4f} | {x['probe_unstable_factor']:.4f} | "
                     f"{(format(x['dt_measured'] / x['dt_scheme'], '.4f')) if x['dt_scheme'] else '-'} | "
                     f"{'PASS' if x['ok'] == 1 else 'FAIL'} |")
        L.append("")
    else:
        ok_all = False
    ld = os.path.join(DOCS, "csv", "large_deformation.csv")
    L += ["### Large deformation: colliding elastic disks", "",
          "Two elastic disks (parameter_files/verification/disks_collision.prm) move across the grid, collide and "
          "separate. Criterion: the run completes, the total energy (kinetic + strain) never exceeds 1.02 x its "
          "initial value, and the points change cell at least 5 times on average.", ""]
    if os.path.isfile(ld):
        x = read_csv(ld)[0]
        ok = x["ok"] == 1
        ok_all = ok_all and ok
        L += ["| exit code | max E / E0 | final E / E0 | cell changes per point | run time [s] | result |",
              "|---|---|---|---|---|---|",
              f"| {int(x['exit_code'])} | {x['energy_max_over_initial']:.4f} | {x['energy_end_over_initial']:.4f} | "
              f"{x['cell_changes_per_point']:.1f} | {x['wall_s']:.1f} | {'PASS' if ok else 'FAIL'} |", ""]
        if os.path.isfile(os.path.join(DOCS, "png", LARGE_DEFORMATION_PNG)):
            L += ["The final state, drawn by the run itself (`output/png snapshots = final`, talus-plot; "
                  "points coloured by the velocity magnitude):", "",
                  f"![colliding disks at the end time](png/{LARGE_DEFORMATION_PNG})", ""]
    else:
        ok_all = False
    cg = os.path.join(DOCS, "csv", "crossing_growth.csv")
    L += ["### Cell crossing: growth of the parasitic mode", "",
          "The translating bar (V/c = 0.2) at 256 cells per metre, 0.25 s: the amplitude growth rate of the "
          "parasitic mode (half the slope of log strain energy while it is above 1000 x its early level and "
          "below 1e-3 x the initial kinetic energy: linear regime) against the Floquet "
          "analysis of the translating state (docs/stability-analysis.md, `talus-critical-dt "
          "--crossing-velocity`). Criterion: within 10 %.", ""]
    if os.path.isfile(cg):
        L += ["| Courant number | predicted growth per step | predicted rate [1/s] | measured rate [1/s] | "
              "steps fitted | result |", "|---|---|---|---|---|---|"]
        for x in read_csv(cg):
            ok_all = ok_all and x["ok"] == 1
            L.append(f"| {x['courant']:g} | {x['growth_per_step_predicted']:.5f} | {x['rate_predicted']:.1f} | "
                     f"{x['rate_measured']:.1f} | {int(x['steps_fitted'])} | {'PASS' if x['ok'] == 1 else 'FAIL'} |")
        L.append("")
    else:
        ok_all = False
    sm = os.path.join(DOCS, "csv", "smoothing.csv")
    L += ["### Near-incompressible elasticity with and without strain smoothing", "",
          "tests/verification/check_smoothing.py (footing on a layer with nu = 0.49 and 0.499; criteria in its "
          "docstring and docs/explicit.md):", ""]
    if os.path.isfile(sm):
        L += ["| criterion | result |", "|---|---|"]
        for x in read_csv(sm):
            ok_all = ok_all and x["ok"] == 1
            L.append(f"| {x['criterion']} | {'PASS' if x['ok'] == 1 else 'FAIL'} |")
        L.append("")
    else:
        ok_all = False
    L += ["## Cases checked at one resolution (ctest)", "",
          "The other cases of tests/verification are checked by their ctest scripts at one resolution "
          "(`ctest -L fast` / `-L verify`), each against its analytic or published reference with the tolerance "
          "stated in the script: " + ", ".join(sorted(os.path.basename(p) for p in glob.glob(
              os.path.join(ROOT, "tests", "verification", "check_*.py")))) + ".", ""]
    L += [f"Overall: **{'all criteria hold' if ok_all else 'SOME CRITERIA FAIL'}**.", ""]
    write_atomic(os.path.join(DOCS, "README.md"), "\n".join(L))
    return ok_all


def main(argv):
    if len(argv) < 1 or argv[0].startswith("--"):
        print(__doc__)
        return 2
    build = os.path.abspath(argv[0])
    only = set()
    for a in argv[1:]:
        if a.startswith("--only="):
            only = set(a[7:].split(","))
    os.makedirs(os.path.join(DOCS, "csv"), exist_ok=True)
    os.makedirs(os.path.join(DOCS, "png"), exist_ok=True)
    work = os.path.join(build, "campaign")
    os.makedirs(work, exist_ok=True)
    if "--readme-only" not in argv:
        run_families(build, work, only)
        run_work_precision(build, work, only)
        run_sweeps(build, work, only)
        run_large_deformation(build, work, only)
        run_crossing_growth(build, work, only)
        run_smoothing(build, work, only)
    ok = readme()
    print(f"wrote {os.path.join(DOCS, 'README.md')}: {'all criteria hold' if ok else 'some criteria FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
