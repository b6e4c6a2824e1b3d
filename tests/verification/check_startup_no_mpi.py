"""--help, --print-parameters and --check of a tool started directly (a singleton) start no
MPI (issue 41; docs/scaling.md, "Start-up"), and still do all their work.

The probe: OMPI_MCA_pml names a messaging layer that does not exist, so any MPI_Init of
the process aborts (exit 1, Open MPI's "component was not found"). Control: the same
--check with TALUS_ALWAYS_START_MPI=1 (MPI started as before) must fail that way, so the
probe can see an MPI start. Then, under the probe:
  * --help and --print-parameters of talus-explicit, talus-implicit, talus-semi-implicit:
    exit 0 and their text;
  * --check of the demo scene: exit 0, "is valid"; of the demo with a bad entry: exit 2
    naming the entry (validation still runs);
  * --check of a scene whose body is read from a talus-mesh particle file (the HDF5 file
    is opened serially without MPI): exit 0; with a file body id the file does not have:
    exit 2 naming 'body 0/file body id' (the file was read);
  * talus-mesh --check of a shipped mesh .prm (its group checks run on "rank 0"): exit 0;
  * a run (not --check) still starts MPI: it fails under the probe.

Usage: check_startup_no_mpi.py TOOLS_DIR REPO_DIR WORKDIR
"""
import os
import shutil
import subprocess
import sys

import talus_verify as tv

tools, repo, work = [os.path.abspath(x) for x in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
T = lambda name: os.path.join(tools, name)  # noqa: E731
probe = {"OMPI_MCA_pml": "talus_no_such_pml"}


def run(cmd, extra=None):
    p = subprocess.run(cmd, cwd=work, capture_output=True, text=True, env=tv.child_env(extra), timeout=600)
    return p.returncode, p.stdout + p.stderr


demo_text = open(os.path.join(repo, "parameter_files", "demo", "column_collapse_2d.prm")).read()
demo_text = tv.prm_set(demo_text, "output/directory", os.path.join(work, "demo_out"))
demo = os.path.join(work, "demo.prm")
with open(demo, "w") as f:
    f.write(demo_text)

# control: the probe makes an MPI start fail
rc, out = run([T("talus-explicit"), "--check", demo], {**probe, "TALUS_ALWAYS_START_MPI": "1"})
tv.check(rc not in (0, 2) and tv.startup_failure(rc, out),
         f"control: --check with MPI started fails under the probe (exit {rc})")

for tool in ("talus-explicit", "talus-implicit", "talus-semi-implicit"):
    rc, out = run([T(tool), "--help"], probe)
    tv.check(rc == 0 and "Usage: " + tool in out, f"{tool} --help without MPI: exit {rc}")
    rc, out = run([T(tool), "--print-parameters"], probe)
    tv.check(rc == 0 and "subsection output" in out and "set dimension" in out,
             f"{tool} --print-parameters without MPI: exit {rc}")

rc, out = run([T("talus-explicit"), "--check", demo], probe)
tv.check(rc == 0 and "is valid" in out, f"--check of the demo without MPI: exit {rc} {out[-300:]}")
bad = os.path.join(work, "demo_bad.prm")
with open(bad, "w") as f:
    f.write(tv.prm_set(demo_text, "grid/cells", "160, 0"))
rc, out = run([T("talus-explicit"), "--check", bad], probe)
tv.check(rc == 2 and "grid/cells" in out, f"--check of a bad demo without MPI: exit {rc}, names grid/cells")

# talus-mesh --check (gmsh grid, its groups checked on "rank 0")
p = subprocess.run([T("talus-mesh"), "--check", os.path.join("parameter_files", "mesh", "cantilever_2d.prm")],
                   cwd=repo, capture_output=True, text=True, env=tv.child_env(probe), timeout=600)
tv.check(p.returncode == 0 and "is valid" in p.stdout + p.stderr,
         f"talus-mesh --check of parameter_files/mesh/cantilever_2d.prm without MPI: exit {p.returncode}")

# a body read from a particle file (made by talus-mesh, a normal run with MPI)
mesh_prm = open(os.path.join(repo, "parameter_files", "mesh", "semi_column_2d.prm")).read()
mesh_prm = mesh_prm.replace("meshes/", os.path.join(repo, "meshes") + "/")
tv.run_tool(T("talus-mesh"), mesh_prm.replace("output/mesh/semi_column_2d", "files"), work, "mesh")
scene = open(os.path.join(repo, "parameter_files", "verification", "semi_implicit_hydrostatic.prm")).read()
old = "set shape                   = box"
tv.check(old in scene, "the hydrostatic scene has a box body to replace")
scene = scene.replace(old, f"set shape = file\n  set particle file = {work}/files/particles.h5")
scene = tv.prm_set(scene, "output/directory", os.path.join(work, "file_out"))
for name, text, want in (("file_body", scene, 0),
                         ("file_body_bad_id", tv.prm_set(scene, "body 0/file body id", "3"), 2)):
    path = os.path.join(work, name + ".prm")
    with open(path, "w") as f:
        f.write(text)
    rc, out = run([T("talus-semi-implicit"), "--check", path], probe)
    ok = rc == want and (want == 0 and "is valid" in out or want == 2 and "body 0/file body id" in out)
    tv.check(ok, f"--check of a file-body scene ({name}) without MPI: exit {rc} (want {want}) {out[-300:]}")

# a run starts MPI
rc, out = run([T("talus-explicit"), demo], probe)
tv.check(rc not in (0, 2) and tv.startup_failure(rc, out), f"a run under the probe starts MPI and fails (exit {rc})")
tv.check(not os.path.exists(os.path.join(work, "demo_out")) and not os.path.exists(os.path.join(work, "file_out")),
         "nothing written by the --check runs")
tv.finish()
