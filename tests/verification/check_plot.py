"""talus-plot and `output/png snapshots` (issue 17).

A small 2D run (an elastic block settling under gravity on the base, 6 particle outputs, one probe) is
drawn by the solver itself (png snapshots = every output) and by talus-plot:
  * every PNG announced ('talus-plot: wrote <path>') exists, nothing else is written, and each
    is a valid PNG of the requested size with more than one colour (decoded here with zlib);
  * one snapshot per output and the series plots (energies, probes, points) are drawn;
  * bad input (missing run directory, unknown field, a field the run does not have, a time
    outside the run, an unknown .prm entry) exits 2 with a message naming it and writes nothing;
  * the coloured extent of the block at t = 0 (footprints of the points = the seeded box
    [0.5, 1.3] x [0, 0.4]) matches the axes mapping within 2 pixels: the plot frame is found
    in the image (its black border) and the data window is the one talus-plot reports;
  * a 3D run drawn as a slice and as a projection; an empty slice is refused (exit 2);
  * a 2-rank run draws its last output from both VTU pieces;
  * a failure to draw after a complete run is a warning (exit 0, results in place); a solver
    without talus-plot next to it refuses png snapshots with exit 2 before running;
  * talus-fem accepts and draws `png snapshots = final`;
  * talus-semi-implicit draws its water set's pore pressure itself (png snapshots = final), and
    talus-plot draws both sets (soil.pvd, water.pvd) of every output in one window; the pore
    pressure and the soil's stress of the geostatic column and the deflection of the implicit
    cantilever are gradients (many colours of points inside the plot frame, not only the colour bar);
  * talus-implicit draws its last output and the Newton iteration and residual plots;
  * a png field the family never writes (pore pressure in talus-implicit, free surface in
    talus-semi-implicit, a z component in 2D) is refused with exit 2 before the run.
Usage: check_plot.py TOOLS_DIR WORKDIR
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

import talus_verify as tv

tools, work = (os.path.abspath(x) for x in sys.argv[1:3])
plot = os.path.join(tools, "talus-plot")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)

BLOCK = tv.elastic_block_scene((2, 1), (20, 10), (0.5, 0), (1.3, 0.4), 0.1,
                             {"directory": "run", "vtu interval": "0.02", "probes": "0.9, 0.4", "progress": "false"})


def read_png(path):
    """(width, height, set of RGB colours, rows of RGB tuples) of an 8-bit PNG (types 0, 2, 3, 4, 6)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("no PNG signature")
    pos, idat, plte = 8, b"", None
    while pos < len(data):
        n, typ = struct.unpack(">I4s", data[pos: pos + 8])
        body = data[pos + 8: pos + 8 + n]
        if zlib.crc32(typ + body) != struct.unpack(">I", data[pos + 8 + n: pos + 12 + n])[0]:
            raise ValueError(f"bad CRC in chunk {typ}")
        if typ == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif typ == b"PLTE":
            plte = [tuple(body[i: i + 3]) for i in range(0, len(body), 3)]
        elif typ == b"IDAT":
            idat += body
        elif typ == b"IEND":
            break
        pos += 12 + n
    if depth != 8 or interlace:
        raise ValueError(f"unsupported PNG (bit depth {depth}, interlace {interlace})")
    bpp = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ctype]
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1: (y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        if ctype in (2, 6):
            px = [tuple(line[i: i + 3]) for i in range(0, stride, bpp)]
        elif ctype == 3:
            px = [plte[v] for v in line]
        else:
            px = [(v, v, v) for v in line[::bpp]]
        rows.append(px)
    return w, h, set(p for r in rows for p in r), rows


def run_plot(args, expect_rc=0):
    p = subprocess.run([plot] + args, capture_output=True, text=True, cwd=work)
    if p.returncode != expect_rc:
        print(p.stdout, p.stderr)
    return p


def announced(stdout):
    return re.findall(r"^talus-plot: wrote (.+)$", stdout, re.M)


def files_below(d):
    return sorted(os.path.join(r, f) for r, _, fs in os.walk(d) for f in fs) if os.path.isdir(d) else []


def check_pngs(paths, size, what):
    ok, bad = 0, []
    for pth in paths:
        try:
            w, h, colours, _ = read_png(pth)
            if (w, h) == tuple(size) and len(colours) > 1:
                ok += 1
            else:
                bad.append(f"{os.path.basename(pth)}: {w}x{h}, {len(colours)} colour(s)")
        except (OSError, ValueError, KeyError, zlib.error, struct.error) as e:
            bad.append(f"{os.path.basename(pth)}: {e}")
    tv.check(ok == len(paths) and paths, f"{what}: {ok}/{len(paths)} valid PNGs of {size[0]}x{size[1]} with "
             f"more than one colour" + (f" ({'; '.join(bad[:3])})" if bad else ""))


# ---- 1. the solver draws its own pictures: every output + series
text = tv.prm_set(BLOCK, "output/png snapshots", "every output")
text = tv.prm_set(text, "output/png field", "velocity magnitude")
rc, out, err = tv.run_tool(os.path.join(tools, "talus-explicit"), text, work, "block")
run = os.path.join(work, "run")
n_out = len(re.findall(r"<DataSet ", open(os.path.join(run, "particles.pvd")).read()))
paths = [os.path.join(work, x) for x in announced(out)]
snaps = [x for x in paths if "/snapshot_velocity_magnitude_" in x]
tv.check(n_out == 6 and len(snaps) == n_out, f"solver: {len(snaps)} snapshots announced for {n_out} outputs")
tv.check(all(os.path.isfile(x) for x in paths), f"solver: the {len(paths)} announced PNGs exist")
tv.check(sorted(os.path.abspath(x) for x in paths) == files_below(os.path.join(run, "png")),
         "solver: nothing but the announced PNGs in run/png")
auto_h = read_png(snaps[0])[1] if snaps else 0
check_pngs(snaps, (800, auto_h), "solver snapshots (auto size: 800 wide, the scene's height at equal scale)")
tv.check(260 <= auto_h <= 500, f"auto size: 800 x {auto_h} (a plot area of 200 to 700 px, the block 0.8 x 0.4 m)")
check_pngs([x for x in paths if "/series_" in x], (800, 500), "solver series plots")
fields = open(os.path.join(run, "fields.txt")).read()
tv.check("material 0 = linear elastic" in fields and "dimension = 2" in fields, "solver wrote fields.txt")

# ---- 2. talus-plot: chosen size, every output, stress field, all series plots
p = run_plot(["--frames=all", "--field=stress yy", "--size=640,480", "--series-size=700,400", "--output=p1", "run"])
paths = announced(p.stdout)
tv.check(p.returncode == 0, f"talus-plot exit code {p.returncode}")
tv.check(sorted(os.path.abspath(os.path.join(work, x)) for x in paths) == files_below(os.path.join(work, "p1")),
         f"talus-plot: the {len(paths)} announced PNGs are exactly the files written")
names = sorted(os.path.basename(x) for x in paths)
want = ["series_energies.png", "series_points.png", "series_probes_displacement.png", "series_probes_stress.png",
        "series_probes_velocity.png"]
tv.check(all(w in names for w in want), f"series plots {', '.join(want)} drawn")
tv.check(sum(1 for x in names if x.startswith("snapshot_stress_yy_")) == n_out, "one stress snapshot per output")
check_pngs([os.path.join(work, x) for x in paths if "snapshot_" in x], (640, 480), "talus-plot snapshots")
check_pngs([os.path.join(work, x) for x in paths if "series_" in x], (700, 400), "talus-plot series plots")
m = re.search(r"colour range \(robust\) \[([-\d.e+]+), ([-\d.e+]+)\]", p.stdout)
tv.check(m is not None and float(m.group(1)) < float(m.group(2)) <= 0.0 + 1e-9 * abs(float(m.group(1))),
         f"one colour range for all frames, from the compressive stresses ({m.group(0) if m else '?'})")

# ---- 3. bad input: exit 2, a message naming it, nothing written
with open(os.path.join(work, "bad.prm"), "w") as f:
    f.write("set run directory = run\nsubsection snapshots\n  set colour = red\nend\n")
before = files_below(work)
cases = [
    (["--output=bad", "no_such_run"], "'no_such_run': no such run directory or parameter file"),
    (["--output=bad", "--run-directory=no_such_run"], "'no_such_run': no such directory"),
    (["--output=bad", "--field=temperature", "run"], "'temperature' is not available"),
    (["--output=bad", "--field=pore pressure", "run"], "'pore pressure' is not available"),
    (["--output=bad", "--frames=times 0.05, 7", "run"], "time 7 s is outside the run"),
    (["--output=bad", "--frames=times -1", "run"], "outside the run"),
    (["--output=bad", "--frames=sometimes", "run"], "possible values"),
    (["--output=bad", "--size=10,10", "run"], "snapshots/size"),
    (["--output=bad", "--series=probes,rainfall", "run"], "series/plots"),
    (["--output=bad", "--colour=1", "run"], "unknown option"),
]
cases.append((["--output=bad", "bad.prm"], "line 3: unknown entry 'snapshots/colour'"))
for args, msg in cases:
    p = run_plot(args, 2)
    tv.check(p.returncode == 2 and msg in p.stderr and "Traceback" not in p.stderr,
             f"{' '.join(args[1:])}: exit {p.returncode}, message: {p.stderr.strip()[:160]}")
after = files_below(work)
tv.check(after == before and not os.path.exists(os.path.join(work, "bad")),
         "bad input wrote nothing" + (f" (new: {sorted(set(after) - set(before))[:3]})" if after != before else ""))
# --check validates and writes nothing either
p = run_plot(["--check", "--output=chk", "run"])
tv.check(p.returncode == 0 and not os.path.exists(os.path.join(work, "chk")), "--check: exit 0, nothing written")

# ---- 4. coloured extent of the block at t = 0 vs the axes mapping
# a fixed window: the mapping does not depend on what is drawn
p = run_plot(["--frames=first", "--field=body id", "--series=none", "--size=900,600", "--window=0.2,1.6,-0.1,0.6",
              "--output=p2", "run"])
m = re.search(r"window x \[(\S+), (\S+)\] y \[(\S+), (\S+)\] m = pixels x \[(\d+), (\d+)\] y \[(\d+), (\d+)\]",
              p.stdout)
png = announced(p.stdout)[0]
w, h, colours, rows = read_png(os.path.join(work, png))
x0, x1, y0, y1 = (float(m.group(i)) for i in range(1, 5))
hx0, hx1, hy1, hy0 = (int(m.group(i)) for i in range(5, 9))  # reported: left, right, bottom, top pixel


def dark(c):
    return max(c) < 100


def find_line(n, hint, is_dark_at):
    """The pixel line (column or row) near `hint` that is dark over most of the frame."""
    best = None
    for k in range(max(0, hint - 4), min(n, hint + 5)):
        if is_dark_at(k) and (best is None or abs(k - hint) < abs(best - hint)):
            best = k
    return best


col_dark = lambda x: sum(dark(rows[y][x]) for y in range(hy0 + 5, hy1 - 5)) > 0.9 * (hy1 - hy0 - 10)
row_dark = lambda y: sum(dark(rows[y][x]) for x in range(hx0 + 5, hx1 - 5)) > 0.9 * (hx1 - hx0 - 10)
L, R = find_line(w, hx0, col_dark), find_line(w, hx1, col_dark)
T, B = find_line(h, hy0, row_dark), find_line(h, hy1, row_dark)
tv.check(None not in (L, R, T, B), f"plot frame found in the image at the reported pixels: x {L}..{R}, y {T}..{B}")
if None not in (L, R, T, B):
    # coloured: at least half covered by the body colour #1f77b4 (saturation 149) over white
    coloured = [(x, y) for y in range(T + 2, B - 1) for x in range(L + 2, R - 1)
                if max(rows[y][x]) - min(rows[y][x]) > 75]
    cx0, cx1 = min(c[0] for c in coloured), max(c[0] for c in coloured)
    cy0, cy1 = min(c[1] for c in coloured), max(c[1] for c in coloured)
    to_px = lambda x: L + (x - x0) / (x1 - x0) * (R - L)
    to_py = lambda y: B - (y - y0) / (y1 - y0) * (B - T)
    ex = (to_px(0.5), to_px(1.3), to_py(0.4), to_py(0.0))
    got = (cx0, cx1 + 1, cy0, cy1 + 1)
    dev = max(abs(a - b) for a, b in zip(ex, got))
    print(f"block [0.5, 1.3] x [0, 0.4] m: expected pixels x {ex[0]:.1f}..{ex[1]:.1f}, y {ex[2]:.1f}..{ex[3]:.1f}; "
          f"coloured x {got[0]}..{got[1]}, y {got[2]}..{got[3]}")
    tv.check(dev <= 2.0, f"coloured extent matches the block within 2 pixels (largest deviation {dev:.2f} px)")
    sx, sy = (R - L) / (x1 - x0), (B - T) / (y1 - y0)
    tv.check(abs(sx / sy - 1) < 0.01, f"equal scale on both axes ({sx:.2f} and {sy:.2f} px/m)")

# ---- 5. 3D: a slice and a projection; an empty slice is refused
c3 = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "parameter_files", "verification",
                       "elastic_column_gravity_3d.prm")).read()
