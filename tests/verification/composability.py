#!/usr/bin/env python3
"""The composability matrix of talus-explicit (issue 38 item 4), generated, not written by hand.

Every feature of the explicit family is switched on, one at a time, in a tiny 2D scene, under every
option set of the columns (kernel, velocity transfer, volumetric stabilisation) and run for a few steps.
Each pair must either run and conserve what it must, or be refused with exit 2 and a reason:

* runs: exit 0, finite series, the number of points and the total mass (series.csv `mass`, both
  phases) constant to 1e-12 relative, and, where no external force acts on the scene (no gravity,
  walls, loads, damping), the momentum constant to 1e-10 of the scene's |sum m v|;
* refused: exit 2 before any output, with the .prm entry named in the message.

Anything else (a crash, NaNs, a run that loses mass or momentum) fails the test whatever the document says.

  composability.py TOOL WORKDIR --write FILE   run the matrix and write the document FILE
  composability.py TOOL WORKDIR --check FILE   run the matrix and fail if FILE differs from it

`make composability` regenerates docs/composability.md; ctest `verification.composability_matrix`
(fast) checks it.
"""
import concurrent.futures
import difflib
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import talus_verify as tv  # noqa: E402

BASE = tv.prm_set(tv.elastic_block_scene((1, 1), (8, 8), (0.25, 0.25), (0.625, 0.625), 1,
                                         {"directory": "out", "series interval": "1e-9", "vtu interval": "0",
                                          "progress": "false"}, walls=False, gravity="0, 0",
                                         initial_velocity=(0.2, 0.1), courant=0.4), "time/maximum steps", "6")

# The columns: one option set each (APIC needs B-splines: measured unstable with linear ones).
COLUMNS = [
    ("linear", {"numerics/shape function": "linear"}),
    ("B-spline", {"numerics/shape function": "quadratic bspline"}),
    ("B-spline + APIC", {"numerics/shape function": "quadratic bspline", "numerics/velocity transfer": "apic"}),
    ("linear + F-bar", {"numerics/shape function": "linear", "numerics/volumetric stabilisation": "f-bar"}),
    ("B-spline + F-bar", {"numerics/shape function": "quadratic bspline",
                          "numerics/volumetric stabilisation": "f-bar"}),
]

GRAVITY = {"gravity/acceleration": "0, -9.81"}
FLOOR = dict(GRAVITY, **{"boundary conditions/fixed": "2"})

