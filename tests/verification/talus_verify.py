"""Helpers for talus verification cases: edit .prm entries, run tools, read CSVs.

Only the Python standard library is used so that the checks run anywhere.
"""
import contextlib
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile


def _prm_entries(lines):
    """(line index, subsection stack, entry, value) of every `set` line of a .prm."""
    stack = []
    for i, line in enumerate(lines):
        s = line.split("#", 1)[0].strip()
        m = re.match(r"subsection\s+(.*)$", s)
        if m:
            stack.append(m.group(1).strip())
            continue
        if s == "end":
            stack.pop()
            continue
        m = re.match(r"set\s+(.*?)\s*=\s*(.*)$", s)
        if m:
            yield i, stack, m.group(1), m.group(2).strip()


def det3(m):
    """Determinant of a 3 x 3 matrix (nested lists)."""
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def prm_set(text, path, value):
    """Set entry `path` ("sub/sub/entry" or "entry") in a .prm text.

    Replaces the entry where it is; otherwise adds it to the (innermost existing)
    subsection, creating the missing subsections at the end of the text.
    """
    parts = path.split("/")
    subs, key = parts[:-1], parts[-1]
    lines = text.splitlines()
    for i, stack, k, _ in _prm_entries(lines):
        if k == key and stack == subs:
            line = lines[i]
            indent = line[: len(line) - len(line.lstrip())]
            lines[i] = f"{indent}set {key} = {value}"
            return "\n".join(lines) + "\n"
    # not found: append a block (deal.II accepts a subsection opened twice)
    block = [f"subsection {x}" for x in subs] + [f"set {key} = {value}"] + ["end"] * len(subs)
    return "\n".join(lines + block) + "\n"


def prm_get(text, path):
    """The value of entry `path` ("sub/sub/entry") in a .prm text (the last one set);
    an error naming the entry if the text does not set it."""
    parts = path.split("/")
    found = [v for _, stack, k, v in _prm_entries(text.splitlines()) if k == parts[-1] and stack == parts[:-1]]
    if not found:
        raise KeyError(f"the .prm does not set '{path}'")
    return found[-1]


# Variables an mpirun (or PMIx launcher) sets for the processes it starts; a
# child started from such a process must not inherit them, or it takes itself
# for a rank of the parent's job (docs/reliability.md).
_LAUNCH_PREFIXES = ("PMIX_", "PMI_", "OMPI_COMM_WORLD_", "OMPI_MCA_orte_", "OMPI_MCA_ess", "OMPI_MCA_pmix")
_LAUNCH_NAMES = {"OMPI_UNIVERSE_SIZE", "OMPI_FIRST_RANKS", "OMPI_NUM_APP_CTX", "OMPI_APP_CTX_NUM_PROCS",
                 "OMPI_FILE_LOCATION", "OMPI_COMMAND", "OMPI_ARGV", "OMPI_MCA_initial_wdir",
                 "OMPI_MCA_shmem_RUNTIME_QUERY_hint", "OMPI_MCA_mpi_oversubscribe"}
# Text of an Open MPI start-up failure (MPI_Init aborted before the tool ran).
MPI_STARTUP_MARKERS = ("Local abort before MPI_INIT completed", "orte_init failed", "ompi_rte_init failed",
                       "orte_ess_init failed", "An error occurred in MPI_Init", "MPI_INIT failed", "PMIx_Init failed")


def prm_set_args(text, settings):
    """prm_set for each "entry=value" string of `settings` (a script's trailing arguments)."""
    for kv in settings:
        k, v = kv.split("=", 1)
        text = prm_set(text, k, v)
    return text


def child_env(extra=None):
    """os.environ without the variables of a parent mpirun, plus the settings every tool run needs."""
    env = {k: v for k, v in os.environ.items() if not (k.startswith(_LAUNCH_PREFIXES) or k in _LAUNCH_NAMES)}
    env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMP_NUM_THREADS": "1"})
    if extra:
        env.update(extra)
    return env