c3 = tv.prm_set(c3, "output/directory", "run3d")
c3 = tv.prm_set(c3, "time/end time", "0.02")
c3 = tv.prm_set(c3, "output/vtu interval", "0.01")
tv.run_tool(os.path.join(tools, "talus-explicit"), c3, work, "column3d")
for view, tag in (("slice y = 0.03", "slice"), ("projection x", "projection")):
    p = run_plot(["--frames=all", "--field=stress zz", "--series=energies", f"--view={view}", "--size=500,700",
                  f"--output=p3_{tag}", "run3d"])
    snaps = [os.path.join(work, x) for x in announced(p.stdout) if "snapshot_" in x]
    tv.check(p.returncode == 0 and len(snaps) == 3, f"3D {view}: exit {p.returncode}, {len(snaps)} snapshots")
    check_pngs(snaps, (500, 700), f"3D {view}")
p = run_plot(["--view=slice y = 5", "--output=p3_empty", "run3d"], 2)
tv.check(p.returncode == 2 and "no material point in the slice" in p.stderr
         and not os.path.exists(os.path.join(work, "p3_empty")), f"empty slice: exit {p.returncode}, nothing written")

# ---- 6. two ranks: the snapshot of the last output reads both VTU pieces (all 128 points)
text = tv.prm_set(BLOCK, "output/directory", "run_np2")
text = tv.prm_set(text, "output/png snapshots", "final")
rc, out, err = tv.run_tool(os.path.join(tools, "talus-explicit"), text, work, "block_np2", np=2)
m = re.search(r"talus-plot: 1 frame\(s\) of (\d+) points from (\d+) VTU piece", out)
tv.check(m is not None and m.groups() == ("128", "2") and len(announced(out)) == 6,
         f"2 ranks: {m.group(0) if m else 'no frame line'}; {len(announced(out))} PNGs announced")

