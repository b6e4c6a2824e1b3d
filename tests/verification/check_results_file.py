"""The shared results file (output/results file) and probes (output/probes) of
talus-implicit and talus-semi-implicit (issue 37, formulations/common/results_file.h,
probes.h). Runs FAMILY's small scene with a results file and probes (implicit: one probe at a
point equidistant from 4 material points, dyadic coordinates: the tie goes to the lowest
id) and checks
  (a) every series/<column> of the file equals the column of series.csv (exactly:
      the file holds the parsed text), the attributes steps / probes / integration, and
      probes/displacement|velocity|stress equal the probe<k>_* columns;
  (b) each probe follows the point nearest to it at t = 0 (by the initial positions
      x - u of the file's particle table, ties: lowest id): its final displacement,
      velocity and stress in the last series row equal that point's in particles/
      to 1e-11 relative (series.csv holds 12 digits), its displacement equals
      particles_final.csv (soil_final.csv) to 1e-9 relative, probes/initial_position equals the point's x - u to 1e-12;
      semi-implicit: probe<k>_pore_pressure equals the pore pressure of the water point
      nearest at t = 0 in water/ to 1e-11 relative, and water/ holds every water point;
  (c) talus-compare reads the file: against itself every item is 0 (linf, tolerance 0:
      exit 0); against a run with 1 % more load (implicit) or half the time
      (semi-implicit), final particle displacements, relative Linf 1e-3: exit 1;
  (d) semi-implicit: the same run on 2 ranks, talus-compare of probes, grid and particle
      fields and two series columns: relative Linf <= 1e-10;
      implicit: the same run on 2 ranks gives the same file content to 1e-10
      (series columns relative to their largest value, a probe's components relative
      to the largest of that field, the Newton residual columns left out: round-off; particles matched by id, grid nodes by coordinates, each
      field relative to its largest value).
  (c) implicit, with EXPLICIT_PRM (the elastic oedometer under gravity): the static implicit
      solve (neo-Hookean) against talus-explicit's quasi-static state (linear elastic), final grid
      and particle displacements and stresses, probe displacements: relative L2 <= 2e-3
      (measured 5.5e-4 .. 8.8e-4: the two models differ by the order of the strain, 1.5e-3);
Usage: check_results_file.py TOOLS_DIR RESULTS_DUMP FAMILY PRM WORKDIR [EXPLICIT_PRM]
  FAMILY: implicit | semi-implicit
"""
import math
import os
import re
import subprocess
import sys

import talus_verify as tv

tools, dump, family, prm_path, work = sys.argv[1:6]
explicit_prm = sys.argv[6] if len(sys.argv) > 6 else None
tool = f"{tools}/talus-{family}"
text = open(prm_path).read()
if family == "implicit":
    # the static block under a top traction (8 x 12 cells, 2 x 2 points a cell: x, y = 1/32 + k/16)
    probes = [(0.5, 1.0), (0.5, 0.5), (0.3, 0.2)]  # (0.5, 0.5): 4 points at the same distance
    short = {"loads/traction 0/traction": "0, -1010"}  # 1 % more load
else:
    # the consolidation column, 0.03 s (3 x 24 cells, 2 x 2 points a cell: x = 0.0125 + k 0.025)
    text = tv.prm_set(text, "time/end time", "0.03")
    probes = [(0.07, 1.0), (0.03, 0.5)]
    short = {"time/end time": "0.015"}  # half the time
text = tv.prm_set(text, "output/probes", "; ".join(f"{x}, {y}" for x, y in probes))
text = tv.prm_set(text, "output/results file", "results.h5")
text = tv.prm_set(text, "output/final particles csv", "true")


def run(name, np=1, extra=None):
    t = tv.prm_set(text, "output/directory", f"{work}/{name}")
    for k, v in (extra or {}).items():
        t = tv.prm_set(t, k, v)
    tv.run_tool(tool, t, work, name, np=np)
    return f"{work}/{name}"


def read_dump(h5, names, attributes=False):
    out = f"{h5}.{abs(hash(tuple(names))) % 10**8}.csv"
    p = subprocess.run([dump, h5, out] + (["--attributes"] if attributes else []) + names, capture_output=True,
                       text=True)
    if p.returncode != 0:
        tv.fail(f"results_dump {h5}: {p.stderr.strip()}")
    with open(out) as f:
        lines = f.read().splitlines()
    attrs = {}
    if lines and lines[0].startswith("# "):
        attrs = dict(kv.split("=", 1) for kv in lines[0][2:].split(";"))
        lines = lines[1:]
    header = lines[0].split(",")
    cols = {h: [] for h in header}
    for line in lines[1:]:
        for h, x in zip(header, line.split(",")):
            cols[h].append(float(x))
    return cols, attrs