@contextlib.contextmanager
def mpirun_session(env):
    """A private Open MPI session base for one mpirun (set in env, removed afterwards): concurrent jobs
    otherwise share <TMPDIR>/ompi.<host>.<uid> and race on its creation and removal. Singleton tool
    starts do this themselves (lib/talus/base/mpi_session.h)."""
    d = tempfile.mkdtemp(prefix="talus-mpirun-", dir=os.environ.get("TMPDIR") or "/tmp")
    env["OMPI_MCA_orte_tmpdir_base"] = d
    try:
        yield env
    finally:
        shutil.rmtree(d, ignore_errors=True)


def startup_failure(returncode, text):
    """True if a tool exited because Open MPI could not start (not the tool's answer to its input)."""
    return returncode not in (0, 2) and any(m in text for m in MPI_STARTUP_MARKERS)


def run_tool(tool, prm_text, workdir, name, np=1, expect_rc=0, extra_env=None, timeout=3000, log=None):
    """Write <workdir>/<name>.prm, run the tool (under mpirun if np > 1).

    Returns (returncode, stdout, stderr). Fails the test if the return code is
    not expect_rc (None: accept anything), and always if the tool could not
    start (MPI start-up failure), with a message saying so. With `log` (a file
    path) stdout and stderr are appended to that file as the tool writes them
    (a run that is stopped keeps its lines) and returned as stdout of this run.
    """
    os.makedirs(workdir, exist_ok=True)
    prm = os.path.join(workdir, name + ".prm")
    with open(prm, "w") as f:
        f.write(prm_text)
    cmd = [os.path.abspath(tool), os.path.abspath(prm)]
    if np > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(np)] + cmd
    env = child_env(extra_env)
    with (mpirun_session(env) if np > 1 else contextlib.nullcontext()):
        if log is None:
            p = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, env=env, timeout=timeout)
        else:
            with open(log, "a") as f:
                start = f.tell()
                rc = subprocess.run(cmd, cwd=workdir, stdout=f, stderr=subprocess.STDOUT, env=env,
                                    timeout=timeout).returncode
            with open(log) as f:
                f.seek(start)
                p = subprocess.CompletedProcess(cmd, rc, f.read(), "")
    if startup_failure(p.returncode, p.stdout + p.stderr):
        sys.stderr.write(p.stderr[-3000:])
        fail(f"{name}: {os.path.basename(tool)} could not start (MPI start-up failure, exit {p.returncode}); "
             "this is not the tool's answer to its input")
    if expect_rc is not None and p.returncode != expect_rc:
        sys.stdout.write(p.stdout)
        sys.stderr.write(p.stderr)
        fail(f"{name}: exit code {p.returncode}, expected {expect_rc}")
    return p.returncode, p.stdout, p.stderr


def check_refused(tool, text, label, expected, workdir):
    """Bad input refused alike with --check and with a run: `text` (a .prm) with its
    output/directory set to <workdir>_check|_run/out is run by `tool` (a path) both ways;
    each must exit 2, print every string of `expected` and write no output directory."""
    for with_check in (True, False):
        d = workdir + ("_check" if with_check else "_run")
        out = os.path.join(d, "out")
        os.makedirs(d, exist_ok=True)
        prm = os.path.join(d, "bad.prm")
        with open(prm, "w") as f:
            f.write(prm_set(text, "output/directory", out))
        p = subprocess.run([tool] + (["--check"] if with_check else []) + [prm], capture_output=True, text=True,
                           env=child_env(), cwd=d, timeout=300)
        both = p.stdout + p.stderr
        missing = [e for e in expected if e not in both]
        last = (both.strip().splitlines() or [""])[-1]
        refused = p.returncode == 2 and not missing and not os.path.exists(out)
        check(refused, f"{os.path.basename(tool)}{' --check' if with_check else ''}: {label}: exit {p.returncode}, "
                        f"{'named ' + str(expected) if not missing else 'MISSING ' + str(missing)}, "
                        f"{'no output' if not os.path.exists(out) else 'OUTPUT WRITTEN'} ({last[:150]})")