# ---- 7. a failure to draw: a warning, the run still exits 0 (docs/plot.md)
text = tv.prm_set(BLOCK, "output/directory", "run_warn")
text = tv.prm_set(text, "output/png snapshots", "final")
text = tv.prm_set(text, "output/png field", "pore pressure")  # a 1-phase run has none
rc, out, err = tv.run_tool(os.path.join(tools, "talus-explicit"), text, work, "block_warn", expect_rc=None)
tv.check(rc == 0 and "warning: output/png snapshots = final: the pictures were not drawn" in err
         and "'pore pressure' is not available" in err and os.path.isfile(os.path.join(work, "run_warn", "series.csv")),
         f"drawing failed after a complete run: exit {rc}, warning on stderr, results in place")
# talus-plot missing next to the solver: refused by --check (exit 2) before any run
lone = os.path.join(work, "lone")
os.makedirs(lone)
shutil.copy(os.path.join(tools, "talus-explicit"), lone)
text = tv.prm_set(BLOCK, "output/png snapshots", "final")
rc, out, err = tv.run_tool(os.path.join(lone, "talus-explicit"), text, lone, "lone", expect_rc=None)
tv.check(rc == 2 and "output/png snapshots" in err and "needs talus-plot next to the solver" in err
         and not os.path.exists(os.path.join(lone, "run")),
         f"no talus-plot next to the solver: exit {rc}, {err.strip()[:150]}")