def table(d, group, field, dim):
    """rows of a dim-column (or 1-column) field of a dump"""
    n = len(d[f"{group}/id"])
    if f"{group}/{field}" in d:
        return [[d[f"{group}/{field}"][i]] for i in range(n)]
    return [[d[f"{group}/{field}[{c}]"][i] for c in range(dim)] for i in range(n)]


def nearest(X, ids, q):
    """index of the point nearest to q at t = 0 (X rounded to 1e-9: x - u carries round-off), ties: lowest id"""
    key = [(math.dist([round(v, 9) for v in X[i]], q), ids[i]) for i in range(len(ids))]
    return min(range(len(ids)), key=lambda i: key[i])


point_fields = ["id", "position", "initial_position", "displacement", "velocity", "stress", "volume"]
dim, nst = 2, 4
axes = "xy"
stress_names = ["stress_xx", "stress_yy", "stress_zz", "stress_xy"]

a = run("np1")
series = tv.read_csv(f"{a}/series.csv")
names = list(series)
h5 = f"{a}/results.h5"
fs, attrs = read_dump(h5, [f"series/{n}" for n in names], attributes=True)
# (a) the series
bad = [n for n in names if fs[f"series/{n}"] != series[n] and
       not all((x == y) or (math.isnan(x) and math.isnan(y)) for x, y in zip(fs[f"series/{n}"], series[n]))]
tv.check(not bad, f"(a) every series/<column> of the file equals series.csv ({len(names)} columns, "
                  f"{len(series['time'])} rows){'; differ: ' + str(bad) if bad else ''}")
n_probes = len(probes)
tv.check(attrs.get("steps") == str(int(series["step"][-1])) and attrs.get("probes") == str(n_probes) and
         attrs.get("integration") == family,
         f"(a) attributes steps {attrs.get('steps')}, probes {attrs.get('probes')}, integration "
         f"'{attrs.get('integration')}'")
pt, _ = read_dump(h5, ["probes/time", "probes/displacement", "probes/velocity", "probes/stress"])
same = pt["probes/time"] == series["time"]
for k in range(n_probes):
    for d in range(dim):
        same = same and pt[f"probes/displacement[{k * dim + d}]"] == series[f"probe{k}_u{axes[d]}"]
        same = same and pt[f"probes/velocity[{k * dim + d}]"] == series[f"probe{k}_v{axes[d]}"]
    for q in range(nst):
        same = same and pt[f"probes/stress[{k * nst + q}]"] == series[f"probe{k}_{stress_names[q]}"]
tv.check(same, "(a) probes/time, displacement, velocity, stress equal the probe columns of series.csv")

# (b) the tracked points
pd, _ = read_dump(h5, [f"particles/{f}" for f in point_fields])
ids = [int(i) for i in pd["particles/id"]]
X = table(pd, "particles", "initial_position", dim)
u = table(pd, "particles", "displacement", dim)
v = table(pd, "particles", "velocity", dim)
s = table(pd, "particles", "stress", nst)
p0, _ = read_dump(h5, ["probes/initial_position"])
if family == "implicit":
    csv, csv_u = tv.read_csv(f"{a}/particles_final.csv"), "u_"
    by_id = {int(j): r for r, j in enumerate(csv["id"])}
    csv_row = lambda i: by_id[ids[i]]
else:  # soil_final.csv has no id: the row at the point's position
    csv, csv_u = tv.read_csv(f"{a}/soil_final.csv"), "displacement_"
    xf = table(pd, "particles", "position", dim)
    csv_row = lambda i: min(range(len(csv["pos_x"])), key=lambda r: math.dist((csv["pos_x"][r], csv["pos_y"][r]),
                                                                             xf[i]))


def rel(a, b):
    """max |a - b| over the components, relative to the largest |b|"""
    return max(abs(x - y) for x, y in zip(a, b)) / (max(abs(y) for y in b) or 1.0)


