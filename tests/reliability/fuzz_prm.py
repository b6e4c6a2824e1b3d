#!/usr/bin/env python3
"""Fuzz test of the .prm input of every talus tool (issue 7: bad input).

Takes every shipped .prm under parameter_files/, finds the tools that read it
(those whose `--check` accepts the unmodified file), mutates it in many ways
(deleted lines, swapped values, wrong types, huge / negative / zero / NaN / inf
numbers, unknown keys and subsections, unbalanced `end`, garbage lines,
truncation at random byte offsets, empty file, binary junk, targeted
inconsistencies such as an undefined material id, a boundary id the grid does
not have, end time <= 0, zero cells, a body outside the grid or pushed partly
outside it, an output path below a file or where nothing can be created
(/proc), a grid too large for the machine) and runs the tools on each mutation with a timeout. Tools that
read no .prm (the micro-benchmarks) get their command line fuzzed instead.

Every mutation is run with --check (parse + full validation, nothing runs).
Mutations that are broken by construction ("error") must give exit 2 and a
short message naming the entry, line or entity; mutations that may stay valid
("any": swapped values, deleted lines, huge numbers, truncation, ...) may give
exit 0 or a clean exit-2 message. A sample of the inputs confirmed broken is
run again WITHOUT --check in a fresh empty directory: exit 2, and nothing may
be written there (no output directory, no file).

Fails on: a signal or exit code outside {0, 2} under --check (1 = internal
error is a failure too: bad input must be recognised as such), a timeout, a
traceback / "terminate called" / deal.II exception dump / sanitizer report in
place of a clean message, a broken input accepted, a message that names
nothing, any file written.

Standard library only. Usage:
  fuzz_prm.py --tools-dir build/tools --prm-dir parameter_files --workdir DIR
              [--seed N] [--subset fast|full] [--jobs N] [--timeout S]
The seed (default 20261122, or $TALUS_FUZZ_SEED) is printed so that a failure
can be reproduced.
"""
import argparse
import concurrent.futures as cf
import os
import random
import re
import shutil
import subprocess
import sys
import time

DEFAULT_SEED = 20261122

FORBIDDEN = [
    "terminate called", "Traceback", "Stacktrace", "stacktrace", "--------------------------------",
    "An error occurred in line", "Additional information", "Aborting!", "Signal", "Segmentation",
    "AddressSanitizer", "LeakSanitizer", "runtime error:", "core dumped", "std::", "what():",
]

# Open MPI's text when MPI_Init aborts before the tool ran (reported as a start-up failure)
MPI_STARTUP_MARKERS = ("Local abort before MPI_INIT completed", "orte_init failed", "ompi_rte_init failed",
                       "orte_ess_init failed", "An error occurred in MPI_Init", "MPI_INIT failed", "PMIx_Init failed")

# mutation classes every run must contain (fast subset included)
REQUIRED_CLASSES = ("body partly outside the grid", "output cannot be created", "grid too large")

NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")


def is_number(s):
    return bool(NUMBER.match(s.strip()))


def is_number_list(s):
    parts = [x.strip() for x in re.split(r"[,;]", s)]
    return len(parts) > 0 and all(is_number(x) for x in parts if x != "") and any(x != "" for x in parts)


# entries that name input files by paths relative to the repository root (the
# shipped .prm files that use gmsh meshes, issue 4: "run from the repository
# root"); the fuzz runs in a scratch directory, so they are made absolute first
INPUT_FILE_KEYS = ("file", "particle file")


def input_file_entries(text):
    """(line index, key, value) of the entries that name input files (not those
    of a subsection 'output', where talus-mesh names the files it writes)."""
    out, stack = [], []
    for i, line in enumerate(text.splitlines()):
        st = line.split("#", 1)[0].strip()
        m = re.match(r"subsection\s+(.*)$", st)
        if m:
            stack.append(m.group(1).strip())
            continue
        if st == "end":
            if stack:
                stack.pop()
            continue
        m = re.match(r"set\s+(.*?)\s*=\s*(.*)$", st)
        if m and m.group(1) in INPUT_FILE_KEYS and m.group(2) and "output" not in stack:
            out.append((i, m.group(1), m.group(2)))
    return out


def generated_inputs(text):
    """Input files under output/: made by another tool first (talus-mesh ->
    talus-explicit in a makefile chain), and the input files a talus-convergence
    family points its runs at through substitutions (made by the mesh stage of a
    campaign Makefile); such a .prm is skipped."""
    out = [v for _, _, v in input_file_entries(text) if v.startswith("output/")]
    for line in text.splitlines():
        st = line.split("#", 1)[0].strip()
        m = re.match(r"set\s+substitution\s+\d+\s*=\s*(.*)$", st)
        if m:
            sub = re.match(r"(?:.*/)?(file|particle file)\s*=\s*(.+)$", m.group(1))
            if sub:
                out.append(sub.group(2).strip())
    return out