# ---- 8. talus-fem draws its final state too
text = tv.prm_set(BLOCK, "output/directory", "runfem")
text = tv.prm_set(text, "output/png snapshots", "final")
text = tv.prm_set(text, "output/vtu interval", "0")
rc, out, err = tv.run_tool(os.path.join(tools, "talus-fem"), text, work, "blockfem")
paths = [os.path.join(work, x) for x in announced(out)]
tv.check(sum("snapshot_displacement_magnitude_" in x for x in paths) == 1 and all(os.path.isfile(x) for x in paths),
         f"talus-fem: png snapshots = final drew {len(paths)} PNGs (one snapshot)")


def window_lines(stdout):
    """The reported mapping of each set drawn: (set or '', window and pixels text)."""
    return re.findall(r"snapshots of '[^']*'(?: on the (\w+) points)?, colour range \(\w+\) \[[^\]]*\], (window .*)$",
                      stdout, re.M)


def interior_colours(path, stdout):
    """Distinct saturated colours of the pixels inside the reported plot frame that equal their four
    neighbours: the colours of the points themselves, without the antialiased edges, the frame, the
    text and the colour bar (which holds the whole palette whatever is drawn)."""
    _, _, _, rows = read_png(path)
    m = re.search(r"pixels x \[(\d+), (\d+)\] y \[(\d+), (\d+)\]", stdout)
    x0, x1, y1, y0 = (int(m.group(i)) for i in range(1, 5))
    out = set()
    for y in range(y0 + 3, y1 - 3):
        for x in range(x0 + 3, x1 - 3):
            c = rows[y][x]
            if max(c) - min(c) > 40 and c == rows[y - 1][x] == rows[y + 1][x] == rows[y][x - 1] == rows[y][x + 1]:
                out.add(c)
    return out


