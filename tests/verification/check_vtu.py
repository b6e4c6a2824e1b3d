"""The point-set VTU files of talus (lib/talus/io/vtu.h: raw appended binary, one piece per rank
plus a PVTU record) read by VTK's own XML readers (Debian python3-vtk9, the library ParaView uses)
and by talus-plot, against the run's own full-precision table particles_final.csv.

A small 2D block of talus-explicit, run on 1 and on 2 ranks (and talus-semi-implicit, below); in the 2-rank run the block lies in
one rank's half of the grid, so the other rank writes a piece without points. Checked, per run:
  * every piece and the PVTU record are read by vtkXMLUnstructuredGridReader /
    vtkXMLPUnstructuredGridReader without an error, with the number of points the run reports,
    every array the PVTU lists, of the listed type and components, one vertex cell per point;
  * the last output equals particles_final.csv (the doubles of the same state) point by point
    (matched by id) to Float32 round-off: |vtk - csv| <= 2^-23 |csv| + 1e-30 for the positions,
    velocity, displacement, stresses and volume (Float32 is what deal.II's writer stored too);
    the ids exactly;
  * talus-plot's reader gives the same values as VTK's for every array and the points (exactly);
  * the FieldData TIME of each piece equals the time of its PVD record (12 digits there);
  * the empty piece of the 2-rank run is a valid file (VTK reads 0 points, every array present);
  * talus-semi-implicit (the same writer) on 2 ranks: every output of its soil and water sets
    read by VTK (480 points each) and by talus-plot alike.
Run with the Debian python3 that has the vtk module (tests/verification/explicit.cmake).
"""
import glob
import importlib.machinery
import importlib.util
import os
import re
import sys
import xml.etree.ElementTree as ET

import talus_verify as tv

try:
    import vtk
except ImportError:
    tv.fail(f"{sys.executable}: no python module 'vtk': install the Debian package python3-vtk9 "
            "(scripts/install-deps.sh)")

tools, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
loader = importlib.machinery.SourceFileLoader("talus_plot", os.path.join(os.path.dirname(__file__), "..", "..",
                                                                          "tools", "talus-plot"))
spec = importlib.util.spec_from_loader("talus_plot", loader)
plot = importlib.util.module_from_spec(spec)
loader.exec_module(plot)

BLOCK = tv.elastic_block_scene((4, 1), (40, 10), (0.2, 0), (1.0, 0.4), 0.06,
                             {"directory": "out", "vtu interval": "0.02", "progress": "false",
                              "final particles csv": "true"})

VTK_TYPES = {"Float32": vtk.VTK_FLOAT, "UInt64": vtk.VTK_UNSIGNED_LONG_LONG}


class Errors:
    """Collects the error and warning events of a VTK reader (VTK reports them, it does not raise)."""

    def __init__(self, obj):
        self.messages = []
        obj.AddObserver("ErrorEvent", self)
        obj.AddObserver("WarningEvent", self)

    def __call__(self, obj, event, data=None):
        self.messages.append(event)


def read(path, parallel):
    r = vtk.vtkXMLPUnstructuredGridReader() if parallel else vtk.vtkXMLUnstructuredGridReader()
    errors = Errors(r)
    r.SetFileName(path)
    r.Update()
    return r.GetOutput(), errors.messages + ([f"error code {r.GetErrorCode()}"] if r.GetErrorCode() else [])


def arrays_of(out):
    pd = out.GetPointData()
    res = {}
    for i in range(pd.GetNumberOfArrays()):
        a = pd.GetArray(i)
        nc = a.GetNumberOfComponents()
        res[a.GetName()] = (a.GetDataType(), nc, [a.GetComponent(j, c) for j in range(a.GetNumberOfTuples())
                                                  for c in range(nc)])
    return res