# The rows: (name, entries set, ranks, momentum conserved). Momentum is checked only where nothing
# outside the points acts on them.
FEATURES = [
    ("plain scene (nothing switched on)", {}, 1, True),
    ("contact between two bodies (Coulomb, mu 0.3)", {
        "number of bodies": "2", "body 1/name": "second block", "body 1/shape": "box",
        "body 1/lower corner": "0.625, 0.25", "body 1/upper corner": "0.875, 0.5",
        "body 1/particles per direction": "2", "body 1/initial velocity": "-0.2, 0",
        "contact/pairs": "0, 1, 0.3, 0"}, 1, True),
    ("contact with adhesion", {
        "number of bodies": "2", "body 1/name": "second block", "body 1/shape": "box",
        "body 1/lower corner": "0.625, 0.25", "body 1/upper corner": "0.875, 0.5",
        "body 1/particles per direction": "2", "body 1/initial velocity": "-0.2, 0",
        "contact/pairs": "0, 1, 0.3, 50"}, 1, True),
    ("coupled 2-phase material (single point)", {
        "material 0/pore liquid/drainage": "coupled", "material 0/pore liquid/porosity": "0.3",
        "material 0/pore liquid/hydraulic conductivity": "1e-3",
        "material 0/pore liquid/liquid bulk modulus": "1e6"}, 1, True),
    ("1-phase liquid with free-surface detection", {
        "material 0/model": "newtonian", "material 0/newtonian/bulk modulus": "1e5",
        "liquid/free surface factor": "0.7"}, 1, True),
    ("traction on a body face", {
        "loads/number of tractions": "1", "loads/traction 0/apply to": "body face", "loads/traction 0/body": "0",
        "loads/traction 0/face": "y+", "loads/traction 0/traction": "0, -1e3"}, 1, False),
    ("point load", {
        "loads/number of point loads": "1", "loads/point load 0/position": "0.4, 0.6",
        "loads/point load 0/force": "0, -10"}, 1, False),
    ("prescribed velocity of a body", {
        "loads/number of velocity conditions": "1", "loads/velocity 0/apply to": "body",
        "loads/velocity 0/body": "0", "loads/velocity 0/velocity": "0.1, 0"}, 1, False),
    ("prescribed velocity of a region", {
        "loads/number of velocity conditions": "1", "loads/velocity 0/apply to": "region",
        "loads/velocity 0/region lower corner": "0.25, 0.25", "loads/velocity 0/region upper corner": "0.375, 0.625",
        "loads/velocity 0/velocity": "0.1, 0"}, 1, False),
    ("gravity on a fixed floor", FLOOR, 1, False),
    ("friction wall (Coulomb, mu 0.3)", dict(GRAVITY, **{
        "boundary conditions/friction": "2", "boundary conditions/friction coefficient": "0.3"}), 1, False),
    ("rigid plate (displacement control)", dict(GRAVITY, **{
        "boundary conditions/number of rigid plates": "1", "boundary conditions/rigid plate 0/apply to": "boundary",
        "boundary conditions/rigid plate 0/boundary id": "2", "boundary conditions/rigid plate 0/direction": "y",
        "boundary conditions/rigid plate 0/surface": "rough",
        "boundary conditions/rigid plate 0/displacement": "0"}), 1, False),
    ("K0 initial stress", dict(FLOOR, **{"body 0/initial stress/K0 procedure": "true",
                                         "body 0/initial stress/K0": "0.5"}), 1, False),
    ("stages (two)", {"number of stages": "2", "stage 0/duration": "0.01", "stage 1/duration": "0.01"}, 1, True),
    ("local damping", dict(FLOOR, **{"damping/local damping": "0.5"}), 1, False),
    ("viscous damping", {"damping/viscous damping": "1"}, 1, False),
    ("quasi-static convergence check", dict(FLOOR, **{
        "damping/local damping": "0.5", "convergence/enabled": "true", "convergence/check interval": "2"}), 1, False),
    ("mass scaling", {"mass scaling/factor": "10"}, 1, True),
    ("strain smoothing = cell", {"numerics/strain smoothing": "cell"}, 1, True),
    ("strain smoothing = nodal", {"numerics/strain smoothing": "nodal"}, 1, True),
    ("integration = mpm-mixed", {"numerics/integration": "mpm-mixed"}, 1, True),
    ("integration = fem", {"numerics/integration": "fem"}, 1, True),
    ("integration = ul-fem", {"numerics/integration": "ul-fem"}, 1, True),
    ("load balancing (2 ranks)", {"load balancing/interval": "2"}, 2, True),
    ("2 ranks", {}, 2, True),
    ("checkpoints", {"checkpoint/interval": "2", "checkpoint/directory": "ckpt"}, 1, True),
    ("results file (HDF5)", {"output/results file": "results.h5"}, 1, True),
    ("VTU snapshots", {"output/vtu interval": "0.005"}, 1, True),
    ("probes", {"output/probes": "0.4, 0.4"}, 1, True),
]

MASS_TOL = 1e-12
MOMENTUM_TOL = 1e-10


def entry_named(text):
    """The first .prm entry path a refusal names ('numerics/...'), or None."""
    m = re.search(r"([a-z][a-z0-9 ]*(?: [0-9]+)?(?:/[a-z0-9][a-z0-9 \-]*)+)", text)
    return m.group(1).strip() if m else None


def run_pair(tool, workdir, ci, fi):
    col, opts = COLUMNS[ci]
    feat, entries, ranks, conserve = FEATURES[fi]
    text = BASE
    for k, v in list(opts.items()) + list(entries.items()):
        text = tv.prm_set(text, k, v)
    d = os.path.join(workdir, f"c{ci}_f{fi}")
    rc, out, err = tv.run_tool(tool, text, d, "scene", np=ranks, expect_rc=None, timeout=600)
    both = (out + err).strip()
    if rc == 2:
        written = os.path.exists(os.path.join(d, "out"))
        # the tool's message: "talus-explicit: error: in '<file>': <entry>: <why>" (under mpirun
        # followed by Open MPI's own lines)
        msg = [l for l in both.splitlines() if "error:" in l]
        reason = msg[0].split("error:", 1)[1].strip() if msg else both.splitlines()[-1] if both else ""
        reason = re.sub(r"^in '[^']*': *", "", reason)
        reason = re.sub(r"Line <\d+> of file <[^>]*>: *", "", reason)
        if written:
            return ("fails", f"refused after writing output: {reason}")
        if not entry_named(reason):
            return ("fails", f"refused without naming an entry: {reason}")
        return ("refused", reason)
    if rc != 0:
        return ("fails", f"exit {rc}: {both.splitlines()[-1] if both else ''}")
    s = tv.read_csv(os.path.join(d, "out", "series.csv"))
    rows = len(s["time"])
    if rows < 2:
        return ("fails", f"series.csv has {rows} rows")
    for k, v in s.items():
        # force_ratio, energy_ratio: nan until the stage's first convergence check, energy_ratio
        # inf while the scene moves without external work done on it (docs/explicit.md)
        if k in ("force_ratio", "energy_ratio"):
            v = [x for x in v if not (isinstance(x, float) and (math.isnan(x) or x == math.inf))]
        if any(isinstance(x, float) and not math.isfinite(x) for x in v):
            return ("fails", f"non-finite values in series.csv column {k}")
    m0, m1 = s["mass"][0], s["mass"][-1]
    if m0 <= 0 or abs(m1 - m0) > MASS_TOL * m0:
        return ("fails", f"mass {m0:.15g} -> {m1:.15g}")
    if s["n_particles"][0] != s["n_particles"][-1]:
        return ("fails", f"points {s['n_particles'][0]:.0f} -> {s['n_particles'][-1]:.0f}")
    if conserve:
        p0 = [s["momentum_x"][0], s["momentum_y"][0]]
        p1 = [s["momentum_x"][-1], s["momentum_y"][-1]]
        scale = math.hypot(*p0)
        dp = math.hypot(p1[0] - p0[0], p1[1] - p0[1])
        if dp > MOMENTUM_TOL * scale:
            return ("fails", f"momentum changed by {dp / scale:.2e} of |p| (bound {MOMENTUM_TOL:g})")
        return ("runs", f"{rows - 1} steps; mass {abs(m1 - m0) / m0:.0e}, momentum {dp / scale:.0e}")
    return ("runs", f"{rows - 1} steps; mass {abs(m1 - m0) / m0:.0e}")