def check_restart_across_rebalances(tool, text, workdir, name, interval, min_step, min_rebalances, np=2):
    """A checkpoint taken between rebalances continues bitwise: `text` (a .prm that rebalances and
    writes particles_final.csv) runs uninterrupted on `np` ranks writing checkpoints every `interval`
    [s], then again from its last checkpoint; the restart must come from a step > `min_step`, rebalance
    at least `min_rebalances` times more, and end with the same particles_final.csv byte for byte."""
    import filecmp
    restart = prm_set(text, "output/directory", f"out_{name}_restart")
    restart = prm_set(restart, "checkpoint/interval", str(interval))
    run_tool(tool, restart, workdir, f"{name}_restart_full", np=np)
    out = os.path.join(workdir, f"out_{name}_restart", "particles_final.csv")
    uninterrupted = os.path.join(workdir, f"{name}_uninterrupted.csv")
    shutil.copy(out, uninterrupted)
    _, log, _ = run_tool(tool, prm_set(restart, "checkpoint/restart", "true"), workdir, f"{name}_restart_cont", np=np)
    m = re.search(r"restarting from \S+ \(step (\d+)", log)
    check(m is not None and int(m.group(1)) > min_step,
          f"{name}: restarted from the checkpoint at step {m.group(1) if m else '?'} (> {min_step})")
    n_after = int(re.search(r"rebalances (\d+)", log).group(1))
    check(n_after >= min_rebalances, f"{name}: the continuation rebalances again ({n_after} >= {min_rebalances} times)")
    check(filecmp.cmp(uninterrupted, out, shallow=False),
          f"{name}: the continuation is bitwise identical to the uninterrupted run (particles_final.csv)")


def read_csv(path):
    """Columns of a CSV file as a dict name -> list of floats."""
    with open(path) as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]

    def value(x):
        try:
            return float(x)
        except ValueError:
            return x  # text columns (names) stay strings

    return {h: [value(r[i]) for r in data] for i, h in enumerate(header)}


def by_initial_position(t):
    """A table (read_csv) of material points reordered by their initial position X = x - u
    (y first, then x, rounded to 1e-9): the storage order differs between runs (ranks, restarts)."""
    key = sorted(range(len(t["pos_x"])), key=lambda i: (round(t["pos_y"][i] - t["displacement_y"][i], 9),
                                                       round(t["pos_x"][i] - t["displacement_x"][i], 9)))
    return {c: [v[i] for i in key] for c, v in t.items()}


def cantilever_tip(p, h, l=8.0):
    """Tip deflection of the seed 001 cantilever from its particles_final.csv table p (docs/implicit.md):
    the points do not sit on the free end, so u_y is extrapolated linearly to X = l from the mean u_y of
    the two outermost point columns (X = l - h/4, l - 3h/4): 1.5 u1 - 0.5 u2. Returns (delta, the
    number of points in each of the two columns)."""
    cols = ([], [])
    for x, ux, uy in zip(p["pos_x"], p["u_x"], p["u_y"]):
        for j, c in enumerate((l - h / 4, l - 3 * h / 4)):
            if abs(x - ux - c) < 1e-9:
                cols[j].append(uy)
    if not cols[0] or not cols[1]:
        return float("nan"), (len(cols[0]), len(cols[1]))
    u1, u2 = (sum(c) / len(c) for c in cols)
    return 1.5 * u1 - 0.5 * u2, (len(cols[0]), len(cols[1]))


def box_body(k, name, lower, upper, initial_velocity=None, ppd=2, material=0):
    """The .prm text of `body k`: a box of material `material` from `lower` to `upper` (strings
    "x, y" or sequences), seeded with ppd points per direction; appended to a scene that has set
    `number of bodies` (deal.II reads a subsection given after the others)."""
    def pair(v):
        return v if isinstance(v, str) else ", ".join(str(x) for x in v)
    text = (f"subsection body {k}\n  set name                    = {name}\n  set material                = {material}\n"
            f"  set shape                   = box\n  set lower corner            = {pair(lower)}\n"
            f"  set upper corner            = {pair(upper)}\n  set particles per direction = {ppd}\n")
    if initial_velocity is not None:
        text += f"  set initial velocity        = {pair(initial_velocity)}\n"
    return text + "end\n"


