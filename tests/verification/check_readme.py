"""docs/verification/README.md matches the CSVs it was generated from (issue 6).

Every table row of the README is compared with the CSV row it came from, number by
number, to the printed precision: the convergence tables (value, abscissa, error,
pairwise order, run times, points, steps, ns per point-step), the observed orders, the
Courant sweeps, the large-deformation row and the smoothing criteria; the work-precision
section (issue 42): its tables number by number against csv/work_precision/, one figure per
scene, and its other lines (orders, PASS/FAIL, crossovers, recommendations) equal to those
regenerated from the CSVs by tests/verification/work_precision.py. Also: every plot
the README shows exists and is a PNG (the large-deformation case shows one snapshot of its final
state, issue 17), every convergence CSV has a table, and a PASS/FAIL
printed matches the criterion flag in the CSV. A number edited in the README or a
regenerated CSV without its README fails this check.
Usage: check_readme.py DOCS_VERIFICATION_DIR
"""
import csv
import math
import os
import re
import sys

import talus_verify as tv

docs = sys.argv[1]
text = open(os.path.join(docs, "README.md")).read()


def rows_of(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def same(printed, value):
    """printed (string from the README) equals value (CSV) to the printed precision."""
    printed = printed.strip().strip("*")
    if printed in ("-", "not analysed"):
        return value in ("", "nan") or (not isinstance(value, str) and not math.isfinite(value)) or float(value) == 0
    p, v = float(printed), float(value)
    m = re.match(r"-?(\d*)\.?(\d*)(e[-+]?\d+)?$", printed)
    if m.group(3):  # scientific: digits after the point
        tol = 0.5 * 10 ** (int(m.group(3)[1:]) - len(m.group(2)))
    else:
        tol = 0.5 * 10 ** (-len(m.group(2)))
    return abs(p - v) <= tol * (1 + 1e-9) + 1e-300


def table_after(heading):
    """Data rows (lists of cells) of the first table after the heading line."""
    i = text.index(heading)
    lines = text[i:].splitlines()[1:]
    out, started = [], False
    for line in lines:
        if line.startswith("|"):
            started = True
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not set(cells[0]) <= set("-") and not cells[0].startswith("value") and cells[0] not in (
                    "case", "exit code", "criterion", "Courant number"):
                out.append(cells)
        elif started:
            break
    return out


n_numbers = 0
summaries = sorted(f for f in os.listdir(os.path.join(docs, "csv")) if f.endswith("_summary.csv"))
tv.check(len(summaries) >= 5, f"at least 5 convergence families in csv/ (found {len(summaries)})")
for sfile in summaries:
    name = sfile[: -len("_summary.csv")]
    heading = f"### {name}\n"
    if heading not in text:
        tv.check(False, f"{name}: section in the README")
        continue
    s = rows_of(os.path.join(docs, "csv", sfile))[0]
    sec = text[text.index(heading):].split("\n### ")[0]
    m = re.search(r"Observed order: \*\*([-\d.]+|-)\*\*", sec)
    ok = m is not None and same(m.group(1), s["observed_order"])
    tv.check(ok, f"{name}: observed order {m.group(1) if m else '?'} = CSV {float(s['observed_order']):.4f}")
    rows = rows_of(os.path.join(docs, "csv", name + ".csv"))
    table = table_after(heading)
    tv.check(len(table) == len(rows), f"{name}: {len(table)} table rows = {len(rows)} CSV rows")
    cols = ["value", "abscissa", "error", "pair_order", "run_time_s", "solver_wall_s", "n_particles", "n_steps",
            "ns_per_particle_step"]
    bad = []
    for cells, r in zip(table, rows):
        for c, col in zip(cells, cols):
            n_numbers += 1
            if not same(c, r[col]):
                bad.append(f"{col} {c} vs {r[col]}")
    tv.check(not bad, f"{name}: every number of the table matches the CSV" + (f" ({'; '.join(bad[:3])})" if bad else ""))
    for png in re.findall(r"\]\((png/[^)]+)\)", sec):
        path = os.path.join(docs, png)
        tv.check(os.path.isfile(path) and open(path, "rb").read(4) == b"\x89PNG", f"{name}: plot {png} exists")

sw = os.path.join(docs, "csv", "courant_sweeps.csv")
tv.check(os.path.isfile(sw), "Courant sweep CSV exists")
if os.path.isfile(sw):
    rows = rows_of(sw)
    table = table_after("### Courant sweeps")
    tv.check(len(table) == len(rows), f"Courant sweeps: {len(table)} rows = {len(rows)} CSV rows")
    bad = []
    for cells, r in zip(table, rows):
        if cells[0] != r["name"]:
            bad.append(f"name {cells[0]} vs {r['name']}")
        cells[4] = cells[4].split(" (")[0]
        if float(r["dt_scheme"]) > 0:
            cells[7] = str(cells[7])
            n_numbers += 1
            if not same(cells[7], float(r["dt_measured"]) / float(r["dt_scheme"])):
                bad.append(f"{r['name']} ratio {cells[7]}")
        for c, col in zip(cells[3:7], ["dt_formula", "dt_scheme", "probe_stable_factor", "probe_unstable_factor"]):
            n_numbers += 1
            if not same(c, r[col]):
                bad.append(f"{r['name']} {col} {c} vs {r[col]}")
        if cells[8] != ("PASS" if r["ok"] == "1" else "FAIL"):
            bad.append(f"{r['name']} result {cells[7]} vs ok={r['ok']}")
    tv.check(not bad, "Courant sweeps: numbers and results match the CSV" + (f" ({'; '.join(bad[:3])})" if bad else ""))

ld = os.path.join(docs, "csv", "large_deformation.csv")
if os.path.isfile(ld):
    r = rows_of(ld)[0]
    cells = table_after("### Large deformation")[0]
    bad = [f"{col} {c} vs {r[col]}" for c, col in zip(cells[:5], ["exit_code", "energy_max_over_initial",
                                                                   "energy_end_over_initial", "cell_changes_per_point",
                                                                   "wall_s"]) if not same(c, r[col])]
    n_numbers += 5
    if cells[5] != ("PASS" if r["ok"] == "1" else "FAIL"):
        bad.append("result")
    tv.check(not bad, "large deformation: row matches the CSV" + (f" ({'; '.join(bad)})" if bad else ""))
else:
    tv.check(False, "large-deformation CSV exists")

# issue 17: the large-deformation case shows its final state (a snapshot drawn by the run)
sec = text[text.index("### Large deformation"):].split("\n### ")[0] if "### Large deformation" in text else ""
pics = re.findall(r"\]\((png/[^)]+)\)", sec)
tv.check(len(pics) == 1 and os.path.isfile(os.path.join(docs, pics[0]))
         and open(os.path.join(docs, pics[0]), "rb").read(8) == b"\x89PNG\r\n\x1a\n",
         f"large deformation: one snapshot embedded and present ({', '.join(pics) or 'none'})")
# every picture the README shows exists and is a PNG
missing = [x for x in re.findall(r"\]\((png/[^)]+)\)", text)
           if not (os.path.isfile(os.path.join(docs, x)) and open(os.path.join(docs, x), "rb").read(4) == b"\x89PNG")]
tv.check(not missing, "every picture of the README exists and is a PNG" + (f" (missing: {missing[:3]})" if missing else ""))

cg = os.path.join(docs, "csv", "crossing_growth.csv")
if os.path.isfile(cg):
    rows = rows_of(cg)
    table = table_after("### Cell crossing")
    bad = [] if len(table) == len(rows) else [f"{len(table)} rows vs {len(rows)}"]
    for cells, r in zip(table, rows):
        for c, col in zip(cells[:5], ["courant", "growth_per_step_predicted", "rate_predicted", "rate_measured",
                                      "steps_fitted"]):
            n_numbers += 1
            if not same(c, r[col]):
                bad.append(f"{col} {c} vs {r[col]}")
        if cells[5] != ("PASS" if r["ok"] == "1" else "FAIL"):
            bad.append("result")
    tv.check(not bad, "cell-crossing growth: rows match the CSV" + (f" ({'; '.join(bad[:3])})" if bad else ""))
else:
    tv.check(False, "cell-crossing growth CSV exists")

sm = os.path.join(docs, "csv", "smoothing.csv")
if os.path.isfile(sm):
    rows = rows_of(sm)
    table = table_after("### Near-incompressible")
    ok = len(table) == len(rows) and all(c[0] == r["criterion"] and c[1] == ("PASS" if r["ok"] == "1" else "FAIL")
                                         for c, r in zip(table, rows))
    tv.check(ok, f"smoothing: {len(rows)} criteria and results match the CSV")
else:
    tv.check(False, "smoothing CSV exists")
# issue 42: the work-precision section against csv/work_precision/ (the tables number by
# number; the orders, PASS/FAIL, crossovers and recommendations as regenerated from the CSVs)
import work_precision as wp  # noqa: E402

wpd = os.path.join(docs, "csv", "work_precision")


def wp_rows(name):
    p = os.path.join(wpd, name + ".csv")
    if not os.path.isfile(p):
        return None
    return [{k: float(v) for k, v in r.items()} for r in rows_of(p)]


def wp_summary(name):
    p = os.path.join(wpd, name + "_summary.csv")
    if not os.path.isfile(p):
        return None
    r = rows_of(p)[0]
    r["observed_order"] = float(r["observed_order"])
    return r


expected, _ = wp.section(wp_rows, wp_summary)
tv.check("## Work-precision across the families (issue 42)\n" in text, "work-precision: section in the README")
for sc in wp.SCENES:
    heading = f"### work-precision: {sc.name} ({sc.kind})\n"
    if heading not in text:
        tv.check(False, f"work-precision {sc.name}: section in the README")
        continue
    sec = text[text.index(heading):].split("\n### ")[0]
    table = [[c.strip() for c in line.strip().strip("|").split("|")] for line in sec.splitlines()
             if line.startswith("| ") and not line.startswith("| family")]
    bad, n_rows = [], 0
    for f in sc.families:
        rows = wp_rows(f.name)
        tv.check(rows is not None and wp_summary(f.name) is not None, f"work-precision {f.name}: CSVs exist")
        if rows is None:
            continue
        mine = [c for c in table if c[0] == f.name]
        n_rows += len(rows)
        if len(mine) != len(rows):
            bad.append(f"{f.name}: {len(mine)} table rows vs {len(rows)} CSV rows")
            continue
        for cells, r in zip(mine, rows):
            for c, col in zip(cells[1:], wp.TABLE_COLS):
                n_numbers += 1
                if not same(c, r[col]):
                    bad.append(f"{f.name} {col} {c} vs {r[col]}")
    tv.check(not bad and len(table) == n_rows, f"work-precision {sc.name}: {len(table)} table rows, every number "
             "matches the CSVs" + (f" ({'; '.join(bad[:3])})" if bad else ""))
    pics = re.findall(r"\]\((png/[^)]+)\)", sec)
    tv.check(pics == [f"png/{wp.figure_name(sc)}"], f"work-precision {sc.name}: one figure ({', '.join(pics)})")
# Terzaghi at k = 1e-7: the cost probes' table against their CSVs
LOW_K_HEADING = "### work-precision: terzaghi_k1e-7, the cost of the other families"
if LOW_K_HEADING in text:
    sec = text[text.index(LOW_K_HEADING):].split("\n### ")[0]
    table = [[c.strip() for c in line.strip().strip("|").split("|")] for line in sec.splitlines()
             if line.startswith("| ") and not line.startswith("| probe")]
    bad, n_rows = [], 0
    for name, _, t_probe in wp.LOW_K:
        rows = wp_rows(name)
        if rows is None:
            bad.append(f"{name}: no CSV")
            continue
        mine = [c for c in table if c[0] == name]
        xs = wp.low_k_rows(name, rows, t_probe)
        n_rows += len(xs)
        if len(mine) != len(xs):
            bad.append(f"{name}: {len(mine)} rows vs {len(xs)}")
            continue
        for cells, x in zip(mine, xs):
            for c, v in zip(cells[1:], [x[0], x[1], x[2], x[3] * 1e3, x[4], x[5], x[5] / 3600]):
                n_numbers += 1
                if not same(c, v) and not (abs(float(c) - v) <= 0.5e-2 * abs(v)):  # [h]: 3 significant digits
                    bad.append(f"{name} {c} vs {v}")
    tv.check(not bad and len(table) == n_rows, f"work-precision terzaghi_k1e-7: {len(table)} probe rows match the "
             "CSVs" + (f" ({'; '.join(bad[:3])})" if bad else ""))
else:
    tv.check(False, "work-precision: the terzaghi_k1e-7 cost estimate in the README")
# every other line of the section (orders, criteria, crossovers, recommendations) as regenerated
i = text.find("## Work-precision across the families (issue 42)")
j = text.find("\n## ", i + 1)
printed = text[i:j].strip().splitlines() if i >= 0 else []
expected = "\n".join(expected).strip().splitlines()
differ = [(a, b) for a, b in zip(printed, expected) if a.strip() != b.strip() and not a.startswith("| ")]
tv.check(len(printed) == len(expected) and not differ,
         "work-precision: orders, criteria, crossovers and recommendations as regenerated from the CSVs"
         + (f" (first difference: '{differ[0][0][:120]}' vs '{differ[0][1][:120]}')" if differ else
            f" ({len(printed)} lines vs {len(expected)})"))

print(f"{n_numbers} numbers compared")
tv.finish()
