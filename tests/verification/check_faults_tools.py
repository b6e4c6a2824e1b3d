"""The fault classes of issue 16 in every tool (bad input: exit 2, the message names the
entity, nothing written):

  * a body partly outside the grid: talus-fem, talus-critical-dt, talus-mesh (box grid:
    at --check), talus-convergence (through the solver's --check); talus-mesh with
    'clip to grid = true' runs and states the dropped points and the volume lost (exact
    count on the box grid);
  * an output location that cannot be created (/proc): talus-fem, talus-mesh,
    talus-element, talus-compare (--report), talus-critical-dt (--csv),
    talus-convergence; nothing is left behind by the writability probe;
  * a grid too large for the machine: talus-critical-dt, talus-fem, talus-mesh (the
    message gives the estimate and the available memory);
  * a child tool whose MPI cannot start (talus-convergence): exit 4 and "could not
    start", never "refused" (exit 2);
  * the cause of those failures is gone: with Open MPI's shared session directory
    blocked, tools still start (and fail to without the private base: control); 16
    tools started at once all start; nothing is left in TMPDIR.

Usage: check_faults_tools.py TOOLS_DIR PRM_DIR WORKDIR
"""
import os
import re
import shutil
import socket
import subprocess
import sys

import talus_verify as tv

tools, prm_dir, work = (os.path.abspath(x) for x in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)  # "nothing written" is judged on a fresh directory
os.makedirs(work)
T = lambda name: os.path.join(tools, name)  # noqa: E731
bar = tv.prm_set(open(os.path.join(prm_dir, "verification", "bar_vibration.prm")).read(), "output/directory",
                 os.path.join(work, "must_not_exist"))


def run(cmd, name, env=None):
    p = subprocess.run(cmd, cwd=work, capture_output=True, text=True, env=env or tv.child_env())
    return p.returncode, p.stdout, p.stderr.strip()


def refused(tool_args, text, name, needles, check=True):
    """The tool (with --check, and without) refuses the .prm text: exit 2, one short message with all needles."""
    prm = os.path.join(work, name.replace(" ", "_") + ".prm")
    with open(prm, "w") as f:
        f.write(text)
    for c in ([["--check"], []] if check else [[]]):
        rc, out, err = run(tool_args[:1] + c + tool_args[1:] + [prm], name)
        ok = rc == 2 and all(n in err for n in needles) and err.count("\n") < 6
        tv.check(ok, f"{os.path.basename(tool_args[0])} {' '.join(c)}: {name}: exit {rc}, message: {err[:300]}")


outside = tv.prm_set(bar, "body 0/upper corner", "1, 0.05")
proc_out = tv.prm_set(bar, "output/directory", "/proc/talus_x")
huge = tv.prm_set(bar, "grid/cells", "100000, 100000")
for tool in ("talus-fem", "talus-critical-dt"):
    refused([T(tool)], outside, f"{tool} body partly outside", ["body 0", "y = 0.05", "y from 0 to 0.03125"])
    refused([T(tool)], huge, f"{tool} grid too large", ["grid/cells", "need about", "available"])
refused([T("talus-fem")], proc_out, "talus-fem output cannot be created", ["output/directory", "/proc/talus_x"])
refused([T("talus-critical-dt"), "--csv=/proc/talus_x/dt.csv"], bar, "talus-critical-dt csv cannot be created",
        ["option --csv", "/proc/talus_x"])

# talus-mesh: box grid 1 x 1, 10 x 10 cells; body 0 reaches y = 1.5
mesh = f"""set dimension = 2
subsection grid
  set source = box
  set lower corner = 0, 0
  set upper corner = 1, 1
  set cells = 10, 10
end
subsection output
  set grid file = {work}/mesh_out/grid.msh
  set particle file = {work}/mesh_out/particles.h5
end
set number of bodies = 1
subsection body 0
  set source = box
  set lower corner = 0, 0
  set upper corner = 1, 1.5
end
"""
refused([T("talus-mesh")], mesh, "talus-mesh body partly outside", ["body 0", "y = 1.5", "y from 0 to 1"])
inside = tv.prm_set(mesh, "body 0/upper corner", "1, 1")
refused([T("talus-mesh")], tv.prm_set(inside, "output/grid file", "/proc/talus_x/grid.msh"),
        "talus-mesh output cannot be created", ["output/grid file", "/proc/talus_x"])
refused([T("talus-mesh")], tv.prm_set(inside, "grid/cells", "100000, 100000"), "talus-mesh grid too large",
        ["grid/cells", "available"])
tv.check(not os.path.exists(os.path.join(work, "mesh_out")), "talus-mesh wrote nothing for the broken inputs")
# clipping on request: y positions (k + 1/2) 0.05 <= 1.5 for k = 0..29, in the grid k = 0..19:
# 10 rows x 20 columns = 200 positions of 0.05^2 m^2 dropped
clip = tv.prm_set(mesh, "body 0/clip to grid", "true")
with open(os.path.join(work, "clip.prm"), "w") as f:
    f.write(clip)
rc, out, err = run([T("talus-mesh"), os.path.join(work, "clip.prm")], "clip")
m = re.search(r"clip to grid: (\S+) seeding positions outside the grid dropped, volume lost ([0-9.eE+-]+)", out)
tv.check(rc == 0 and m is not None and float(m.group(1)) == 200 and abs(float(m.group(2)) - 0.5) < 1e-12
         and "400 material points" in out,
         f"talus-mesh clip to grid = true: exit {rc}: {m.group(0) if m else (out + err)[-300:]}")

