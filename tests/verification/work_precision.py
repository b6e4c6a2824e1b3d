"""The work-precision campaign across the formulation families (issue 42): its scenes,
their families and criteria, and the evaluation of the runs (crossover points, the
cheapest family per accuracy). One definition, used by scripts/verify_campaign.py (the
full campaign and the README), tests/verification/check_work_precision.py (the fast
subset in ctest) and tests/verification/check_readme.py (the README against the CSVs).

Every scene is one shared .prm fragment (parameter_files/work_precision/scenes/<scene>.inc:
grid, bodies, materials, loads) included by one base .prm per tool, which adds only that
tool's time integration, numerics and output; each family is a talus-convergence .prm
(parameter_files/work_precision/<family>.prm) that refines the cell size (and the time step
where the tool has a free one) over the same resolutions.
"""
import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PRM_DIR = os.path.join(ROOT, "parameter_files", "work_precision")


class Family:
    def __init__(self, name, tool, options, order=None, max_error=None, why="", shrinks=False):
        self.name = name  # parameter_files/work_precision/<name>.prm, <name>.csv
        self.tool = tool
        self.options = options  # the option set, as printed
        self.order = order  # (low, high) of the observed order, or None: no order expected
        self.max_error = max_error  # every run's error at most this, or None
        self.why = why  # the reason of the range, as printed
        self.shrinks = shrinks  # the error of the coarsest run above that of the finest run with an error

    def criterion(self):
        c = []
        if self.order:
            c.append(f"order in [{self.order[0]:g}, {self.order[1]:g}]")
        if self.max_error is not None:
            c.append(f"error <= {self.max_error:g} at every resolution")
        if self.shrinks:
            c.append("the error of the coarsest run above that of the finest run with an error")
        return " and ".join(c)

    def holds(self, order, errors):
        ok = True
        if self.order:
            ok = ok and math.isfinite(order) and self.order[0] <= order <= self.order[1]
        if self.max_error is not None:
            ok = ok and max(errors) <= self.max_error
        if self.shrinks:
            nz = [e for e in errors if e > 0]
            ok = ok and len(nz) >= 2 and nz[0] > nz[-1]
        return ok


class Scene:
    def __init__(self, name, kind, title, reference, families, fast_values, note=""):
        self.name, self.kind, self.title, self.reference = name, kind, title, reference
        self.families = families
        self.fast_values = fast_values  # the two resolutions of the ctest subset
        self.note = note