def document(results):
    lines = [
        "# Composability matrix of talus-explicit",
        "",
        "Generated by `tests/verification/composability.py` (`make composability`); do not edit by hand:",
        "ctest `verification.composability_matrix` runs every pair again and fails when this file and the",
        "behaviour disagree (issue 38 item 4).",
        "",
        "Every feature (row) is switched on alone in a tiny 2D scene (an elastic block of 3 x 3 cells with",
        "2 x 2 points per cell, moving at (0.2, 0.1) m/s in an 8 x 8 grid, no gravity, no walls) under each",
        "option set (column: shape function, velocity transfer, volumetric stabilisation) and run for 6 steps.",
        "A pair either **runs** (exit 0; points and total mass constant to 1e-12; where nothing outside the",
        "points acts on them, marked *p*, the momentum constant to 1e-10 of |sum m v|) or is **refused**",
        "with exit 2 before any output, naming the .prm entry; the reasons are listed below the table.",
        "A pair that does neither fails the test. APIC is shown on B-splines only: with linear shape functions it",
        "is refused (measured unstable, docs/shape-functions.md, \"APIC\").",
        "",
    ]
    reasons = []
    header = "| feature | " + " | ".join(c for c, _ in COLUMNS) + " |"
    lines += [header, "|" + "---|" * (len(COLUMNS) + 1)]
    for fi, (feat, _, ranks, conserve) in enumerate(FEATURES):
        cells = []
        for ci in range(len(COLUMNS)):
            status, detail = results[(ci, fi)]
            if status == "runs":
                cells.append("runs" + (", *p*" if conserve else ""))
            elif status == "refused":
                if detail not in reasons:
                    reasons.append(detail)
                cells.append(f"refused [{reasons.index(detail) + 1}]")
            else:
                cells.append("FAILS")
        lines.append(f"| {feat} | " + " | ".join(cells) + " |")
    lines += ["", "## Reasons given for the refusals", ""]
    for i, r in enumerate(reasons):
        lines.append(f"{i + 1}. {r}")
    lines.append("")
    return "\n".join(lines)


def main():
    if len(sys.argv) != 5 or sys.argv[3] not in ("--write", "--check"):
        sys.exit(__doc__)
    tool, workdir, mode, path = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
    os.makedirs(workdir, exist_ok=True)
    pairs = [(ci, fi) for fi in range(len(FEATURES)) for ci in range(len(COLUMNS))]
    jobs = int(os.environ.get("TALUS_COMPOSABILITY_JOBS", "2"))
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as ex:
        results = dict(zip(pairs, ex.map(lambda p: run_pair(tool, workdir, *p), pairs)))
    failed = [(p, r) for p, r in results.items() if r[0] == "fails"]
    for (ci, fi), (status, detail) in sorted(results.items(), key=lambda x: (x[0][1], x[0][0])):
        print(f"{status:8s} {COLUMNS[ci][0]:18s} | {FEATURES[fi][0]:45s} | {detail[:160]}")
    for (ci, fi), (_, detail) in failed:
        tv.check(False, f"{COLUMNS[ci][0]} x {FEATURES[fi][0]}: {detail}")
    doc = document(results)
    if mode == "--write":
        with open(path, "w") as f:
            f.write(doc)
        print(f"wrote {path}")
    else:
        with open(path) as f:
            old = f.read()
        diff = list(difflib.unified_diff(old.splitlines(), doc.splitlines(), path, "behaviour", lineterm=""))
        if diff:
            print("\n".join(diff))
        tv.check(not diff, f"{path} matches the behaviour (regenerate with `make composability`)")
    tv.finish()


if __name__ == "__main__":
    main()