def check_outputs(label, d, pvd_name, np, n_total):
    """Every output of one point set (its PVD record) read by VTK and talus-plot; n_total: the
    points of each output (None: the sum of the pieces' NumberOfPoints). Returns the records and
    the number of pieces without points."""
    pvd = ET.parse(os.path.join(d, pvd_name)).getroot()
    records = [(float(ds.get("timestep")), ds.get("file")) for ds in pvd.iter("DataSet")]
    empty_pieces, bad = 0, []
    for time, pvtu in records:
        head = ET.parse(os.path.join(d, pvtu)).getroot()
        listed = {a.get("Name"): (a.get("type"), int(a.get("NumberOfComponents", "1")))
                  for a in head.iter("PDataArray") if a.get("Name")}
        pieces = [p.get("Source") for p in head.iter("Piece")]
        if len(pieces) != np:
            bad.append(f"{pvtu}: {len(pieces)} pieces")
        whole, errs = read(os.path.join(d, pvtu), True)
        n_here = 0
        got = arrays_of(whole)
        for k, (typ, nc) in listed.items():
            if k not in got or got[k][0] != VTK_TYPES[typ] or got[k][1] != nc:
                bad.append(f"{pvtu}: array {k} ({typ}, {nc}) read as {got.get(k, (None, None))[:2]}")
        for piece in pieces:
            out_p, errs_p = read(os.path.join(d, piece), False)
            n = out_p.GetNumberOfPoints()
            n_here += n
            empty_pieces += n == 0
            t = out_p.GetFieldData().GetArray("TIME")
            if errs_p or t is None or abs(t.GetValue(0) - time) > 1e-11 * max(abs(time), 1e-3):
                bad.append(f"{piece}: errors {errs_p}, TIME {t.GetValue(0) if t else None} vs the PVD's {time}")
            cells_ok = out_p.GetNumberOfCells() == n and all(out_p.GetCellType(c) == vtk.VTK_VERTEX and
                                                             out_p.GetCell(c).GetPointId(0) == c for c in range(n))
            if not cells_ok:
                bad.append(f"{piece}: not one vertex cell per point")
            mine = arrays_of(out_p)
            if set(mine) != set(listed):
                bad.append(f"{piece}: arrays {sorted(mine)} vs the PVTU's {sorted(listed)}")
                continue
            # talus-plot's reader: the same values, exactly
            pts, tp = plot.read_vtu(os.path.join(d, piece), list(listed))
            vtk_pts = [out_p.GetPoint(i) for i in range(n)]
            if [tuple(p) for p in pts] != vtk_pts:
                bad.append(f"{piece}: talus-plot's points differ from VTK's")
            for k in listed:
                if tp[k][0] != mine[k][1] or tp[k][1] != mine[k][2]:
                    bad.append(f"{piece}: talus-plot's array {k} differs from VTK's")
        expected = n_here if n_total is None else n_total
        if errs or whole.GetNumberOfPoints() != expected or whole.GetNumberOfCells() != expected or n_here == 0:
            bad.append(f"{pvtu}: {whole.GetNumberOfPoints()} points, {whole.GetNumberOfCells()} cells "
                       f"(pieces {n_here}), {errs}")
    tv.check(len(records) >= 3 and not bad,
             f"{label}: {len(records)} PVTU records of {pvd_name} and their pieces read by VTK and talus-plot, "
             f"{n_here} points, every listed array ({len(listed)}) present and equal {bad[:5]}")
    return records, empty_pieces


def check_run(name, np, expect_empty_piece):
    rc, out, err = tv.run_tool(os.path.join(tools, "talus-explicit"), BLOCK, os.path.join(work, name), "block",
                               np=np)
    d = os.path.join(work, name, "out")
    n_total = int(re.search(r"done: \d+ steps, (\d+) particles", out).group(1))
    records, empty_pieces = check_outputs(name, d, "particles.pvd", np, n_total)
    if expect_empty_piece:
        tv.check(empty_pieces == len(records), f"{name}: the piece of the rank without points is a valid "
                                               f"file in every output ({empty_pieces} of {len(records)})")

    # the last output against particles_final.csv (the same state in double precision)
    last, _ = read(os.path.join(d, records[-1][1]), True)
    a = arrays_of(last)
    csv = tv.read_csv(os.path.join(d, "particles_final.csv"))
    row = {int(i): k for k, i in enumerate(csv["id"])}
    ids = [int(v) for v in a["id"][2]]
    tv.check(sorted(ids) == sorted(row), f"{name}: the ids of the last output are those of particles_final.csv "
                                         f"({len(ids)} points)")
    worst, where = 0.0, ""

    def compare(label, vtk_value, exact):
        nonlocal worst, where
        e = abs(vtk_value - exact) / (abs(exact) * 2.0 ** -23 + 1e-30)
        if e > worst:
            worst, where = e, label

    pairs = [("volume", 0, "volume")] + [(s, 0, s) for s in a if s.startswith("stress_")]
    for j, pid in enumerate(ids):
        k = row[pid]
        p = last.GetPoint(j)
        for c, ax in enumerate("xy"):
            compare(f"pos_{ax}", p[c], csv[f"pos_{ax}"][k])
            compare(f"velocity {ax}", a["velocity"][2][3 * j + c], csv[f"v_{ax}"][k])
            compare(f"displacement {ax}", a["displacement"][2][3 * j + c], csv[f"u_{ax}"][k])
        if p[2] != 0 or a["velocity"][2][3 * j + 2] != 0 or a["displacement"][2][3 * j + 2] != 0:
            worst, where = float("inf"), "z of a 2D vector"
        for arr, c, col in pairs:
            compare(arr, a[arr][2][j + c], csv[col][k])
    tv.check(worst <= 1.0, f"{name}: last output = particles_final.csv to Float32 round-off: worst "
                           f"{worst:.3f} x 2^-23 relative ({where})")


check_run("np1", 1, False)
check_run("np2", 2, True)

# the same writer in talus-semi-implicit: the soil and water sets of the geostatic saturated column
# (480 + 480 points, 3 outputs) on 2 ranks
semi = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "parameter_files", "verification",
                         "semi_implicit_hydrostatic.prm")).read()
for k, v in {"output/directory": "out", "time/end time": "0.003", "output/vtu interval": "0.0015",
             "output/series interval": "0", "output/final particles csv": "false"}.items():
    semi = tv.prm_set(semi, k, v)
tv.run_tool(os.path.join(tools, "talus-semi-implicit"), semi, os.path.join(work, "semi"), "semi", np=2)
for s in ("soil", "water"):
    check_outputs(f"semi-implicit {s}", os.path.join(work, "semi", "out"), s + ".pvd", 2, 480)
tv.finish()