def absolute_input_files(text, path):
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(path))))
    lines = text.splitlines()
    for i, key, value in input_file_entries(text):
        if not os.path.isabs(value) and os.path.exists(os.path.join(root, value)):
            lines[i] = lines[i].replace(value, os.path.join(root, value), 1)
    return "\n".join(lines) + ("\n" if text.endswith("\n") else "")


def expand_includes(text, path, depth=0):
    """The text with every `include FILE` line replaced by that file's text (talus
    resolves FILE relative to the including .prm's directory), so that the
    mutations reach the entries of a shared scene fragment too and the mutated
    file stands alone."""
    out = []
    for line in text.splitlines():
        m = re.match(r"\s*include\s+(\S.*?)\s*$", line, re.I)
        if m and depth < 8:
            name = m.group(1)
            inc = name if os.path.isabs(name) else os.path.join(os.path.dirname(os.path.abspath(path)), name)
            if os.path.isfile(inc):
                out.append(expand_includes(open(inc, encoding="utf-8", errors="replace").read(), inc, depth + 1))
                continue
        out.append(line)
    return "\n".join(out) + ("\n" if text.endswith("\n") else "")


class Prm:
    """A .prm file as lines with their subsection path, key and value (the
    fragments it includes pasted in)."""

    def __init__(self, path):
        self.path = path
        raw = open(path, encoding="utf-8", errors="replace").read()
        self.text = absolute_input_files(expand_includes(raw, path), path)
        self.lines = self.text.splitlines()
        self.entries = []  # (line index, subsection path tuple, key, value)
        self.subsections = []  # (line index of 'subsection', path tuple)
        self.ends = []
        stack = []
        for i, line in enumerate(self.lines):
            s = line.split("#", 1)[0].strip()
            m = re.match(r"subsection\s+(.*)$", s)
            if m:
                stack.append(m.group(1).strip())
                self.subsections.append((i, tuple(stack)))
                continue
            if s == "end":
                self.ends.append(i)
                if stack:
                    stack.pop()
                continue
            m = re.match(r"set\s+(.*?)\s*=\s*(.*)$", s)
            if m:
                self.entries.append((i, tuple(stack), m.group(1), m.group(2).strip()))
        self.vocabulary = {e[2] for e in self.entries} | {p[-1] for _, p in self.subsections}

    def find(self, path):
        """Entry 'sub/sub/key' -> its tuple, or None."""
        parts = path.split("/")
        for e in self.entries:
            if e[1] == tuple(parts[:-1]) and e[2] == parts[-1]:
                return e
        return None

    def with_value(self, entry, value):
        i, _, key, _ = entry
        lines = list(self.lines)
        indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
        lines[i] = f"{indent}set {key} = {value}"
        return "\n".join(lines) + "\n"

    def with_lines(self, lines):
        return "\n".join(lines) + "\n"


class Mutation:
    def __init__(self, category, data, expect, needles=None, base=None, args=None, any_for=()):
        self.category = category
        self.any_for = set(any_for)  # tools that do not use the mutated entry: exit 0 is fine for them
        self.data = data  # str or bytes: content of the mutated file; None: no file (missing path)
        self.expect = expect  # "error" | "any"
        self.needles = needles or []  # one of them must appear in the message (case-insensitive)
        self.base = base  # Prm the mutation came from
        self.args = args  # command line (tools without .prm)


def numeric_entries(prm):
    return [e for e in prm.entries if is_number_list(e[3])]