vdir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "parameter_files", "verification")
idir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "parameter_files", "implicit")

# ---- 9. talus-semi-implicit: the soil and water sets (soil.pvd, water.pvd), pore pressure on the water
# the geostatic saturated column (480 soil + 480 water points), 20 steps, 3 outputs
semi = open(os.path.join(vdir, "semi_implicit_hydrostatic.prm")).read()
for k, v in {"output/directory": "runsemi", "time/end time": "0.003", "output/vtu interval": "0.0015",
             "output/series interval": "0", "output/final particles csv": "false",
             "output/png snapshots": "final", "output/png field": "pore pressure"}.items():
    semi = tv.prm_set(semi, k, v)
rc, out, err = tv.run_tool(os.path.join(tools, "talus-semi-implicit"), semi, work, "semi")
runsemi = os.path.join(work, "runsemi")
n_semi = len(re.findall(r"<DataSet ", open(os.path.join(runsemi, "water.pvd")).read()))
paths = [os.path.join(work, x) for x in announced(out)]
names = sorted(os.path.basename(x) for x in paths)
snaps = [x for x in names if x.startswith("snapshot_")]
tv.check(n_semi == 3 and snaps == [f"snapshot_water_pore_pressure_{n_semi - 1:04d}.png"],
         f"talus-semi-implicit, png snapshots = final, png field = pore pressure: the water set's last output "
         f"drawn, no soil picture (snapshots: {snaps}, {n_semi} outputs)")