SCENES = [
    Scene("bar", "dynamic", "the elastic bar's first axial mode (scenes/bar.inc)",
          "displacement of every point at t = 3T/4 against the exact first mode (`bar displacement`), "
          "RMS relative to the amplitude v0/omega; h = 1/N, N = 8 to 256",
          [Family("bar_explicit", "talus-explicit", "central differences, Courant 0.5", (1.8, 2.6),
                  why="second order in h and dt (dt ~ h)"),
           Family("bar_implicit_dt1", "talus-implicit", "Newmark (trapezoidal), dt = h/c", (1.8, 3.6),
                  why="second order in h and dt; the error at the displacement's extreme (t = 3T/4) is "
                  "quadratic in the phase error, so while the period error of the trapezoidal rule "
                  "dominates the pairs decay faster than h^2 (up to h^4)"),
           Family("bar_implicit_dt4", "talus-implicit", "Newmark (trapezoidal), dt = 4 h/c", (1.8, 3.6),
                  why="as for dt = h/c")],
          [16, 32]),
    Scene("cantilever", "quasi-static", "the seed 001 cantilever under its self-weight (scenes/cantilever.inc)",
          "deflection of the point nearest the tip's mid-depth against Timoshenko's beam (`cantilever "
          "deflection`); h = 1/N, 8 N x N cells; talus-explicit and talus-fem N = 2, 4, 8 (the damped runs to rest "
          "take 35 s at N = 8), talus-implicit N = 2 to 32",
          [Family("cantilever_explicit", "talus-explicit", "MPM, local damping 0.7 to rest", (1.5, 2.3),
                  why="second order of the Q1 grid"),
           Family("cantilever_fem", "talus-fem", "UL-FEM, local damping 0.7 to rest", (1.5, 2.3),
                  why="second order of the Q1 elements"),
           Family("cantilever_implicit", "talus-implicit", "static, one load step", (1.5, 2.3),
                  why="second order of the Q1 grid; the finest pair falls below 2 where the error nears the "
                  "difference between Timoshenko's beam and plane-strain elasticity")],
          [2, 4]),
    Scene("footing", "quasi-static", "a rigid rough strip footing pushed 1 mm into an elastic layer "
          "(scenes/footing.inc)",
          "the footing's reaction at the settlement against V = -551.73 N, the Richardson extrapolation of "
          "talus-implicit's N = 32, 64, 128 runs (`value`, relative to |V|); h = 1/N, talus-explicit N = 8 to 64, "
          "talus-implicit N = 8 to 128",
          [Family("footing_explicit", "talus-explicit", "local damping 0.7, settlement ramped over 0.5 s",
                  (0.7, 1.3), why="first order: the stress singularity at the footing's edge"),
           Family("footing_explicit_ms10", "talus-explicit", "local damping 0.7, mass scaling 10", None, 0.06,
                  why="no order: the scaled inertia leaves the layer short of rest at the end, a bias of about 4 % "
                  "that the grid does not reduce"),
           Family("footing_implicit", "talus-implicit", "static, one load step", (0.7, 1.3),
                  why="first order: the stress singularity at the footing's edge")],
          [8, 16]),
    Scene("column_collapse", "dynamic, large deformation",
          "the seed 001 granular column collapse, a = 1.2 (scenes/column_collapse.inc)",
          "run-out (the front of the contiguous deposit at t = 0.8 s, points ahead of its first gap left out) "
          "against the family's finest run (`richardson`, `particles:pos_x:front`), in m; h = d_i/N, talus-explicit N = 12, 18, 24, 36, talus-implicit N = 12, "
          "18, 24 (the finest run of each family is its reference and has no error)",
          [Family("column_collapse_explicit", "talus-explicit", "Courant 0.5",
                  why="no order expected of the front of a plastic flow: self-convergence", shrinks=True),
           Family("column_collapse_implicit", "talus-implicit", "Newmark, dt = 0.018/N s",
                  why="as for talus-explicit", shrinks=True)],
          None,
          note="The rough base is a prescribed zero velocity (`loads/velocity 0` on the base), one condition "
          "with one meaning in both tools. With `boundary conditions/fixed = 2` instead the two tools solved "
          "different problems and their finest runs differed by 10.4 %: talus-explicit's fixed node has v = a = 0, "
          "but its reaction never reaches the FLIP points next to it, which keep sliding on the base (run-out, "
          "front of the contiguous deposit in bins of one cell: +2.3 % at N = 12, +16.7 % at N = 24 over the "
          "prescribed zero velocity); talus-implicit's fixed DoFs stop the points through Newmark's nodal "
          "acceleration, so either form gives it the same answer (identical at N = 12). With the same condition "
          "the two tools' runs at N = 12 and 24 differ by +3.8 % and -1.8 % (explicit over implicit): within the "
          "discretisation error, which changes sign between them."),
    Scene("terzaghi_k1e-3", "consolidation",
          "Terzaghi's consolidation at k = 1e-3 m/s (scenes/terzaghi.inc)",
          "pore pressure of every pressure-carrying point at T_v = 0.2 against the Terzaghi series "
          "(`terzaghi pore pressure`), RMS of p/q - series; h = 1/N, N = 10, 20, 40, 80",
          [Family("terzaghi_explicit", "talus-explicit", "2-phase single point, Courant 0.9", (0.8, 1.2), 0.03,
                  why="first order: the load and the free drainage act at the points of the top layer, h/4 "
                  "below the surface"),
           Family("terzaghi_semi_implicit_double", "talus-semi-implicit", "double point, dt = h/250 s", None, 3e-3,
                  why="no order: the error is at a floor of about 1e-3 from N = 10 on"),
           Family("terzaghi_semi_implicit_single", "talus-semi-implicit", "single point, dt = h/250 s", None, 3e-3,
                  why="no order: the error is at a floor of a few 1e-4 from N = 20 on"),
           Family("terzaghi_semi_implicit_double_dt80", "talus-semi-implicit", "double point, dt = h/80 s", None,
                  3e-3, why="as for dt = h/250 s (0.92 x the skeleton's critical step h / 73.4 s)")],
          [10, 20]),
    Scene("terzaghi_k1e-7", "consolidation",
          "Terzaghi's consolidation at k = 1e-7 m/s (scenes/terzaghi.inc; T_v = 0.2 at t = 1962 s)",
          "as at k = 1e-3; h = 1/N, N = 5, 10, 20 (0.78, 1.57, 3.14 million steps); talus-semi-implicit, double "
          "and single point; talus-explicit's 2-phase family (days to weeks of loop time per run) and the other option sets are "
          "estimated in the next section",
          [Family("terzaghi_k1e-7_semi_implicit_double_dt80", "talus-semi-implicit",
                  "double point, dt = h/80 s, smoothing of Eq. 77 every step", None, 0.1,
                  why="a documented defect, no order: the map-remap of the pore pressure at every one of "
                  "the million steps flattens the profile into a straight line, about 8 % at every N "
                  "(docs/semi-implicit.md, 'The smoothing at low k')"),
           Family("terzaghi_k1e-7_semi_implicit_double_dt80_beta", "talus-semi-implicit",
                  "double point, dt = h/80 s, pressure smoothing fraction 1e-5", None, 0.02,
                  why="as the k = 1e-3 column at the same N (1.42 % at N = 5): the blend keeps the "
                  "smoothing's relaxation of the modes the grid does not see without its cumulative "
                  "flattening"),
           Family("terzaghi_k1e-7_semi_implicit_single_dt80_beta", "talus-semi-implicit",
                  "single point, dt = h/80 s, pressure smoothing fraction 1e-5", None, 0.02,
                  why="as the double-point family with the same blend (1.41 % at N = 5, 2026-12-07): the water "
                  "riding on the soil points changes the pressure's positions, not the smoothing's "
                  "cumulative effect")],
          None,
          note="Run to T_v = 0.2, not estimated: at this k the step of talus-semi-implicit is still bound to the "
          "skeleton's wave (h / 80 s), so the run takes 1e4 times the steps of the k = 1e-3 column, and the "
          "paper's smoothing, harmless over 157 steps, is applied a million times. The flattening grows with the "
          "number of steps: at N = 5 and T_v = 0.2 the error was (2026-12-07) 1.42 / 5.71 / 8.31 / 8.72 / 8.76 % at "
          "k = 1e-3 ... 1e-7 (one decade each). `verification.semi_implicit_terzaghi_low_k` checks the "
          "blended smoothing at k = 1e-6 in ctest. The single-point family was run beside the campaign and two test "
          "suites (2026-12-07): its loop times are 2-3 x those of a free core, and its N = 20 run was paused for "
          "10 min to let a test suite through (about 18 min of CPU time for its 2689 s of loop)."),
]