# talus-element: the csv file below /proc
el = open(os.path.join(prm_dir, "element", "mc_drained_triaxial.prm")).read()
refused([T("talus-element")], tv.prm_set(el, "output/csv file", "/proc/talus_x/a.csv"),
        "talus-element output cannot be created", ["output/csv file", "/proc/talus_x"])

# talus-compare: the report below /proc (the input files only need to exist for this check)
some = os.path.join(work, "talus-mesh_body_partly_outside.prm")
rc, out, err = run([T("talus-compare"), "--check", f"--a={some}", f"--b={some}", "--report=/proc/talus_x/r.csv"],
                   "compare")
tv.check(rc == 2 and "report file" in err and "/proc/talus_x" in err,
         f"talus-compare --report below /proc: exit {rc}, message: {err[:300]}")

# talus-convergence: the bar family with a body pushed outside, an output directory below /proc,
# and a solver whose MPI cannot start
conv = open(os.path.join(prm_dir, "convergence", "bar_displacement.prm")).read().replace(
    "../verification/", os.path.join(prm_dir, "verification") + "/")
conv = tv.prm_set(conv, "output/directory", os.path.join(work, "conv_must_not_exist"))
refused([T("talus-convergence")], conv.replace("body 0/upper corner = 1, {1/N}", "body 0/upper corner = 1, {2/N}"),
        "talus-convergence body partly outside", ["refused by talus-explicit --check", "outside the grid"])
refused([T("talus-convergence")], tv.prm_set(conv, "output/directory", "/proc/talus_x"),
        "talus-convergence output cannot be created", ["output/directory", "/proc/talus_x"])
with open(os.path.join(work, "conv.prm"), "w") as f:
    f.write(conv)
# an MCA setting that makes every MPI_Init abort (no such point-to-point layer): the children
# cannot start; that is not the input's fault. A singleton's --check starts no MPI
# (docs/scaling.md, "Start-up"): TALUS_ALWAYS_START_MPI=1 makes it start MPI here and below
mpi_on = {"TALUS_ALWAYS_START_MPI": "1"}
rc, out, err = run([T("talus-convergence"), "--check", os.path.join(work, "conv.prm")], "startup",
                   env=tv.child_env({"OMPI_MCA_pml": "no_such_pml", **mpi_on}))
tv.check(rc == 4 and "could not start" in err and "MPI start-up failure" in err and "refused" not in err,
         f"talus-convergence, solver cannot start MPI: exit {rc} (want 4), message: {err[:400]}")
rc, out, err = run([T("talus-convergence"), "--check", os.path.join(work, "conv.prm")], "startup ok")
tv.check(rc == 0, f"talus-convergence --check of the unmodified family: exit {rc} {err[:200]}")

# the cause of the start-up failures: Open MPI's session directory <TMPDIR>/ompi.<host>.<uid>,
# shared by all jobs. Block it (a file in its place): a tool started without mpirun must not
# need it (it uses a private base); with the private base turned off it cannot start (control)
tmpb = os.path.join(work, "tmpbase")
shutil.rmtree(tmpb, ignore_errors=True)
os.makedirs(tmpb)
blocker = f"ompi.{socket.gethostname().split('.')[0]}.{os.getuid()}"
with open(os.path.join(tmpb, blocker), "w") as f:
    f.write("not a directory\n")
barprm = os.path.join(work, "bar_ok.prm")
with open(barprm, "w") as f:
    f.write(bar)
rc, out, err = run([T("talus-explicit"), "--check", barprm], "blocked", env=tv.child_env({"TMPDIR": tmpb, **mpi_on}))
tv.check(rc == 0, f"talus-explicit starts with the shared session directory blocked: exit {rc} {err[-200:]}")
rc, out, err = run([T("talus-explicit"), "--check", barprm], "blocked, shared",
                   env=tv.child_env({"TMPDIR": tmpb, "TALUS_SHARED_MPI_SESSION": "1", **mpi_on}))
tv.check(tv.startup_failure(rc, out + err),
         f"control: with the shared session directory (TALUS_SHARED_MPI_SESSION=1) it cannot start: exit {rc}")
# 16 tools starting at once, twice: all start, and nothing is left in TMPDIR
for r in range(2):
    procs = [subprocess.Popen([T("talus-explicit"), "--check", barprm], cwd=work, stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True, env=tv.child_env({"TMPDIR": tmpb, **mpi_on}))
             for _ in range(16)]
    codes = [p.wait() for p in procs]
    tv.check(codes == [0] * 16, f"16 concurrent starts (round {r}): exit codes {sorted(set(codes))}")
tv.check(os.listdir(tmpb) == [blocker], f"nothing left in TMPDIR: {os.listdir(tmpb)}")

tv.check(not os.path.exists(os.path.join(work, "must_not_exist")) and
         not os.path.exists(os.path.join(work, "conv_must_not_exist")) and not os.path.exists("/proc/talus_x"),
         "no output directory created for any broken input")
tv.check(not any(n.startswith(".talus-probe") for n in os.listdir(work)), "the writability probes left nothing")
tv.finish()
