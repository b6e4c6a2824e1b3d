"""parameter_files/examples/Makefile (issue 4): talus-mesh -> talus-explicit ->
talus-fem -> talus-compare with real file dependencies.
  * a clean `make` runs the chain and talus-compare accepts FEM vs MPM (exit 0);
  * a second `make -q` says everything is up to date and `make` runs nothing;
  * touching the FEM .prm reruns exactly the FEM run and the comparison;
  * a tighter tolerance in a copy of the comparison makes `make` fail and leaves
    no report behind (.DELETE_ON_ERROR), so the next `make` retries it.
Usage: check_examples_makefile.py TOOLS_DIR EXAMPLES_DIR WORKDIR
"""
import os
import shutil
import subprocess
import sys

import talus_verify as tv

tools, source, work = [os.path.abspath(x) for x in sys.argv[1:4]]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
# a copy of the example directory (its files get touched below)
examples = os.path.join(work, "examples")
shutil.copytree(source, examples)
root = os.path.dirname(os.path.dirname(source))
out = os.path.join(work, "out")
args = ["make", "-C", examples, f"ROOT={root}", f"TOOLS={tools}", f"OUT={out}"]


def make(*extra):
    p = subprocess.run(args + list(extra), capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


rc, log = make()
print(log[-2500:])
tv.check(rc == 0, f"first make: exit {rc}")
for f in ("grid.msh", "particles.h5", "mpm/results.h5", "fem/results.h5", "compare.csv"):
    tv.check(os.path.isfile(os.path.join(out, f)), f"{f} written")
tv.check("within the tolerance" in log, "talus-compare accepted FEM vs MPM")

rc, _ = make("-q")
tv.check(rc == 0, f"make -q after the chain: exit {rc} (0 = up to date)")
rc, log = make()
ran = [t for t in ("talus-mesh", "talus-explicit", "talus-fem", "talus-compare") if f"/{t} " in log]
tv.check(rc == 0 and not ran, f"second make runs nothing (ran: {ran})")

os.utime(os.path.join(examples, "oedometer_fem.prm"))
rc, log = make("-n")
ran = [t for t in ("talus-mesh", "talus-explicit", "talus-fem", "talus-compare") if f"/{t} " in log]
tv.check(ran == ["talus-fem", "talus-compare"], f"after touching oedometer_fem.prm make would run {ran}")
rc, log = make()
tv.check(rc == 0, "make after the touch")

# a failing comparison leaves no report (the next make retries it)
strict = os.path.join(work, "strict.mk")
with open(strict, "w") as f:
    f.write(f"include {examples}/Makefile\n"
            f"$(O)/strict.csv: $(O)/fem/results.h5 $(O)/mpm/results.h5\n"
            f"\tcd $(O) && $(T)/talus-compare fem/results.h5 mpm/results.h5 --quantities=grid:displacement "
            f"--time=final --tolerance=1e-9 --report=strict.csv\n")
p = subprocess.run(["make", "-f", strict, f"ROOT={root}", f"TOOLS={tools}", f"OUT={out}", f"{out}/strict.csv"],
                   capture_output=True, text=True)
print((p.stdout + p.stderr)[-800:])
tv.check(p.returncode != 0, f"a comparison beyond the tolerance fails make (exit {p.returncode})")
tv.check(not os.path.exists(os.path.join(out, "strict.csv")), "and leaves no report behind")
tv.finish()