# Terzaghi at k = 1e-7 m/s: the same scene and families, too slow to run to T_v = 0.2
# (t = 0.2 H^2 / c_v = 1962 s); each family's cost probe (parameter_files/work_precision/
# terzaghi_k1e-7_probe_<family>.prm, N = 10 and 20) runs to a short time, and the loop time
# to T_v = 0.2 is estimated as (steps needed) x (loop time per step of the probe).
LOW_K_T_END = 0.2 * 1.0 ** 2 / (1e-7 * 1e7 / (1000 * 9.81))
LOW_K = [("terzaghi_k1e-7_probe_explicit", "terzaghi_explicit", 1e-4),
         ("terzaghi_k1e-7_probe_semi_implicit_double", "terzaghi_semi_implicit_double", 0.1962),
         ("terzaghi_k1e-7_probe_semi_implicit_single", "terzaghi_semi_implicit_single", 0.1962),
         ("terzaghi_k1e-7_probe_semi_implicit_double_dt80", "terzaghi_semi_implicit_double_dt80", 0.1962)]
LOW_K_HEAD = ("| probe | N | dt [s] | probe steps | loop per step [ms] | steps to T_v = 0.2 | "
              "estimated loop to T_v = 0.2 [s] | [h] |")


def low_k_rows(name, rows, t_probe):
    """(N, dt, probe steps, loop per step [s], steps needed, estimated loop [s]) per probe run."""
    out = []
    for r in rows:
        dt = t_probe / r["n_steps"]
        per = r["solver_wall_s"] / r["n_steps"]
        need = math.ceil(LOW_K_T_END / dt - 1e-9)
        out.append((r["value"], dt, int(r["n_steps"]), per, need, need * per))
    return out