want = ["series_energies.png", "series_iterations.png", "series_residuals.png"]
tv.check(all(w in names for w in want), f"talus-semi-implicit series plots {want} drawn (got {names})")
tv.check(sorted(os.path.abspath(x) for x in paths) == files_below(os.path.join(runsemi, "png")),
         "talus-semi-implicit: nothing but the announced PNGs in runsemi/png")
pp = [x for x in paths if "/snapshot_water_pore_pressure_" in x]
size = read_png(pp[0])[:2] if pp else (0, 0)  # auto: a tall scene is less than 800 wide
tv.check(size[0] <= 800 and size[1] <= 820, f"auto size of the tall column: {size[0]} x {size[1]}")
check_pngs(pp, size, "talus-semi-implicit snapshot")
check_pngs([x for x in paths if "/series_" in x], (800, 500), "talus-semi-implicit series plots")
cols = interior_colours(pp[0], out) if pp else set()
# the hydrostatic pore pressure grows with depth: a colour per row of water points (40 rows)
tv.check(len(cols) >= 10, f"the water's pore pressure is drawn as a gradient: {len(cols)} colours of points")
fields = open(os.path.join(runsemi, "fields.txt")).read()
tv.check("integration = mpm" in fields and "material 0 = linear elastic" in fields,
         "talus-semi-implicit wrote fields.txt")

# talus-plot on the semi-implicit run: every output of both sets, one window for both
p = run_plot(["--frames=all", "--field=velocity magnitude", "--size=400,700", "--series=none", "--output=psemi",
              "runsemi"])
names = sorted(os.path.basename(x) for x in announced(p.stdout))
exp = sorted([f"snapshot_{s}_velocity_magnitude_{i:04d}.png" for s in ("soil", "water") for i in range(n_semi)])
tv.check(p.returncode == 0 and names == exp, f"talus-plot on a semi-implicit run: soil and water snapshots of every "
         f"output ({len(names)} of {len(exp)})")
check_pngs([os.path.join(work, "psemi", x) for x in names], (400, 700), "semi-implicit soil and water snapshots")
wl = window_lines(p.stdout)
tv.check(len(wl) == 2 and {w[0] for w in wl} == {"soil", "water"} and wl[0][1] == wl[1][1],
         f"one window for the soil and the water pictures ({wl})")
p = run_plot(["--frames=first", "--field=stress yy", "--series=none", "--output=psemi_s", "runsemi"])
names = [os.path.basename(x) for x in announced(p.stdout)]
sy = [os.path.join(work, "psemi_s", x) for x in names if x.startswith("snapshot_soil_stress_yy")]
tv.check(p.returncode == 0 and len(sy) == 1 and len(interior_colours(sy[0], p.stdout)) >= 10,
         f"the soil's effective stress yy at t = 0 drawn as a gradient ({names})")
p = run_plot(["--output=bad", "--field=free surface", "runsemi"], 2)
tv.check(p.returncode == 2 and "'free surface' is not available" in p.stderr and "water points:" in p.stderr
         and not os.path.exists(os.path.join(work, "bad")),
         f"a field neither set has: exit {p.returncode}, {p.stderr.strip()[:200]}")