def mutate(prm, rng, n_random):
    """Mutations of one .prm: the random ones (n_random) plus the fixed ones."""
    muts = []
    lines = prm.lines
    content_lines = [i for i, l in enumerate(lines) if l.strip() and not l.strip().startswith("#")]
    numeric = numeric_entries(prm)
    words = [e for e in prm.entries if not is_number_list(e[3])]

    def M(cat, data, expect, needles=None, any_for=()):
        muts.append(Mutation(cat, data, expect, needles, prm, any_for=any_for))

    # ---- fixed, broken by construction
    M("empty file", "", "error", ["must be set", "not been set", "line", "entry"])
    M("comments only", "# nothing here\n\n   \n", "error", ["must be set", "not been set", "entry"])
    M("binary junk", bytes(rng.randrange(1, 256) for _ in range(300)).replace(b"#", b"\x7f"), "error", ["line"])
    junk = "\x7f" + "".join(chr(rng.randrange(33, 127)) for _ in range(40)).replace("#", "~")
    M("junk line appended", prm.text + junk + "\n", "error", ["line"])
    M("missing file", None, "error", ["does not exist"])
    M("unknown subsection", prm.text + "subsection nonsense section\n  set a = 1\nend\n", "error",
      ["nonsense section"])
    M("extra end", prm.text + "end\n", "error", ["line", "end", "subsection"])
    if prm.ends:
        i = rng.choice(prm.ends)
        M("missing end", prm.with_lines(lines[:i] + lines[i + 1:]), "error", ["subsection", "end", "line"])
    if prm.subsections:
        i, p = rng.choice(prm.subsections)
        M("unbalanced subsection", prm.with_lines(lines[:i] + lines[i + 1:]), "error",
          ["subsection", "end", "line"] + list(prm.vocabulary))

    # ---- targeted inconsistencies (applied when the entry exists in the file)
    targeted = [
        ("time/end time", "0", ["end time"]),
        ("time/end time", "-1", ["end time"]),
        ("time/courant number", "0", ["courant number"]),
        ("time/time step", "1e6", ["time step"]),
        ("grid/cells", None, ["cells"]),  # zero cells, built below
        ("grid/upper corner", None, ["upper corner", "lower corner"]),  # = lower corner
        ("boundary conditions/fixed", "7", ["boundary id 7"]),
        ("boundary conditions/roller", "0, 99", ["boundary id 99"]),
        ("output/directory", "@PRM@/sub", ["output/directory", "directory"]),
        ("output/csv file", "@DIR@", ["csv file"]),
        ("test/number of increments", "0", ["number of increments"]),
        ("test/target strain", "0", ["target strain"]),
        ("test/path", "sideways", ["path", "sideways"]),
        ("dimension", "4", ["dimension"]),
        ("number of materials", "0", ["number of materials"]),
        ("number of materials", "65", ["number of materials"]),
    ]
    # tools that read the scene but do not write its output directory
    no_output = {"output/directory": ["talus-critical-dt"]}
    for path, value, needles in targeted:
        e = prm.find(path)
        if not e:
            continue
        if path == "grid/cells":
            parts = [x.strip() for x in e[3].split(",")]
            parts[rng.randrange(len(parts))] = "0"
            value = ", ".join(parts)
        if path == "grid/upper corner":
            lo = prm.find("grid/lower corner")
            value = lo[3] if lo else "0, 0"
        if path == "time/time step" and (prm.find("time/force time step") or (0, 0, 0, ""))[3] == "true":
            continue
        M("inconsistent: " + path, prm.with_value(e, value), "error", needles, no_output.get(path, ()))
    # material id not defined / body outside the grid / body count mismatch
    nm = prm.find("number of materials")
    for e in prm.entries:
        if len(e[1]) == 1 and e[1][0].startswith("body ") and e[2] == "material" and nm:
            M("undefined material id", prm.with_value(e, str(int(nm[3]) + rng.randrange(0, 3))), "error",
              [e[1][0] + "/material", "not defined"])
            break
    for sub in sorted({e[1] for e in prm.entries if len(e[1]) == 1 and e[1][0].startswith("body ")}):
        shape = prm.find(sub[0] + "/shape")
        text = prm.text
        if shape is None or shape[3] == "box":
            lo, hi = prm.find(sub[0] + "/lower corner"), prm.find(sub[0] + "/upper corner")
            if lo and hi:
                n = len(lo[3].split(","))
                p1 = Prm.__new__(Prm)
                p1.__dict__.update(prm.__dict__)
                text = prm.with_value(lo, ", ".join(["1000"] * n))
                p1.lines = text.splitlines()
                text = p1.with_value(hi, ", ".join(["1001"] * n))
                M("body outside the grid", text, "error", [sub[0], "outside the grid"])
        elif shape[3] == "ball":
            c = prm.find(sub[0] + "/center")
            if c:
                n = len(c[3].split(","))
                M("body outside the grid", prm.with_value(c, ", ".join(["-500"] * n)), "error",
                  [sub[0], "outside the grid"])
        break
    # a body pushed partly outside a box grid: one coordinate beyond the grid's extent (issue 16:
    # refused naming the body, the coordinate and the extent, never clipped silently)
    g_lo, g_hi = prm.find("grid/lower corner"), prm.find("grid/upper corner")
    g_src = prm.find("grid/source")
    if g_lo and g_hi and (g_src is None or g_src[3] == "box") and is_number_list(g_hi[3]):
        glo = [float(x) for x in g_lo[3].split(",")]
        ghi = [float(x) for x in g_hi[3].split(",")]
        for sub in sorted({e[1] for e in prm.entries if len(e[1]) == 1 and e[1][0].startswith("body ")}):
            shape = prm.find(sub[0] + "/shape") or prm.find(sub[0] + "/source")
            kind = "box" if shape is None else shape[3]
            clip = prm.find(sub[0] + "/clip to grid")
            if clip and clip[3] == "true":
                continue
            d = rng.randrange(len(ghi))
            beyond = ghi[d] + 0.37 * (ghi[d] - glo[d])
            if kind == "box" and prm.find(sub[0] + "/upper corner"):
                e = prm.find(sub[0] + "/upper corner")
                parts = [x.strip() for x in e[3].split(",")]
                parts[d] = f"{beyond:.6g}"
                M("body partly outside the grid", prm.with_value(e, ", ".join(parts)), "error",
                  [sub[0], "outside the grid"])
            elif kind == "ball" and prm.find(sub[0] + "/center"):
                e = prm.find(sub[0] + "/center")
                parts = [x.strip() for x in e[3].split(",")]
                parts[d] = f"{ghi[d]:.6g}"  # the centre on the grid's face: half the ball outside
                M("body partly outside the grid", prm.with_value(e, ", ".join(parts)), "error",
                  [sub[0], "outside the grid"])
            elif kind == "polygon" and prm.find(sub[0] + "/vertices"):
                e = prm.find(sub[0] + "/vertices")
                verts = [v.strip() for v in e[3].split(";") if v.strip()]
                xy = [x.strip() for x in verts[0].split(",")]
                xy[d % 2] = f"{beyond:.6g}"
                verts[0] = ", ".join(xy)
                M("body partly outside the grid", prm.with_value(e, "; ".join(verts)), "error",
                  [sub[0], "outside the grid"])
            break
    # output that cannot be created: /proc accepts no new directory, not even from root
    for key in ("directory", "grid file", "particle file", "csv file"):
        e = prm.find("output/" + key)
        if e:
            value = "/proc/talus_fuzz/out" + ("" if key == "directory" else "/x.out")
            M("output cannot be created: output/" + key, prm.with_value(e, value), "error",
              ["output/" + key], no_output.get("output/" + key, ()))
    # a grid far too large for any machine this runs on (refused with the memory estimate)
    e = prm.find("grid/cells")
    if e and (g_src is None or g_src[3] == "box"):
        n = len(e[3].split(","))
        M("grid too large", prm.with_value(e, ", ".join(["100000"] * n)), "error", ["grid/cells"])
    nb = prm.find("number of bodies")
    if nb and int(nb[3]) > 1:
        M("fewer bodies than subsections", prm.with_value(nb, str(int(nb[3]) - 1)), "error",
          ["body " + str(int(nb[3]) - 1), "line"])
    if nb:
        M("more bodies than subsections", prm.with_value(nb, str(int(nb[3]) + 1)), "any")
    dim = prm.find("dimension")
    if dim and any(is_number_list(e[3]) and "," in e[3] for e in prm.entries):
        M("dimension changed", prm.with_value(dim, "3" if dim[3] == "2" else "2"), "error",
          list(prm.vocabulary))

    # ---- random mutations
    cats = ["delete line", "swap values", "wrong type", "huge", "negative", "zero", "non-finite",
            "unknown key", "misspelt key", "truncate", "garbage line", "overflow"]
    for _ in range(n_random):
        cat = rng.choice(cats)
        if cat == "delete line" and content_lines:
            i = rng.choice(content_lines)
            s = lines[i].strip()
            broken = s == "end" or s.startswith("subsection")
            M(cat, prm.with_lines(lines[:i] + lines[i + 1:]), "error" if broken else "any",
              ["subsection", "end", "line"] + list(prm.vocabulary))
        elif cat == "swap values" and len(prm.entries) > 1:
            a, b = rng.sample(prm.entries, 2)
            l2 = list(lines)
            for (i, _, k, _), v in ((a, b[3]), (b, a[3])):
                ind = l2[i][: len(l2[i]) - len(l2[i].lstrip())]
                l2[i] = f"{ind}set {k} = {v}"
            M(cat, prm.with_lines(l2), "any")
        elif cat == "wrong type" and (numeric or words):
            e = rng.choice(numeric + [w for w in words if w[3] in ("true", "false")] or numeric)
            bad = rng.choice(["abc", "1.5.3", "twelve", "1,,2x", "0x1g", "--3", "1e", "true"])
            if e[3] in ("true", "false"):
                bad = rng.choice(["maybe", "1.5", "yes please", "tru"])
            M(cat, prm.with_value(e, bad), "error", [e[2], "line"])
        elif cat in ("huge", "negative", "zero") and numeric:
            e = rng.choice(numeric)
            parts = [x.strip() for x in e[3].split(",")]
            j = rng.randrange(len(parts))
            parts[j] = {"huge": rng.choice(["1e300", "1e30", "99999999999", "4294967296"]),
                        "negative": rng.choice(["-1", "-1e20", "-" + parts[j].lstrip("+-")]),
                        "zero": rng.choice(["0", "0.0", "-0"])}[cat]
            M(cat, prm.with_value(e, ", ".join(parts)), "any", [e[2], "line"])
        elif cat in ("non-finite", "overflow") and numeric:
            e = rng.choice(numeric)
            parts = [x.strip() for x in e[3].split(",")]
            j = rng.randrange(len(parts))
            parts[j] = rng.choice(["nan", "NaN", "inf", "-inf", "Infinity"]) if cat == "non-finite" \
                else rng.choice(["1e999", "-1e999", "1e400"])
            M(cat, prm.with_value(e, ", ".join(parts)), "error", [e[2], "line"])
        elif cat == "unknown key":
            if prm.subsections and rng.random() < 0.7:
                i, p = rng.choice(prm.subsections)
            else:
                i, p = -1, ()
            key = rng.choice(["frobnicate", "end  time", "youngs modulus", "number of bodys", "x"])
            l2 = lines[: i + 1] + [f"  set {key} = 1"] + lines[i + 1:]
            M(cat, prm.with_lines(l2), "error", [key, "line"])
        elif cat == "misspelt key" and prm.entries:
            e = rng.choice(prm.entries)
            k = e[2]
            j = rng.randrange(len(k))
            k2 = k[:j] + k[j + 1:] if len(k) > 1 and rng.random() < 0.5 else k + "s"
            if k2 == k or k2.strip() == "" or k2 in prm.vocabulary:
                k2 = k + "_x"
            l2 = list(lines)
            l2[e[0]] = l2[e[0]].replace("set " + k, "set " + k2, 1)
            M(cat, prm.with_lines(l2), "error", [k2, "line"])
        elif cat == "truncate":
            raw = prm.text.encode()
            off = rng.randrange(0, len(raw))
            M(cat, raw[:off], "any", ["line", "subsection", "end", "must be set"] + list(prm.vocabulary))
        elif cat == "garbage line":
            i = rng.randrange(0, len(lines) + 1)
            g = rng.choice(["set = 3", "set", "subsection", "= 5", "sett end time = 1", "end end", "{]}",
                            "set a b c", "include /nonexistent/file.prm"])
            expect = "error"
            M(cat, prm.with_lines(lines[:i] + [g] + lines[i:]), expect,
              ["line", "subsection", "end", "include", "file"] + list(prm.vocabulary))
    return muts