def low_k_row(name, x):
    return (f"| {name} | {x[0]:g} | {x[1]:.4e} | {x[2]} | {x[3] * 1e3:.4f} | {x[4]:.4e} | {x[5]:.4e} | "
            f"{x[5] / 3600:.3g} |")


TARGETS = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5]


def fit_order(xs, es):
    """Least-squares slope of log e over log x (as talus-convergence)."""
    pts = [(math.log(x), math.log(e)) for x, e in zip(xs, es) if e > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def pareto(rows):
    """The runs of a family no other run beats in both error and wall time of the time loop,
    as (error, wall) sorted by decreasing error (increasing wall)."""
    pts = sorted(((r["error"], r["solver_wall_s"]) for r in rows if r["error"] > 0 and r["solver_wall_s"] > 0),
                 key=lambda p: (p[1], p[0]))
    front = []
    for e, w in pts:
        if not front or e < front[-1][0]:
            front.append((e, w))
    return front


def cost(front, e):
    """Wall time the family needs for the error e: log-log interpolation between the runs of
    its Pareto front; None outside the errors it reached (no extrapolation)."""
    if not front or e < front[-1][0] or e > front[0][0]:
        return None
    for (e0, w0), (e1, w1) in zip(front, front[1:]):
        if e1 <= e <= e0:
            if e0 == e1:
                return w0
            s = (math.log(e) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))
    return front[0][1]


def crossovers(front_a, front_b):
    """Errors at which the two families cost the same, in the error range both reached:
    (common range (lo, hi), [(error, wall)], which is cheaper at the top of the range
    (+1: a, -1: b, 0: none))."""
    if not front_a or not front_b:
        return None, [], 0
    lo = max(front_a[-1][0], front_b[-1][0])
    hi = min(front_a[0][0], front_b[0][0])
    if lo >= hi:
        return None, [], 0
    n = 400
    grid = [hi] + [math.exp(math.log(hi) + (math.log(lo) - math.log(hi)) * i / n) for i in range(1, n)] + [lo]

    def d(e):
        return math.log(cost(front_a, e)) - math.log(cost(front_b, e))
    out, first = [], 0
    prev_e, prev_d = None, None
    for e in grid:
        v = d(e)
        if prev_d is None:
            first = -1 if v > 0 else 1 if v < 0 else 0
        elif (prev_d < 0 < v) or (prev_d > 0 > v):
            a, b = prev_e, e  # bisection in log e
            for _ in range(60):
                m = math.sqrt(a * b)
                if (d(m) > 0) == (prev_d > 0):
                    a = m
                else:
                    b = m
            m = math.sqrt(a * b)
            out.append((m, cost(front_a, m)))
        prev_e, prev_d = e, v
    return (lo, hi), out, first


def label(f):
    return f"{f.name} ({f.tool}, {f.options})"