# a semi-implicit run without water bodies: its water pieces hold no point (deal.II writes them without
# <Points>); pore pressure is then a warning after the run, the soil is drawn alone
dry = tv.prm_set(semi, "output/directory", "runsoil")
for k, v in {"body 0/initial stress/K0 procedure": "false", "body 0/phase": "soil", "time/end time": "0.0015"}.items():
    dry = tv.prm_set(dry, k, v)
rc, out, err = tv.run_tool(os.path.join(tools, "talus-semi-implicit"), dry, work, "soil_only")
tv.check(rc == 0 and "the pictures were not drawn" in err and "hold no material point" in err
         and os.path.isfile(os.path.join(work, "runsoil", "series.csv")),
         f"pore pressure of a run without water points: exit {rc}, warning: {err.strip()[-200:]}")
p = run_plot(["--frames=all", "--series=none", "--output=psoil", "runsoil"])
names = sorted(os.path.basename(x) for x in announced(p.stdout))
tv.check(p.returncode == 0 and names == [f"snapshot_soil_displacement_magnitude_{i:04d}.png" for i in range(2)]
         and "water: no points in the frames drawn" in p.stdout,
         f"the soil drawn alone, the empty water set noted ({names})")

# ---- 10. talus-implicit: the cantilever under self-weight in two load steps (512 points)
imp = open(os.path.join(idir, "cantilever_self_weight.prm")).read()
for k, v in {"output/directory": "runimp", "time/time step": "0.5", "output/vtu interval": "0.5",
             "output/final particles csv": "false", "output/png snapshots": "final",
             "output/png field": "displacement y"}.items():
    imp = tv.prm_set(imp, k, v)
rc, out, err = tv.run_tool(os.path.join(tools, "talus-implicit"), imp, work, "implicit")
paths = [os.path.join(work, x) for x in announced(out)]
names = sorted(os.path.basename(x) for x in paths)
tv.check([x for x in names if x.startswith("snapshot_")] == ["snapshot_displacement_y_0002.png"],
         f"talus-implicit, png snapshots = final: the last of 3 outputs drawn ({names})")
want = ["series_energies.png", "series_iterations.png", "series_residuals.png"]
tv.check(all(w in names for w in want), f"talus-implicit series plots {want} drawn (got {names})")
dy = [x for x in paths if "/snapshot_displacement_y_" in x]
check_pngs(dy, (800, read_png(dy[0])[1]) if dy else (0, 0), "talus-implicit snapshot")
check_pngs([x for x in paths if "/series_" in x], (800, 500), "talus-implicit series plots")
cols = interior_colours(dy[0], out) if dy else set()
tv.check(len(cols) >= 10, f"the cantilever's deflection is drawn as a gradient: {len(cols)} colours of points")
p = run_plot(["--frames=all", "--field=von mises stress", "--series=iterations,residuals", "--output=pimp", "runimp"])
names = sorted(os.path.basename(x) for x in announced(p.stdout))
tv.check(p.returncode == 0 and names == ["series_iterations.png", "series_residuals.png"] +
         [f"snapshot_von_mises_stress_{i:04d}.png" for i in range(3)],
         f"talus-plot on an implicit run: every output and the Newton plots ({names})")

# ---- 11. png field: a field the family never writes is refused before the run (exit 2, nothing written)
for tool, text, field in (("talus-implicit", imp, "pore pressure"), ("talus-semi-implicit", semi, "free surface"),
                          ("talus-explicit", BLOCK, "displacement z")):
    t = tv.prm_set(text, "output/directory", "refused")
    t = tv.prm_set(t, "output/png snapshots", "final")
    t = tv.prm_set(t, "output/png field", field)
    rc, out, err = tv.run_tool(os.path.join(tools, tool), t, work, "refused", expect_rc=None)
    tv.check(rc == 2 and "png field" in err and field in err and "displacement magnitude" in err
             and not os.path.exists(os.path.join(work, "refused")),
             f"{tool}: png field = {field} refused before the run: exit {rc}, {err.strip()[:220]}")
tv.finish()