def bench_mutations(tool, rng):
    """Command-line mutations of a tool that reads no .prm."""
    h = subprocess.run([tool, "--help"], capture_output=True, text=True, timeout=60).stdout
    opts = re.findall(r"^\s+(--[a-z-]+=)VALUE", h, re.M)
    muts = [Mutation("cli: --check", None, "valid", args=["--check"]),
            Mutation("cli: unknown option", None, "error", ["--frobnicate"], args=["--frobnicate"]),
            Mutation("cli: positional", None, "error", ["unexpected argument"], args=["some.prm"])]
    for o in opts:
        for v in ["abc", "-1", "0", "1e3", "99999999999999999999", ""]:
            muts.append(Mutation("cli: bad " + o + v, None, "error", [o.rstrip("=")], args=["--check", o + v]))
        muts.append(Mutation("cli: missing value", None, "error", [o.rstrip("=")], args=[o.rstrip("=")]))
        muts.append(Mutation("cli: valid " + o, None, "valid", args=["--check", o + "3"]))
        muts.append(Mutation("cli: valid spaced " + o, None, "valid", args=["--check", o.rstrip("="), "3"]))
    return muts


def top_level_names(text):
    """Top-level subsection and entry names of a .prm text, indexed subsections
    (body 3, material 0, stage 1) left out."""
    names, depth = set(), 0
    for line in text.splitlines():
        s = line.split("#", 1)[0].strip()
        m = re.match(r"subsection\s+(.*)$", s)
        if m:
            # indexed subsections (body 3, stage 1) are declared only up to the
            # default count, so they do not decide whether a tool can read a file
            if depth == 0 and not re.search(r"\s\d+$", m.group(1).strip()):
                names.add(("subsection", m.group(1).strip()))
            depth += 1
        elif s == "end":
            depth = max(0, depth - 1)
        else:
            m = re.match(r"set\s+(.*?)\s*=", s)
            if m and depth == 0:
                names.add(("set", m.group(1)))
    return names