last = -1
for k, q in enumerate(probes):
    i = nearest(X, ids, q)
    got_u = [series[f"probe{k}_u{axes[d]}"][last] for d in range(dim)]
    got_v = [series[f"probe{k}_v{axes[d]}"][last] for d in range(dim)]
    got_s = [series[f"probe{k}_{stress_names[c]}"][last] for c in range(nst)]
    # series.csv holds 12 significant digits: 1e-11 of the vector's size
    du = max(rel(got_u, u[i]), rel(got_v, v[i]), rel(got_s, s[i]))
    tv.check(du < 1e-11, f"(b) probe {k} at {q}: point id {ids[i]} (X = {X[i]}), final u {got_u} = its particles/ "
                         f"displacement {u[i]}, velocity and stress too ({du:.1e} relative)")
    r = csv_row(i)
    dc = rel([csv[f"{csv_u}{axes[d]}"][r] for d in range(dim)], u[i])
    tv.check(dc < 1e-9, f"(b) probe {k}: particles_final.csv displacement of id {ids[i]} agrees ({dc:.1e} relative)")
    dx = max(abs(p0[f"probes/initial_position[{d}]"][k] - X[i][d]) for d in range(dim))
    tv.check(dx < 1e-12, f"(b) probe {k}: probes/initial_position = the point's x - u ({dx:.1e})")
if family == "implicit":  # dyadic coordinates: the distances tie exactly in floating point too
    tie = nearest(X, ids, probes[1])
    dist = lambda j: math.dist([round(c, 9) for c in X[j]], probes[1])
    n_tied = sum(1 for j in range(len(ids)) if dist(j) == dist(tie))
    tv.check(n_tied == 4, f"(b) the tie probe has {n_tied} points at the same distance (lowest id {ids[tie]} tracked)")
if family == "semi-implicit":
    wd, wa = read_dump(h5, ["water/id", "water/initial_position", "water/displacement", "water/pore_pressure"])
    wcsv = tv.read_csv(f"{a}/water_final.csv")
    tv.check(len(wd["water/id"]) == len(wcsv["pos_x"]),
             f"(b) water/ holds every water point ({len(wd['water/id'])}, water_final.csv {len(wcsv['pos_x'])})")
    wids = [int(i) for i in wd["water/id"]]
    WX = table(wd, "water", "initial_position", dim)
    for k, q in enumerate(probes):
        j = nearest(WX, wids, q)
        got = series[f"probe{k}_pore_pressure"][last]
        tv.check(rel([got], [wd["water/pore_pressure"][j]]) < 1e-11,
                 f"(b) probe {k}: pore pressure {got} = that of the water point {wids[j]} nearest at t = 0")

# (c) talus-compare reads the file
items = "probes,grid:displacement,grid:stress,particles:displacement,particles:stress,series:load_factor" \
    if family == "implicit" else "probes,grid:displacement,grid:stress,particles:displacement,particles:stress," \
                                 "kinetic_energy_soil"
p = subprocess.run([f"{tools}/talus-compare", f"--quantities={items}", "--norm=linf", "--tolerance=0", h5, h5],
                   capture_output=True, text=True, env=tv.child_env())
tv.check(p.returncode == 0, f"(c) talus-compare of the file with itself: exit {p.returncode} (0: every item 0)")
b = run("other", extra=short)
p = subprocess.run([f"{tools}/talus-compare", "--quantities=particles:displacement", "--norm=relative-linf",
                    "--tolerance=1e-3", "--time=final", h5, f"{b}/results.h5"], capture_output=True, text=True,
                   env=tv.child_env())
tv.check(p.returncode == 1, f"(c) talus-compare against the other run: exit {p.returncode} (1: differs)")

# (c) implicit against explicit: the elastic oedometer column under gravity (0.1 x 1 m, 4 x 40
# cells, 2 x 2 points a cell), talus-explicit damped to its quasi-static state (linear elastic)
# against one static talus-implicit solve (neo-Hookean, same E, nu): the same point ids, grid
# nodes by coordinates; the two models differ by the order of the strain (1.5e-3 at the base)
if family == "implicit" and explicit_prm:
    ex = tv.prm_set(open(explicit_prm).read(), "output/directory", f"{work}/oedometer_explicit")
    tv.run_tool(f"{tools}/talus-explicit", ex, work, "oedometer_explicit")
    im = """set dimension = 2
subsection time
  set end time  = 1
  set time step = 0.5
end
subsection implicit
  set analysis = static
end
subsection newton
  set residual relative = 1e-10
end
subsection grid
  set lower corner = 0, 0
  set upper corner = 0.1, 1
  set cells        = 4, 40
end
subsection boundary conditions
  set fixed  = 2
  set roller = 0, 1
end
subsection gravity
  set acceleration = 0, -9.81
end
subsection output
  set directory    = WORK/oedometer_implicit
  set vtu interval = 0
  set probes       = 0.04, 1; 0.04, 0.49
  set results file = results.h5
  set progress     = false
end
set number of materials = 1
subsection material 0
  set model   = neo hookean
  set density = 2000
  subsection neo hookean
    set young modulus = 1e7
    set poisson ratio = 0.3
  end
end
set number of bodies = 1
subsection body 0
  set name                    = column
  set shape                   = box
  set lower corner            = 0, 0
  set upper corner            = 0.1, 1
  set particles per direction = 2
end
""".replace("WORK", work)
    tv.run_tool(tool, im, work, "oedometer_implicit")
    p = subprocess.run([f"{tools}/talus-compare", "--quantities=grid:displacement,grid:stress,particles:displacement,"
                        "particles:stress,probe_displacements", "--norm=relative-l2", "--tolerance=2e-3",
                        "--time=final", f"{work}/oedometer_implicit/results.h5",
                        f"{work}/oedometer_explicit/results.h5"], capture_output=True, text=True, env=tv.child_env())
    print(p.stdout.strip())
    tv.check(p.returncode == 0, f"(c) implicit static vs explicit quasi-static oedometer: talus-compare exit "
                                f"{p.returncode} (0: every item within 2e-3 relative L2)")

