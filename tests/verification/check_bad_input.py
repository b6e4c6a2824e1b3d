"""Bad input to talus-explicit gives one clear message and exit code 2, and no output.

Usage: check_bad_input.py TOOL PRM WORKDIR
"""
import os
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = tv.prm_set(open(prm_path).read(), "output/directory", "must_not_exist")
lines = base.splitlines()

cases = {
    "unknown entry": (base.replace("set end time", "set end tiem", 1), ["end tiem", "Line"]),
    "wrong type": (tv.prm_set(base, "time/courant number", "fast"), ["courant number", "fast", "Line"]),
    "out of range": (tv.prm_set(base, "time/courant number", "3"), ["courant number", "0...1"]),
    "unknown model": (tv.prm_set(base, "material 0/model", "granite"), ["granite", "linear elastic"]),
    "bad poisson": (tv.prm_set(base, "material 0/linear elastic/poisson ratio", "0.5"), ["poisson ratio", "0.5"]),
    "undefined material": (tv.prm_set(base, "body 0/material", "3"), ["body 0/material", "not defined"]),
    "wrong vector length": (tv.prm_set(base, "gravity/acceleration", "0, 0, -9.81"), ["gravity/acceleration", "2"]),
    "body outside grid": (tv.prm_set(tv.prm_set(base, "body 0/lower corner", "5, 5"), "body 0/upper corner", "6, 6"),
                          ["body 0", "no material point"]),
    "unknown boundary id": (tv.prm_set(base, "boundary conditions/roller", "2, 3, 9"), ["boundary id 9"]),
    "unknown subsection": (base + "subsection nonsense\n  set a = 1\nend\n", ["nonsense"]),
}
for name, (text, needles) in cases.items():
    rc, out, err = tv.run_tool(tool, text, work, name.replace(" ", "_"), expect_rc=None)
    msg = err.strip()
    ok = rc == 2 and all(n in msg for n in needles) and msg.count("\n") < 6
    tv.check(ok, f"{name}: exit {rc}, message: {msg[:300]}")

rc2 = os.system(f"{os.path.abspath(tool)} /nonexistent/file.prm > /dev/null 2>&1") >> 8
tv.check(rc2 == 2, f"missing parameter file: exit {rc2}")
rc3 = os.system(f"{os.path.abspath(tool)} --bogus > /dev/null 2>&1") >> 8
tv.check(rc3 == 2, f"unknown option: exit {rc3}")
tv.check(not os.path.exists(os.path.join(work, "must_not_exist")), "no output written for any broken input")
tv.finish()