def tool_listing(tool, env):
    """What `tool --print-parameters` declares (its default .prm)."""
    r = subprocess.run([tool, "--print-parameters"], capture_output=True, text=True, env=env, timeout=60)
    return r.stdout


class Runner:
    def __init__(self, args):
        self.args = args
        self.env = dict(os.environ)
        self.env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                         "OMP_NUM_THREADS": "1", "OMPI_MCA_rmaps_base_oversubscribe": "1"})
        self.counter = 0

    def run(self, tool, mut, check, key):
        """Run tool on mutation in fresh directories; returns (rc, out, err, problems)."""
        base = os.path.join(self.args.workdir, key)
        shutil.rmtree(base, ignore_errors=True)
        indir, rundir = os.path.join(base, "in"), os.path.join(base, "run")
        os.makedirs(indir)
        os.makedirs(rundir)
        if mut.args is not None:
            cmd = [tool] + mut.args
        else:
            # the .prm's siblings (data files it may name) are linked next to the mutation
            if mut.base is not None:
                src = os.path.dirname(os.path.abspath(mut.base.path))
                for f in os.listdir(src):
                    if not f.endswith(".prm"):
                        os.symlink(os.path.join(src, f), os.path.join(indir, f))
                # a .prm that names another .prm by a relative path (talus-convergence:
                # "base parameter file") finds it at the same relative place
                m = re.search(r"^\s*set\s+base parameter file\s*=\s*(\S+)", mut.base.text, re.M)
                if m and not os.path.isabs(m.group(1)):
                    dst = os.path.normpath(os.path.join(indir, m.group(1)))
                    if dst.startswith(base + os.sep) and not os.path.exists(dst):
                        os.makedirs(os.path.dirname(dst), exist_ok=True)
                        os.symlink(os.path.normpath(os.path.join(src, m.group(1))), dst)
            prm = os.path.join(indir, "mutated.prm")
            if mut.data is not None:
                data = mut.data
                if isinstance(data, str):
                    data = data.replace("@PRM@", prm).replace("@DIR@", indir)
                    data = data.encode()
                with open(prm, "wb") as f:
                    f.write(data)
            else:
                prm = os.path.join(indir, "no_such_file.prm")
            cmd = [tool] + (["--check"] if check else []) + [prm]
        before = sorted(os.listdir(indir))
        t0 = time.time()
        try:
            p = subprocess.run(cmd, cwd=rundir, capture_output=True, env=self.env, timeout=self.args.timeout)
            rc, out, err = p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired as e:
            rc, out, err = None, "", f"TIMEOUT after {self.args.timeout} s"
        dt = time.time() - t0
        problems = []
        written = sorted(os.listdir(rundir))
        if written:
            problems.append(f"wrote into the working directory: {written}")
        if sorted(os.listdir(indir)) != before:
            problems.append(f"wrote next to the .prm: {sorted(set(os.listdir(indir)) - set(before))}")
        if not problems:
            shutil.rmtree(base, ignore_errors=True)
        return rc, out, err, problems, dt