def elastic_block_scene(upper, cells, block_lower, block_upper, end_time, output, walls=True,
                        gravity="0, -9.81", initial_velocity=None, courant=0.5):
    """A small 2D talus-explicit scene: an elastic block (E 1e5 Pa, nu 0.3, rho 1000, 2 x 2 points per
    cell) in a box grid from the origin to `upper` with `cells`; with `walls` a fixed base and roller
    sides; `output` a dict of output/ entries. The scene of check_plot.py, check_vtu.py and the
    composability matrix."""
    def pair(v):
        return ", ".join(str(x) for x in v)
    text = f"""set dimension = 2
subsection time
  set end time       = {end_time}
  set courant number = {courant}
end
subsection grid
  set lower corner = 0, 0
  set upper corner = {pair(upper)}
  set cells        = {pair(cells)}
end
"""
    if walls:
        text += "subsection boundary conditions\n  set fixed  = 2\n  set roller = 0, 1\nend\n"
    text += f"subsection gravity\n  set acceleration = {gravity}\nend\nsubsection output\n"
    text += "".join(f"  set {k} = {v}\n" for k, v in output.items())
    text += f"""end
set number of materials = 1
subsection material 0
  set model   = linear elastic
  set density = 1000
  subsection linear elastic
    set young modulus = 1e5
    set poisson ratio = 0.3
  end
end
set number of bodies = 1
subsection body 0
  set name                    = block
  set material                = 0
  set shape                   = box
  set lower corner            = {pair(block_lower)}
  set upper corner            = {pair(block_upper)}
  set particles per direction = 2
"""
    if initial_velocity:
        text += f"  set initial velocity        = {pair(initial_velocity)}\n"
    return text + "end\n"


def lame_cylinder(a, b, p, E, nu):
    """Lamé's thick-walled cylinder (inner radius a, outer b, internal pressure p, plane strain or
    the axisymmetric long cylinder): functions r -> radial displacement, hoop stress, radial stress."""
    A = a * a * p / (b * b - a * a)
    return (lambda r: (1 + nu) / E * A * ((1 - 2 * nu) * r + b * b / r),
            lambda r: A * (1 + b * b / (r * r)),
            lambda r: A * (1 - b * b / (r * r)))