def analysis(scene, rows_of):
    """The text lines of a scene's crossovers and of the cheapest family per target error,
    from the CSV rows (rows_of(family name) -> list of dicts with error, solver_wall_s)."""
    fronts = {f.name: pareto(rows_of(f.name)) for f in scene.families}
    lines = []
    fams = scene.families
    for i in range(len(fams)):
        for j in range(i + 1, len(fams)):
            a, b = fams[i], fams[j]
            rng, xs, first = crossovers(fronts[a.name], fronts[b.name])
            if rng is None:
                fa, fb = fronts[a.name], fronts[b.name]
                if not fa or not fb:
                    lines.append(f"* {a.name} vs {b.name}: a family has no run with an error and a wall time.")
                    continue
                if fa[-1][0] < fb[-1][0]:  # name the more accurate family hi, the other lo
                    hi_n, hi_f, lo_n, lo_f = a.name, fa, b.name, fb
                else:
                    hi_n, hi_f, lo_n, lo_f = b.name, fb, a.name, fa
                if hi_f[0][1] <= lo_f[-1][1]:
                    lines.append(f"* {a.name} vs {b.name}: no common error range; {hi_n} dominates: its cheapest "
                                 f"run (error {hi_f[0][0]:.2e}, loop {hi_f[0][1]:.3g} s) is more accurate and "
                                 f"cheaper than the most accurate run of {lo_n} (error {lo_f[-1][0]:.2e}, loop "
                                 f"{lo_f[-1][1]:.3g} s).")
                else:
                    lines.append(f"* {a.name} vs {b.name}: no common error range: {lo_n} covers "
                                 f"[{lo_f[-1][0]:.2e}, {lo_f[0][0]:.2e}] for a loop of {lo_f[0][1]:.3g} to "
                                 f"{lo_f[-1][1]:.3g} s, {hi_n} [{hi_f[-1][0]:.2e}, {hi_f[0][0]:.2e}] for "
                                 f"{hi_f[0][1]:.3g} to {hi_f[-1][1]:.3g} s.")
                continue
            top = a.name if first > 0 else b.name if first < 0 else "neither"
            if not xs:
                lines.append(f"* {a.name} vs {b.name}: no crossover in the common error range "
                             f"[{rng[0]:.2e}, {rng[1]:.2e}]: {top} is cheaper throughout.")
            else:
                pts = ", ".join(f"error {e:.2e} (loop {w:.3g} s)" for e, w in xs)
                lines.append(f"* {a.name} vs {b.name}: crossover at {pts} in the common error range "
                             f"[{rng[0]:.2e}, {rng[1]:.2e}]; {top} is cheaper above the first crossover.")
    for t in TARGETS:
        # the cheapest run of each family with an error at most t (measured, not interpolated)
        c = [(min((w for e, w in fronts[f.name] if e <= t), default=None), f.name) for f in fams]
        c = sorted(x for x in c if x[0] is not None)
        if not c:
            best = min(((fronts[f.name][-1][0], f.name) for f in fams if fronts[f.name]), default=None)
            lines.append(f"* error <= {t:.0e}: reached by no family" +
                         (f" (the smallest error: {best[0]:.2e}, {best[1]})." if best else "."))
        else:
            rest = "; ".join(f"{n} {w:.3g} s" for w, n in c[1:])
            lines.append(f"* error <= {t:.0e}: cheapest {c[0][1]} (loop {c[0][0]:.3g} s)" +
                         (f"; then {rest}." if rest else "; no other family reaches it."))
    return lines


def cheapest(scene, rows_of, t):
    """The family whose cheapest run with an error at most t has the smallest loop wall time
    (name, wall), or None."""
    c = []
    for f in scene.families:
        w = min((r["solver_wall_s"] for r in rows_of(f.name) if 0 < r["error"] <= t), default=None)
        if w is not None:
            c.append((w, f.name))
    return (min(c)[1], min(c)[0]) if c else None


# ------------------------------------------------------------------ the README section
TABLE_COLS = ["value", "abscissa", "error", "pair_order", "solver_wall_s", "run_time_s", "n_particles", "n_steps",
              "newton_iterations", "linear_iterations"]
TABLE_HEAD = ("| family | N | h [m] | error | pairwise order | loop [s] | run time [s] | points | steps | "
              "Newton iterations | linear iterations |")


def _f2(x):
    return "-" if isinstance(x, str) or not math.isfinite(x) else f"{x:.2f}"


def table_row(family, r):
    return (f"| {family} | {r['value']:g} | {r['abscissa']:.4g} | {r['error']:.3e} | {_f2(r['pair_order'])} | "
            f"{r['solver_wall_s']:.4f} | {r['run_time_s']:.2f} | {int(r['n_particles'])} | {int(r['n_steps'])} | "
            f"{int(r['newton_iterations'])} | {int(r['linear_iterations'])} |")