def judge(tool_name, mut, rc, out, err, check):
    """List of problems with one result."""
    pr = []
    msg = err.strip()
    if rc is None:
        return [msg]
    if rc not in (0, 2) and any(m in err + out for m in MPI_STARTUP_MARKERS):
        return [f"the tool could not start (MPI start-up failure, exit {rc}; not its answer to the input): "
                f"{msg[-300:]}"]
    if rc < 0:
        return [f"killed by signal {-rc}: {msg[-400:]}"]
    for f in FORBIDDEN:
        if f in err or f in out:
            pr.append(f"output contains '{f}' (a dump instead of a clean message)")
    allowed = {0, 2} if check or mut.args is not None else {0, 1, 2, 3}
    if rc not in allowed:
        pr.append(f"exit {rc} not in {sorted(allowed)}")
    if mut.expect == "valid" and rc != 0:
        pr.append(f"valid input refused (exit {rc})")
    if mut.expect == "error" and rc == 0 and tool_name not in mut.any_for:
        pr.append("broken input accepted (exit 0)")
    if rc == 2:
        first = msg.splitlines()[0] if msg else ""
        if not first.startswith(tool_name + ": error:"):
            pr.append("message does not start with '<tool>: error:'")
        if msg.count("\n") > 8:
            pr.append(f"message has {msg.count(chr(10)) + 1} lines (want a short one)")
        low = msg.lower()
        needles = mut.needles if mut.expect == "error" else (mut.needles or []) + ["line"] + \
            (sorted(mut.base.vocabulary) if mut.base else [])
        if needles and not any(n.lower() in low for n in needles):
            pr.append(f"message names none of {needles[:6]}")
    return pr


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tools-dir", required=True)
    ap.add_argument("--prm-dir", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--seed", type=int, default=int(os.environ.get("TALUS_FUZZ_SEED", DEFAULT_SEED)))
    ap.add_argument("--subset", choices=["fast", "full"], default="full")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--fast-per-prm", type=int, default=8, help="mutations per .prm in the fast subset (at most)")
    ap.add_argument("--fast-budget", type=int, default=450,
                    help="fast subset: about this many category mutations over all .prm files together (each "
                         "file gets budget / files of them, between 4 and --fast-per-prm), so the CI cost stays "
                         "flat as files are added; 0: --fast-per-prm each")
    ap.add_argument("--no-check-runs", type=int, default=None,
                    help="how many confirmed-broken inputs to run again without --check (default 10 fast, 80 full)")
    args = ap.parse_args()
    t_start = time.time()
    rng = random.Random(args.seed)
    print(f"fuzz_prm: seed {args.seed} (override with --seed or TALUS_FUZZ_SEED), subset {args.subset}", flush=True)
    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    runner = Runner(args)
    failures = []

    tools = sorted(os.path.join(args.tools_dir, t) for t in os.listdir(args.tools_dir)
                   if t.startswith("talus-") and os.access(os.path.join(args.tools_dir, t), os.X_OK))
    prm_tools, cli_tools = [], []
    for t in tools:
        h = subprocess.run([t, "--help"], capture_output=True, text=True, env=runner.env, timeout=60)
        (prm_tools if "FILE.prm" in h.stdout else cli_tools).append(t)
    print("tools reading a .prm:", ", ".join(os.path.basename(t) for t in prm_tools))
    print("tools without a .prm (command line fuzzed):", ", ".join(os.path.basename(t) for t in cli_tools))

    # .prm files next to a Makefile belong to a make chain (parameter_files/examples):
    # they read files that the chain makes, relative to its output directory, so
    # they are checked by their own test (verification.examples_makefile)
    # (the run directories a make chain writes below parameter_files, out/ and output/,
    # are not shipped files either)
    prms = sorted(os.path.join(r, f) for r, _, fs in os.walk(args.prm_dir) for f in fs
                  if f.endswith(".prm") and not os.path.exists(os.path.join(r, "Makefile"))
                  and not {"out", "output"} & set(os.path.relpath(r, args.prm_dir).split(os.sep)))
    jobs = []  # (tool, mutation)
    n_mut = 0
    required_runs = {c: 0 for c in REQUIRED_CLASSES}
    per_prm = 40
    # every shipped file through every tool with --check, in parallel (the jobs of
    # this phase are independent; each in its own directory)
    parsed = {path: Prm(path) for path in prms}

    def original(j):
        k, (path, t) = j
        m = Mutation("original", parsed[path].text, "any", base=parsed[path])
        return path, t, runner.run(t, m, True, f"orig{k:04d}_" + os.path.basename(t))

    # fast subset: a tool is tried on an unmodified file only if it declares every
    # top-level subsection and entry of it (deal.II refuses unknown ones, so the
    # others cannot read it); this keeps the phase from growing as tools x files.
    # The full subset tries every pair (and so also checks the refusals).
    top_level = {t: top_level_names(tool_listing(t, runner.env)) for t in prm_tools}
    pairs = [(path, t) for path in prms if not generated_inputs(parsed[path].text) for t in prm_tools
             if args.subset == "full" or top_level_names(parsed[path].text) <= top_level[t]]
    print(f"unmodified files: {len(pairs)} (file, tool) pairs with --check", flush=True)
    with cf.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        originals = {(path, t): r for path, t, r in ex.map(original, enumerate(pairs))}
    fast_per_file = args.fast_per_prm
    if args.fast_budget > 0:
        fast_per_file = max(4, min(args.fast_per_prm, args.fast_budget // max(1, len(prms))))
    if args.subset == "fast":
        print(f"fast subset: {fast_per_file} category mutations per file ({len(prms)} files, budget "
              f"{args.fast_budget})", flush=True)
    for path in prms:
        prm = parsed[path]
        rel = os.path.relpath(path, args.prm_dir)
        missing = generated_inputs(prm.text)
        if missing:
            print(f"  {rel}: skipped, it reads files made by another tool first ({', '.join(missing)})")
            continue
        readers = []
        for t in prm_tools:
            if (path, t) not in originals:
                continue
            rc, out, err, probs, _ = originals[(path, t)]
            if rc == 0:
                readers.append(t)
            if probs:
                failures.append(f"{os.path.basename(t)} --check {rel} (unmodified): {probs}")
        if "broken" in os.path.basename(path):
            if readers:
                failures.append(f"{rel} is meant to be broken but {readers} accept it")
            continue
        if not readers:
            failures.append(f"{rel}: no tool accepts the shipped file with --check")
            continue
        muts = mutate(prm, rng, per_prm)
        if args.subset == "fast":
            # a stratified sample: one mutation of each category in turn (random order)
            by_cat = {}
            for m in muts:
                by_cat.setdefault(m.category, []).append(m)
            order = sorted(by_cat)
            rng.shuffle(order)
            picked = [rng.choice(by_cat[c]) for c in order[:fast_per_file]]
            # the fault classes of issue 16 are always in the fast subset, a few of each
            for cls in REQUIRED_CLASSES:
                have = [m for m in muts if m.category.startswith(cls) and m not in picked]
                if have and required_runs[cls] < 4:
                    picked.append(rng.choice(have))
                    required_runs[cls] += 1
            muts = picked
        n_mut += len(muts)
        for i, m in enumerate(muts):
            # fast subset: each mutation through one of the tools reading it (rotating);
            # full: through every tool that reads it
            for t in ([readers[i % len(readers)]] if args.subset == "fast" else readers):
                jobs.append((t, m, rel))
        print(f"  {rel}: read by {', '.join(os.path.basename(t) for t in readers)}; {len(muts)} mutations", flush=True)
    for t in cli_tools:
        muts = bench_mutations(t, rng)
        if args.subset == "fast":
            muts = muts[:3] + rng.sample(muts[3:], min(3, len(muts) - 3))
        n_mut += len(muts)
        jobs += [(t, m, "command line") for m in muts]

    def work(j):
        idx, (t, m, rel) = j
        rc, out, err, probs, dt = runner.run(t, m, True, f"m{idx:05d}")
        return idx, t, m, rel, rc, out, err, probs + judge(os.path.basename(t), m, rc, out, err, True), dt

    results = []
    with cf.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        for r in ex.map(work, enumerate(jobs)):
            results.append(r)
    cats = {}
    slowest = 0
    for idx, t, m, rel, rc, out, err, probs, dt in results:
        c = cats.setdefault(m.category.split(":")[0] if m.category.startswith("inconsistent") else m.category,
                            [0, 0, 0])
        c[0] += 1
        c[1 if rc == 0 else 2] += 1
        slowest = max(slowest, dt)
        if probs:
            failures.append(f"[{idx}] {os.path.basename(t)} --check, {rel}, {m.category}: {'; '.join(probs)}\n"
                            f"      stderr: {err.strip()[:500]}")

    # confirmed-broken inputs again without --check: exit 2 and nothing written
    broken = [r for r in results if r[4] == 2 and r[2].args is None]
    n_nc = args.no_check_runs if args.no_check_runs is not None else (10 if args.subset == "fast" else 80)
    sample = rng.sample(broken, min(n_nc, len(broken)))

    def work_nc(r):
        idx, t, m, rel = r[:4]
        rc, out, err, probs, dt = runner.run(t, m, False, f"n{idx:05d}")
        pr = probs + judge(os.path.basename(t), m, rc, out, err, False)
        if rc != 2:
            pr.append(f"exit {rc} without --check (2 under --check)")
        return idx, t, m, rel, rc, err, pr

    with cf.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        for idx, t, m, rel, rc, err, pr in ex.map(work_nc, sample):
            if pr:
                failures.append(f"[{idx}] {os.path.basename(t)} (no --check), {rel}, {m.category}: "
                                f"{'; '.join(pr)}\n      stderr: {err.strip()[:500]}")

    print(f"\n{n_mut} mutations, {len(results)} runs with --check, {len(sample)} broken inputs run without "
          f"--check; slowest run {slowest:.2f} s; total {time.time() - t_start:.1f} s")
    print(f"{'category':34s} {'runs':>5s} {'exit 0':>7s} {'exit!=0':>8s}")
    for k in sorted(cats):
        print(f"{k:34s} {cats[k][0]:5d} {cats[k][1]:7d} {cats[k][2]:8d}")
    for cls in REQUIRED_CLASSES:
        n = sum(v[0] for k, v in cats.items() if k.startswith(cls))
        print(f"{cls}: {n} runs")
        if n == 0:
            failures.append(f"no mutation of the class '{cls}' was run")
    if args.subset == "full" and n_mut < 200:
        failures.append(f"only {n_mut} mutations (want >= 200)")
    if failures:
        print(f"\nFAILED: {len(failures)} problem(s) (seed {args.seed}):")
        for f in failures:
            print("  " + f)
        sys.exit(1)
    print(f"\nOK: no crash, no hang, no dump, every broken input refused with a message, nothing written "
          f"(seed {args.seed})")


if __name__ == "__main__":
    main()