# (d) 1 vs 2 ranks
if family == "implicit":
    c = run("np2", np=2)
    series2 = tv.read_csv(f"{c}/series.csv")
    skip = {"residual_first", "residual_last", "newton_order", "increment_order", "linear_iterations",
            "load_imbalance"}
    worst = (0.0, "")

    def group(n):
        """the columns whose largest value is a column's scale: a probe's components of one field (the
        round-off shear stress on the scale of the normal ones), the centre of mass"""
        m = re.match(r"probe\d+_(u|v|stress)", n) or re.match(r"(centre_of_mass)_", n)
        return [c for c in names if m and re.match(m.group(0), c)] or [n]

    for n in names:
        if n in skip:
            continue
        sc = max(abs(x) for c in group(n) for x in series[c]) or 1.0
        d = max(abs(x - y) for x, y in zip(series[n], series2[n])) / sc
        worst = max(worst, (d, "series " + n))
    pd2, _ = read_dump(f"{c}/results.h5", [f"particles/{f}" for f in point_fields])
    row2 = {int(i): r for r, i in enumerate(pd2["particles/id"])}
    tv.check(sorted(row2) == sorted(ids), f"(d) the same {len(ids)} point ids on 2 ranks")
    for f in point_fields[1:]:
        cols = [h for h in pd if h.startswith(f"particles/{f}[") or h == f"particles/{f}"]
        sc = max(abs(x) for h in cols for x in pd[h]) or 1.0
        d = max(abs(pd[h][r] - pd2[h][row2[ids[r]]]) for h in cols for r in range(len(ids))) / sc
        worst = max(worst, (d, "particles/" + f))
    gf = ["vertices", "mass", "displacement", "velocity", "stress"]
    g1, _ = read_dump(h5, [f"grid/{f}" for f in gf])
    g2, _ = read_dump(f"{c}/results.h5", [f"grid/{f}" for f in gf])
    key = lambda g, r: (round(g["grid/vertices[0]"][r], 9), round(g["grid/vertices[1]"][r], 9))
    n1 = len(g1["grid/mass"])
    r2 = {key(g2, r): r for r in range(len(g2["grid/mass"]))}
    tv.check(sorted(r2) == sorted(key(g1, r) for r in range(n1)), f"(d) the same {n1} grid nodes on 2 ranks")
    for f in gf[1:]:
        cols = [h for h in g1 if h.startswith(f"grid/{f}[") or h == f"grid/{f}"]
        sc = max(abs(x) for h in cols for x in g1[h]) or 1.0
        d = max(abs(g1[h][r] - g2[h][r2[key(g1, r)]]) for h in cols for r in range(n1)) / sc
        worst = max(worst, (d, "grid/" + f))
    tv.check(worst[0] <= 1e-10, f"(d) 1 and 2 ranks: largest relative difference {worst[0]:.2e} ({worst[1]}) "
                                f"<= 1e-10")
if family == "semi-implicit":  # through talus-compare: the soil's probes, grid and particle fields
    c = run("np2", np=2)
    p = subprocess.run([f"{tools}/talus-compare", "--quantities=probes,grid:displacement,grid:stress,"
                        "particles:displacement,particles:stress,kinetic_energy_soil,min_pore_pressure",
                        "--norm=relative-linf", "--tolerance=1e-10", f"{c}/results.h5", h5], capture_output=True,
                       text=True, env=tv.child_env())
    print(p.stdout.strip())
    tv.check(p.returncode == 0, f"(d) 1 and 2 ranks: talus-compare exit {p.returncode} (0: within 1e-10 relative Linf)")
tv.finish()