def figure_name(scene):
    return f"work_precision_{scene.name}.png"


def recommendations(rows_of, summary_of):
    """One line per scene: the cheapest family for each target error it reached."""
    out = []
    for sc in SCENES:
        if any(summary_of(f.name) is None for f in sc.families):
            continue
        parts = []
        for t in TARGETS:
            c = cheapest(sc, rows_of, t)
            if c is None:
                continue
            others = []
            for f in sc.families:
                w = min((r["solver_wall_s"] for r in rows_of(f.name) if 0 < r["error"] <= t), default=None)
                if f.name != c[0] and w is not None:
                    others.append(w / c[1])
            ratio = f", {min(others):.3g} x faster than the next" if others else ", the only family reaching it"
            parts.append(f"error <= {t:.0e}: {c[0]} ({c[1]:.3g} s{ratio})")
        out.append(f"* {sc.kind}, {sc.name}: " + ("; ".join(parts) if parts else "no target error reached") + ".")
    est = []
    for name, _, t in LOW_K:
        rows = rows_of(name)
        if rows:
            x = min(low_k_rows(name, rows, t), key=lambda x: x[0])  # the coarsest grid, N = 10
            est.append((x[5], name))
    if len(est) == len(LOW_K):
        est.sort()
        out.append(f"* consolidation, terzaghi_k1e-7 (estimated loop to T_v = 0.2 at N = 10): {est[0][1]} "
                   f"({est[0][0]:.3g} s), " + ", ".join(f"{n} {w:.3g} s ({w / est[0][0]:.3g} x)" for w, n in est[1:])
                   + ".")
    return out


def finest_quantities(sc, rows_of):
    """For a scene whose families are judged against their own finest run: the quantity of each
    family's finest run, and how far apart the families' answers are."""
    q = []
    for f in sc.families:
        rows = rows_of(f.name)
        if rows and all("quantity" in r for r in rows) and any(r["error"] == 0 for r in rows):
            r = min(rows, key=lambda r: r["abscissa"])
            q.append((f.name, r["value"], r["quantity"]))
    if len(q) < 2:
        return []
    lo, hi = min(x[2] for x in q), max(x[2] for x in q)
    return [f"* the families' own references (their finest runs): " + "; ".join(
        f"{n} (N = {v:g}) {x:.4g}" for n, v, x in q) + f"; they differ by {100 * (hi - lo) / abs(lo):.1f} % "
        "(each family converges to its own answer: the errors above do not measure that difference)."]