def deposit_front(xs, hx, origin):
    """Front of a granular deposit from its points' x: the points are binned by x in bins of width
    hx (edges at origin + k hx); the deposit is the run of occupied bins that starts at the wall
    (the smallest x). Returns (largest x inside that run, number of points beyond it)."""
    occupied = {}
    for x in xs:
        k = int((x - origin) // hx)
        occupied[k] = occupied.get(k, 0) + 1
    k = int((min(xs) - origin) // hx)
    while k in occupied:
        k += 1
    edge = origin + k * hx
    return max(x for x in xs if x < edge), sum(1 for x in xs if x >= edge)


# seed 001 Table 5.1, Cook's membrane, u_y(A) per elements per side n (structured triangles, one
# point per element): (U, UP no stab, UP stab) for nu = 0.33 and 0.499999 (as printed)
COOKS_TABLE_5_1 = {
    "0.33": {2: (0.089, 0.1013, 0.1172), 4: (0.1415, 0.1718, 0.1953), 8: (0.2183, 0.2511, 0.2669),
             16: (0.2771, 0.2952, 0.3025), 32: (0.30386, 0.3119, 0.315), 64: (0.3133, 0.3176, 0.319)},
    "0.499999": {2: (0.0723, 0.0788, 0.1277), 4: (0.0736, 0.1157, 0.1932), 8: (0.0742, 0.1821, 0.2424),
                 16: (0.075, 0.2356, 0.2648), 32: (0.0775, 0.2606, 0.2725), 64: (0.0862, 0.2702, 0.275)},
}


def cooks_membrane_prm(base, n, nu):
    """The Cook's membrane .prm `base` (docs/implicit.md) on n cells along the 48 mm side: the grid
    rows that cover the 62 mm height, the shear traction on the right edge's column of points
    and the Poisson ratio nu (a string)."""
    h = 48.0 / n
    rows = math.ceil(62.0 / h - 1e-9)
    text = prm_set(base, "grid/cells", f"{n}, {rows}")
    text = prm_set(text, "grid/upper corner", f"48, {rows * h}")
    text = prm_set(text, "loads/traction 0/region lower corner", f"{48 - h / 2}, 40")
    text = prm_set(text, "loads/traction 0/region upper corner", f"48, {rows * h}")
    return prm_set(text, "material 0/neo hookean/poisson ratio", nu)


def cooks_corner_uy(t, corner=(48.0, 60.0)):
    """Vertical displacement of Cook's membrane's corner A from a particles_final.csv table t
    (docs/implicit.md, "Cook's membrane"): no point sits on A; the value at A of the least-squares
    plane u_y = a + b (X - 48) + c (Y - 60) through the 6 points nearest to A by initial position
    X = x - u. Returns (u_y(A), number of points)."""
    pts = [(t["pos_x"][i] - t["u_x"][i], t["pos_y"][i] - t["u_y"][i], t["u_y"][i]) for i in range(len(t["id"]))]
    pts.sort(key=lambda q: (q[0] - corner[0]) ** 2 + (q[1] - corner[1]) ** 2)
    near = pts[:6]
    # normal equations of the plane fit (3 x 3), solved by Cramer's rule
    rows = [(1.0, x - corner[0], y - corner[1]) for x, y, _ in near]
    A = [[sum(r[i] * r[j] for r in rows) for j in range(3)] for i in range(3)]
    b = [sum(r[i] * q[2] for r, q in zip(rows, near)) for i in range(3)]
    Ab = [[b[i] if j == 0 else A[i][j] for j in range(3)] for i in range(3)]
    return det3(Ab) / det3(A), len(pts)


def zigzag_index(X, Y, p, h):
    """Checkerboard measure of a point field p (e.g. the mean stress) on the initial lattice of
    2 x 2 points per cell of size h (X, Y the initial positions): per point and direction with
    neighbours on both sides min(|dp1|, |dp2|) if the two differences change sign, else 0; the RMS
    over the range of p (a smooth or stepped field gives 0, a checkerboard its amplitude)."""
    pts = {(round(x / h * 2 - 0.5), round(y / h * 2 - 0.5)): v for x, y, v in zip(X, Y, p)}
    z = []
    for (i, j), v in pts.items():
        for a, b in (((i - 1, j), (i + 1, j)), ((i, j - 1), (i, j + 1))):
            if a in pts and b in pts:
                d1, d2 = v - pts[a], pts[b] - v
                z.append(min(abs(d1), abs(d2)) if d1 * d2 < 0 else 0.0)
    return (sum(q * q for q in z) / len(z)) ** 0.5 / (max(pts.values()) - min(pts.values()))


def relative_differences(a, b, columns=None):
    """Per column of two equally ordered tables (read_csv): max |a - b| / max |a| (the scale is 1
    for a column of zeros). Default columns: every column of a but 'id'."""
    out = {}
    for col in columns if columns is not None else [c for c in a if c != "id"]:
        scale = max(abs(v) for v in a[col]) or 1.0
        out[col] = max(abs(x - y) for x, y in zip(a[col], b[col])) / scale
    return out


def zero_crossings(t, y, direction=0):
    """Times where y crosses 0 (linear interpolation). direction: +1 up, -1 down, 0 both."""
    out = []
    for i in range(1, len(y)):
        a, b = y[i - 1], y[i]
        if (a < 0 <= b and direction >= 0) or (a > 0 >= b and direction <= 0):
            if a != b:
                out.append(t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a))
    return out


def crossing_periods(t, y):
    """Spacings between successive upward zero crossings of y and between successive downward
    ones (each a period of an oscillation about 0), upward ones first."""
    up, down = zero_crossings(t, y, +1), zero_crossings(t, y, -1)
    return [b - a for a, b in zip(up, up[1:])] + [b - a for a, b in zip(down, down[1:])]


_failures = []


def check(cond, message):
    print(("PASS: " if cond else "FAIL: ") + message)
    if not cond:
        _failures.append(message)


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def finish():
    if _failures:
        print(f"{len(_failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


def parasitic_growth_rate(series, t_early=0.05, start_factor=1e3, stop_fraction=1e-3):
    """Amplitude growth rate [1/s] of a growing parasitic mode from a series.csv dict: half
    the least-squares slope of log(strain energy) over the rows where it exceeds
    start_factor x its largest value before t_early (the mode dominates) and stays below
    stop_fraction x the initial kinetic energy (the perturbation is still small: linear
    regime). Returns (rate, number of rows fitted); rate is nan with fewer than 3 rows."""
    import math
    t, e = series["time"], series["strain_energy"]
    base = max(x for tt, x in zip(t, e) if tt < t_early)
    cap = stop_fraction * series["kinetic_energy"][0]
    pts = [(tt, math.log(x)) for tt, x in zip(t, e) if start_factor * base < x < cap]
    if len(pts) < 3:
        return float("nan"), len(pts)
    mx = sum(a for a, _ in pts) / len(pts)
    my = sum(b for _, b in pts) / len(pts)
    return 0.5 * sum((a - mx) * (b - my) for a, b in pts) / sum((a - mx) ** 2 for a, _ in pts), len(pts)


def time_average_last_period(t, u):
    """(average, period): the time average of u(t) over its last full
    oscillation period (between the last two upward crossings of its mean,
    trapezoidal on the linear interpolation of u) and that period; (nan, nan)
    if there are fewer than two crossings."""
    mean = sum(u) / len(u)
    up = zero_crossings(t, [x - mean for x in u], direction=+1)
    if len(up) < 2:
        return float("nan"), float("nan")
    ta, tb = up[-2], up[-1]
    num = 0.0
    for i in range(1, len(t)):
        lo, hi = max(t[i - 1], ta), min(t[i], tb)
        if hi > lo:
            f = lambda x: u[i - 1] + (u[i] - u[i - 1]) * (x - t[i - 1]) / (t[i] - t[i - 1])
            num += 0.5 * (f(lo) + f(hi)) * (hi - lo)
    return num / (tb - ta), tb - ta


def polyfit_noise(xs, ys, deg=4):
    """RMS residual of a least-squares polynomial fit of degree deg of ys(xs)."""
    n = deg + 1
    A = [[sum(x ** (i + j) for x in xs) for j in range(n)] for i in range(n)]
    b = [sum(y * x ** i for x, y in zip(xs, ys)) for i in range(n)]
    M = [row[:] + [b[i]] for i, row in enumerate(A)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        M[c], M[p] = M[p], M[c]
        for r in range(n):
            if r != c:
                f = M[r][c] / M[c][c]
                for k in range(c, n + 1):
                    M[r][k] -= f * M[c][k]
    coef = [M[i][n] / M[i][i] for i in range(n)]
    r2 = sum((y - sum(coef[i] * x ** i for i in range(n))) ** 2 for x, y in zip(xs, ys))
    return (r2 / len(xs)) ** 0.5


if __name__ == "__main__":
    # `talus_verify.py mpirun ARGS...`: mpirun ARGS with a private session base (for ctest)
    if len(sys.argv) < 3 or sys.argv[1] != "mpirun":
        sys.exit("usage: talus_verify.py mpirun ARGS...")
    e = child_env()
    with mpirun_session(e):
        sys.exit(subprocess.run(["mpirun"] + sys.argv[2:], env=e).returncode)