def section(rows_of, summary_of):
    """The README's work-precision section (lines) and whether every criterion holds.
    rows_of(name) -> CSV rows of a family (dicts of floats) or None; summary_of(name) -> its
    summary row or None."""
    L = ["## Work-precision across the families (issue 42)", "",
         "Shared scenes, each solved by every family that can solve it: one `.prm` fragment per scene "
         "(`parameter_files/work_precision/scenes/<scene>.inc`: grid, bodies, materials, loads) included by one "
         "base `.prm` per tool that adds only its time integration, numerics and output; one talus-convergence "
         "family per tool and option set (`parameter_files/work_precision/<family>.prm`) refines the cell size, "
         "and the time step with it where the tool has a free one. Work: the wall time of the solver's time loop "
         "(`loop`, from its log; the figures use it) on this machine (2 cores shared with other jobs: "
         "indicative), the whole process (`run time`, about 0.5-1 s of start-up more), the steps, and for the "
         "families with solves the Newton iterations (talus-implicit) and the linear iterations (talus-implicit: "
         "one per direct solve; talus-semi-implicit: the pressure CG iterations). Crossover: the error at which "
         "two families' log-log interpolated work-precision curves (each family's runs that no other of its runs "
         "beats in both error and time) cost the same, within the error range both reached; the cheapest family "
         "for an error: the cheapest run of each family with an error at most that (measured, not "
         "interpolated). The criteria are checked on two resolutions per family in ctest "
         "(`verification.work_precision_fast`).", ""]
    ok_all = True
    for sc in SCENES:
        L += [f"### work-precision: {sc.name} ({sc.kind})", "", f"Scene: {sc.title}. Error: {sc.reference}.", ""]
        L += [sc.note, ""] if sc.note else []
        missing = [f.name for f in sc.families if summary_of(f.name) is None]
        if missing:
            L += ["not run: " + ", ".join(missing), ""]
            ok_all = False
            continue
        L += [f"![work-precision {sc.name}](png/{figure_name(sc)})", ""]
        for f in sc.families:
            s, r = summary_of(f.name), rows_of(f.name)
            ok = f.holds(s["observed_order"], [x["error"] for x in r])
            ok_all = ok_all and ok
            L.append(f"* `{f.name}` ({f.tool}, {f.options}): observed order **{_f2(s['observed_order'])}**. "
                     f"Criterion: {f.criterion()} ({f.why}): **{'PASS' if ok else 'FAIL'}**.")
        L += ["", TABLE_HEAD, "|---|---|---|---|---|---|---|---|---|---|---|"]
        for f in sc.families:
            for r in rows_of(f.name):
                L.append(table_row(f.name, r))
        L += ["", "Measured on this machine:", ""] + analysis(sc, rows_of) + finest_quantities(sc, rows_of) + [""]
    L += ["### work-precision: terzaghi_k1e-7, the cost of the other families (estimate)", "",
          f"The Terzaghi scene at k = 1e-7 m/s (c_v = 1.019e-4 m^2/s): T_v = 0.2 needs t = {LOW_K_T_END:.5g} s. "
          "talus-semi-implicit at dt = h/80 s is run to that time (above). The other families are not: each "
          "family's probe (the same scene and family at k = 1e-7, N = 10 and 20) runs a short time, and the loop "
          "time to T_v = 0.2 is estimated as the steps needed times the probe's loop time per step. "
          "talus-explicit's coupled "
          "2-phase step is limited by the drag "
          "(independent of h at this k); talus-semi-implicit's by the skeleton (dt ~ h, its option sets as at "
          "k = 1e-3).", ""]
    probes = [(n, fam, t, rows_of(n)) for n, fam, t in LOW_K]
    if any(r is None for *_, r in probes):
        L += ["not run: " + ", ".join(n for n, _, _, r in probes if r is None), ""]
        ok_all = False
    else:
        L += [LOW_K_HEAD, "|---|---|---|---|---|---|---|---|"]
        for n, fam, t, rows in probes:
            for x in low_k_rows(n, rows, t):
                L.append(low_k_row(n, x))
        best = min(((x[5], n, x[0]) for n, fam, t, rows in probes for x in low_k_rows(n, rows, t)))
        worst = max(((x[5], n, x[0]) for n, fam, t, rows in probes for x in low_k_rows(n, rows, t)))
        run = rows_of("terzaghi_k1e-7_semi_implicit_double_dt80") or []
        for n, fam, t, rows in probes:  # the estimate against the run, where both exist
            for x in low_k_rows(n, rows, t):
                r = [r for r in run if n.endswith("double_dt80") and r["value"] == x[0]]
                if r:
                    L += ["", f"The estimate against the run: {n} at N = {x[0]:g} estimated {x[5]:.4g} s, the run "
                          f"to T_v = 0.2 took {r[0]['solver_wall_s']:.4g} s."]
        L += ["", f"Cheapest estimate: {best[1]} at N = {best[2]:g}, {best[0]:.3g} s ({best[0] / 3600:.3g} h); "
              f"dearest: {worst[1]} at N = {worst[2]:g}, {worst[0]:.3g} s ({worst[0] / 86400:.3g} days). "
              "Both families' steps are bound to a time scale that does not grow with 1/k (the skeleton's wave "
              "in talus-semi-implicit, the drag in talus-explicit) while the consolidation time does: the "
              "steps to T_v = 0.2 are 1e4 times those at k = 1e-3 (talus-semi-implicit) and more "
              "(talus-explicit, whose step also shrinks with k).", ""]
    L += ["### Which family for which problem (from the numbers above)", "",
          "The cheapest family for each target error that some family reached, with the factor by which it is "
          "faster than the next family reaching it (time loop, this machine):", ""]
    L += recommendations(rows_of, summary_of) + [""]
    return L, ok_all
