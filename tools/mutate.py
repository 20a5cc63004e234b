# SPDX-License-Identifier: GPL-3.0-or-later
"""Mutation testing of the estimator's and the flight code's libraries: `make mutate`.

universalmutator (`mutate`, PyPI) writes every mutant of each selected source file; a
seeded sample of them is compiled, one at a time, into a test binary of only the host
unit tests that include a selected library (build/mutate/), and run with a timeout.
A mutant the tests fail on (or that hangs) is killed; one they pass survives. The
kill score is printed per library, then each survivor (file, line, original, mutant).
The tests of the mutated library's own folder (test/<Library>/) run first: most kills
then cost only those.

Mutants that cannot change behaviour (equivalent ones) are listed in
test/mutants_equivalent.txt, keyed by the file, the mutated line's text and its
replacement (never by line number: the files change; an inserted line's "original" is
"(new line after) " and the line before it), each with its reason; they are
left out of the sample and the score.

Not mutated: lines the host does not compile (#ifdef __AVR__ blocks; the trace's
#if DCM_TRACE blocks, host-only instrumentation for replay, built with DCM_TRACE=0), the calls
of the trace's hook (one line each: `trace().NAME(...);`, `c.trace.NAME(...);`, which return at
once with DCM_TRACE=0), preprocessor lines, comment lines, mutants that only rename an identifier (int32_t -> int(32+1)_t: they do
not compile), mutants that only move blanks or swap the arguments of a commutative
product (mul_q30, mul_s16, mul_u16: the same tokens), and lib/DCM/Trace.h (the trace's
record). A mutant that does not compile is not counted either.
"""
import argparse
import collections
import concurrent.futures
import glob
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The libraries and their files (globs: the files may be split and renamed).
LIBRARIES = collections.OrderedDict([
    # (Trace.h: the replay trace's record, host-only instrumentation, left out.)
    ("lib/DCM", ["lib/DCM/*.cpp", "lib/DCM/[!T]*.h", "lib/DCM/T[!r]*.h"]),
    ("lib/LinAlg/Fixed", ["lib/LinAlg/Fixed.*"]),
    ("lib/Calibration", ["lib/Calibration/*.cpp", "lib/Calibration/*.h"]),
    # Flight.h and Ppm.h hold code (inline maps, the signal timeout, the decoder's limits);
    # FlightSettings.h only declares the settings record, which every test includes
    # through Settings.h (a mutant of it would rebuild them all): left out.
    ("lib/Flight", ["lib/Flight/*.cpp", "lib/Flight/Flight.h", "lib/Flight/Ppm.h"]),
])


def library_named(name):
    """The LIBRARIES key for a name as given: lib/Flight, Flight, Fixed, LinAlg/Fixed."""
    for lib in LIBRARIES:
        if name.rstrip("/") in (lib, lib[len("lib/"):], lib.rsplit("/", 1)[-1]):
            return lib
    sys.exit("mutate: no library %s (one of %s)" % (name, ", ".join(LIBRARIES)))


def own_tests_first(lib, test_srcs):
    """The tests in the library's own folder (test/DCM/ for lib/DCM, test/LinAlg/ for
    lib/LinAlg/Fixed) first, the rest after, each in its order: GoogleTest runs them in
    link order, and the first failure ends the run."""
    folder = "test/" + lib.split("/")[1] + "/"
    return sorted(test_srcs, key=lambda s: not s.startswith(folder))
EQUIVALENT_FILE = "test/mutants_equivalent.txt"
# The trace (lib/DCM/Trace.h) is host-only instrumentation for replay: left out.
LIB_FLAGS = ["-O1", "-DDCM_TRACE=0"]
TEST_FLAGS = ["-O0", "-DDCM_TRACE=0"]


def run(cmd, **kw):
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, **kw)


# The generated MAVLink headers (make mavlink: BUILD/mavlink), for lib/MavLink; None when
# they are not there (lib/MavLink and the tests that need it are then left out).
MAVLINK_DIR = None


def include_flags():
    mavlink = ["-I" + MAVLINK_DIR] if MAVLINK_DIR else []
    return ["-I" + d.rstrip("/") for d in sorted(glob.glob("lib/*/"))] + ["-Itest"] + mavlink


# GoogleTest's header precompiled for the tests (a third of a test file's compile time):
# gcc takes DIR/gtest/gtest.h.gch for <gtest/gtest.h> when -IDIR comes first.
PCH_DIR = None


def compile_cmd(src, obj, is_test):
    pch = ["-I" + PCH_DIR] if is_test and PCH_DIR else []
    return (["g++", "-std=c++14", "-g0", "-MMD", "-w"] + (TEST_FLAGS if is_test else LIB_FLAGS) + pch +
            include_flags() + ["-c", src, "-o", obj])


def build_pch(out):
    global PCH_DIR
    d = os.path.join(out, "pch")
    os.makedirs(os.path.join(d, "gtest"), exist_ok=True)
    r = run(["g++", "-std=c++14", "-g0", "-w"] + TEST_FLAGS + ["-x", "c++-header", "/usr/include/gtest/gtest.h",
                                                                "-o", os.path.join(d, "gtest", "gtest.h.gch")])
    PCH_DIR = d if r.returncode == 0 else None


# The host unit tests as CMakeLists.txt globs them: test/<Library>/ and test/sim/, not the
# folders of the other suites.
OTHER_SUITES = ("e2e", "fuzz", "sketch", "flight", "mavlink", "view", "compass", "support")


def unit_test_sources():
    return sorted(f for f in glob.glob("test/*/*.cpp") if f.split("/")[1] not in OTHER_SUITES)


def obj_name(src):
    return src.replace("/", "__") + ".o"


# ---------------------------------------------------------------------------
# The base build: every lib/*.cpp and the relevant tests, compiled once.

def selected_files():
    files = collections.OrderedDict()
    for lib, patterns in LIBRARIES.items():
        for p in patterns:
            for f in sorted(glob.glob(p)):
                files[f] = lib
    return files


def dependencies(dep_file):
    text = open(dep_file).read().replace("\\\n", " ")
    _, _, deps = text.partition(":")
    return [os.path.normpath(d) for d in deps.split()]


def base_build(out, files, jobs):
    """Compiles every lib source and the test files that include a selected file (and
    nothing of sim/, which the binary does not link) into out/obj; returns
    (lib objects, test objects, {source: its dependencies})."""
    obj_dir = os.path.join(out, "obj")
    os.makedirs(obj_dir, exist_ok=True)
    lib_srcs = sorted(glob.glob("lib/*/*.cpp"))
    if not MAVLINK_DIR:
        lib_srcs = [s for s in lib_srcs if not s.startswith("lib/MavLink/")]
    test_srcs = unit_test_sources()
    jobs_list = [(s, False) for s in lib_srcs] + [(s, True) for s in test_srcs]

    def build(item):
        src, is_test = item
        obj = os.path.join(obj_dir, obj_name(src))
        r = run(compile_cmd(src, obj, is_test))
        return src, r.returncode == 0, r.stdout

    deps = {}
    lib_objs, test_objs = [], []
    with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        for src, ok, log in pool.map(build, jobs_list):
            if not ok:
                if src in lib_srcs:
                    sys.exit("mutate: %s does not compile:\n%s" % (src, log))
                continue  # a test that needs what is not linked here (sim/, mavlink)
            d = dependencies(os.path.join(obj_dir, obj_name(src)[:-2] + ".d"))
            deps[src] = d
            if src in lib_srcs:
                lib_objs.append(src)
            elif any(f in d for f in files) and not any(x.startswith("sim/") for x in d) and \
                    (MAVLINK_DIR or not any(x.startswith("lib/MavLink/") for x in d)):
                test_objs.append(src)
    return lib_objs, test_objs, deps


def link(out_bin, objs):
    r = run(["g++", "-o", out_bin] + objs + ["-lgtest", "-lgtest_main", "-pthread"])
    return r.returncode == 0, r.stdout


# ---------------------------------------------------------------------------
# Mutants: universalmutator's, less what the host never compiles.

# A call of the trace's hook (lib/DCM/Trace.h, TraceHook), one statement on one line:
# instrumentation, which returns at once in the build with -DDCM_TRACE=0.
TRACE_HOOK_CALL = re.compile(r"^(\w+\.)?trace(\(\))?\.\w+\(.*\);$")


def host_lines(path):
    """Line numbers (1-based) the host compiles: outside #ifdef __AVR__ ... #else/#endif
    and the trace's #if DCM_TRACE blocks (left out of the build: -DDCM_TRACE=0), and not
    preprocessor lines nor the trace hook's calls."""
    keep = set()
    stack = []  # for each open #if: True when its current branch is AVR-only
    for n, line in enumerate(open(path), 1):
        s = line.strip()
        if s.startswith("#"):
            word = s[1:].strip().split(" ")[0] if len(s) > 1 else ""
            if word in ("if", "ifdef", "ifndef"):
                stack.append(word == "ifdef" and "__AVR__" in s or (word == "if" and "defined(__AVR__)" in s
                                                                     and "!" not in s) or
                             s.replace(" ", "") == "#ifDCM_TRACE")
            elif word in ("else", "elif") and stack:
                stack[-1] = False
            elif word == "endif" and stack:
                stack.pop()
            continue
        if s.startswith("//") or s.startswith("/*") or s.startswith("*"):
            continue  # a comment: a mutant of it is the same program
        if TRACE_HOOK_CALL.match(s):
            continue  # the trace's hook: instrumentation, not the estimator
        if not any(stack):
            keep.add(n)
    return keep


def changed_line(orig_lines, mutant_lines):
    """(line number, original text, mutant text) of a one-line mutant, or None."""
    if len(mutant_lines) == len(orig_lines):
        diff = [i for i, (a, b) in enumerate(zip(orig_lines, mutant_lines)) if a != b]
        if len(diff) == 1:
            i = diff[0]
            return i + 1, orig_lines[i], mutant_lines[i]
    elif len(mutant_lines) == len(orig_lines) + 1:  # a line inserted (break; continue;)
        for i in range(len(orig_lines) + 1):
            if i == len(orig_lines) or orig_lines[i] != mutant_lines[i]:
                return i + 1, "", mutant_lines[i]
    elif len(mutant_lines) == len(orig_lines) - 1:  # a line deleted
        for i in range(len(orig_lines)):
            if i == len(mutant_lines) or orig_lines[i] != mutant_lines[i]:
                return i + 1, orig_lines[i], ""
    return None


def renames_identifier(orig, mutant):
    """A change inside a name (int32_t -> int(32+1)_t, kPiQ24 -> kPiQ1)."""
    p = 0
    while p < min(len(orig), len(mutant)) and orig[p] == mutant[p]:
        p += 1
    s = 0
    while s < min(len(orig), len(mutant)) - p and orig[-1 - s] == mutant[-1 - s]:
        s += 1
    before = orig[p - 1] if p > 0 else " "
    after = orig[len(orig) - s] if s > 0 else " "
    changed = orig[p:len(orig) - s]
    ident = re.compile(r"[A-Za-z_]")
    word = re.compile(r"[A-Za-z0-9_]")
    inside = word.match(before) and word.match(changed[:1] or " ") or \
        word.match(after) and word.match(changed[-1:] or " ")
    # A digit run inside a name: its first character is not a digit or a name precedes it.
    return bool(inside and (ident.search(orig[max(0, p - 1):len(orig) - s + 1]) or before == "_"))


# C++ tokens, roughly: names and numbers, the operators of two or three characters, then
# any other character.
TOKEN = re.compile(r"[A-Za-z0-9_.]+|<<=|>>=|->|\+\+|--|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%&|^]=|::|\S")


# Products whose two arguments commute (same types): a mutant that only swaps them is the
# same product.
COMMUTATIVE_CALL = re.compile(r"\b(mul_q30|mul_s16|mul_u16)\s*\(\s*([^(),]+?)\s*,\s*([^(),]+?)\s*\)")


def same_tokens(before, after):
    """A change of blanks only (universalmutator's spacing of an unchanged call), or the
    two arguments of a commutative product swapped: the same tokens, no mutant. Lines
    with a quote are kept (blanks count in a literal)."""
    if '"' in before or "'" in before:
        return False

    def canonical(line):
        return TOKEN.findall(COMMUTATIVE_CALL.sub(lambda m: "%s(%s)" % (m.group(1), ",".join(sorted(m.group(2, 3)))),
                                                  line))
    return canonical(before) == canonical(after)


# An inserted line's "original" (report and equivalent-mutant file): the line before it.
NEW_LINE_AFTER = "(new line after) "


# An equivalent mutant's `context:` is looked for among this many lines before it.
CONTEXT_LINES = 3


def is_equivalent(m, equivalent):
    contexts = equivalent.get((m["file"], m["orig"], m["new"]), [])
    return any(c is None or c in m["before"] for c in contexts)


def generate(out, files, mutate_bin):
    """Every mutant of every selected file: a list of dicts."""
    mutants = []
    for path in files:
        base = os.path.basename(path)
        mdir = os.path.join(out, "mutants", path.replace("/", "__"))
        if os.path.isdir(mdir):
            shutil.rmtree(mdir)
        os.makedirs(mdir)
        lang = "cpp"
        r = run([mutate_bin, os.path.abspath(path), lang, "--noCheck",
                 "--mutantDir", mdir])
        if r.returncode != 0:
            sys.exit("mutate: universalmutator failed on %s:\n%s" % (path, r.stdout[-2000:]))
        orig = open(path).read().split("\n")
        keep = host_lines(path)
        stem, ext = os.path.splitext(base)
        for m in sorted(glob.glob(os.path.join(mdir, stem + ".mutant.*" + ext)),
                        key=lambda f: int(f.rsplit(".", 2)[-2])):
            mutant_lines = open(m).read().split("\n")
            c = changed_line(orig, mutant_lines)
            if c is None:
                continue
            line, before, after = c
            if line not in keep and (before or line - 1 not in keep):
                continue
            if before and after and renames_identifier(before, after):
                continue
            if same_tokens(before, after):
                continue
            # An inserted line (continue; break;) is keyed by the line it follows: the same
            # insertion elsewhere in the file is another mutant.
            inserted = len(mutant_lines) == len(orig) + 1
            key = NEW_LINE_AFTER + orig[line - 2].strip() if inserted and line >= 2 else before.strip()
            before_lines = [t.strip() for t in orig[max(0, line - 1 - CONTEXT_LINES):line - 1]]
            mutants.append({"file": path, "mutant": m, "line": line, "orig": key, "new": after.strip(),
                            "before": before_lines})
    return mutants


def load_equivalent():
    """{(file, original, mutant): [context or None, ...]} from test/mutants_equivalent.txt:
    blocks of `file:`, `original:`, `mutant:`, `reason:` lines (and an optional
    `context:`, a line among the CONTEXT_LINES before the mutated one, for a line whose
    text recurs in the file where only one of its mutants is equivalent), a blank line
    between blocks."""
    out = {}
    if not os.path.exists(EQUIVALENT_FILE):
        return out
    block = {}
    for line in open(EQUIVALENT_FILE).read().split("\n") + [""]:
        if line.startswith("#"):
            continue
        if not line.strip():
            if block:
                key = (block.get("file", ""), block.get("original", ""), block.get("mutant", ""))
                out.setdefault(key, []).append(block.get("context"))
                if not block.get("reason"):
                    sys.exit("mutate: %s: no reason for %s" % (EQUIVALENT_FILE, key))
            block = {}
            continue
        k, _, v = line.partition(":")
        block[k.strip()] = v.strip()
    return out


# ---------------------------------------------------------------------------
# One mutant: the mutated file in the worker's copy, its dependents recompiled, the
# binary linked and run.

def test_mutant(m, lib, worker, base, lib_objs, test_objs, deps, obj_dir, timeout_s):
    src_path = os.path.join(worker, m["file"])
    shutil.copyfile(m["mutant"], src_path)
    try:
        wobj = os.path.abspath(os.path.join(worker, "obj"))
        os.makedirs(wobj, exist_ok=True)
        dependents = [s for s in lib_objs + test_objs if m["file"] in deps[s]]
        # The mutated file's own translation unit first: most invalid mutants fail there.
        dependents.sort(key=lambda s: (s != m["file"], s.startswith("test/")))
        changed = {}
        for s in dependents:
            o = os.path.join(wobj, obj_name(s))
            cmd = compile_cmd(s, o, s.startswith("test/"))
            r = run(cmd, cwd=worker)
            if r.returncode != 0:
                return "invalid", ""
            changed[s] = o
        objs = [changed.get(s, os.path.abspath(os.path.join(obj_dir, obj_name(s))))
                for s in lib_objs + own_tests_first(lib, test_objs)]
        binary = os.path.abspath(os.path.join(worker, "tests"))
        ok, log = link(binary, objs)
        if not ok:
            return "invalid", ""
        try:
            # The first failure ends the run (a trap): a killed mutant costs less.
            r = subprocess.run([binary, "--gtest_break_on_failure"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               universal_newlines=True, timeout=timeout_s, cwd=ROOT)
        except subprocess.TimeoutExpired:
            return "killed", "timeout"
        if r.returncode == 0:
            return "survived", ""
        failed = re.findall(r"^\[ RUN      \] ([\w./]+)", r.stdout, re.M)
        return "killed", failed[-1] if failed else "exit %d" % r.returncode
    finally:
        shutil.copyfile(os.path.join(base, m["file"]), src_path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--mutants", default="400", help="how many viable mutants in all (split evenly over the "
                    "libraries), or 'all'")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--library", action="append", help="only this library (lib/DCM, lib/LinAlg/Fixed, lib/Flight, "
                    "...; or its last name: DCM, Fixed, Flight); repeat for more")
    ap.add_argument("--survivors-of", metavar="REPORT", help="run only the survivors a previous report lists "
                    "(build/mutate/report.txt: after writing tests for them)")
    args = ap.parse_args()
    os.chdir(ROOT)
    global MAVLINK_DIR
    generated = os.path.abspath(os.path.join(args.build, "mavlink"))
    MAVLINK_DIR = generated if os.path.exists(os.path.join(generated, "common", "mavlink.h")) else None
    start = time.time()
    out = os.path.join(args.build, "mutate")
    os.makedirs(out, exist_ok=True)
    # A snapshot of the sources: the run never reads the working tree again (it may be
    # edited meanwhile).
    base = os.path.abspath(os.path.join(out, "base"))
    if os.path.isdir(base):
        shutil.rmtree(base)
    for d in ("lib", "test"):
        shutil.copytree(d, os.path.join(base, d))
    os.chdir(base)
    files = selected_files()
    if args.library:
        chosen = [library_named(n) for n in args.library]
        files = collections.OrderedDict((f, l) for f, l in files.items() if l in chosen)

    out = os.path.join(ROOT, out)
    if os.path.exists("/usr/include/gtest/gtest.h"):
        build_pch(out)
    lib_objs, test_objs, deps = base_build(out, files, args.jobs)
    obj_dir = os.path.join(out, "obj")
    base_bin = os.path.join(out, "tests")
    # Only the library objects the tests use (an archive, the linker's --trace): a mutant
    # of a header recompiles no object the binary does not link.
    archive = os.path.join(out, "libs.a")
    if os.path.exists(archive):
        os.remove(archive)
    run(["ar", "rcs", archive] + [os.path.join(obj_dir, obj_name(s)) for s in lib_objs])
    link_map = os.path.join(out, "tests.map")
    r = run(["g++", "-o", base_bin] + [os.path.join(obj_dir, obj_name(s)) for s in test_objs] +
            [archive, "-lgtest", "-lgtest_main", "-pthread", "-Wl,-Map=" + link_map])
    if r.returncode != 0:
        sys.exit("mutate: the test binary does not link:\n" + r.stdout[-3000:])
    used = set(re.findall(r"libs\.a\(([^()]+\.o)\)", open(link_map).read()))
    lib_objs = [s for s in lib_objs if obj_name(s) in used]
    ok, log = link(base_bin, [os.path.join(obj_dir, obj_name(s)) for s in lib_objs + test_objs])
    if not ok:  # the objects alone, as each mutant links them
        sys.exit("mutate: the test binary does not link from the objects it uses:\n" + log[-3000:])
    t0 = time.time()
    r = run([base_bin, "--gtest_brief=1"], cwd=ROOT)
    base_s = time.time() - t0
    if r.returncode != 0:
        sys.exit("mutate: the tests fail without a mutant:\n" + r.stdout[-3000:])
    timeout_s = max(20.0, 10.0 * base_s)
    print("# mutate: test binary of %s (%.1f s a run, timeout %.0f s)" % (
        " ".join(os.path.basename(t) for t in test_objs), base_s, timeout_s))

    mutate_bin = os.path.join(ROOT, args.build, "venv", "bin", "mutate")
    if not os.path.exists(mutate_bin):
        mutate_bin = shutil.which("mutate") or os.path.join(ROOT, "build", "venv", "bin", "mutate")
    mutants = generate(out, files, mutate_bin)
    equivalent = load_equivalent()
    # Shuffled before the equivalent ones are taken out: listing one leaves the rest of
    # the sample as it was (the next mutant in the order takes its place). Each library's
    # mutants apart, with the same seed: a library's sample is the same whichever others
    # run beside it (--library DCM draws what the whole run draws for lib/DCM).
    by_lib = collections.OrderedDict()
    for m in mutants:
        by_lib.setdefault(files[m["file"]], []).append(m)
    mutants = []
    for lib_mutants in by_lib.values():
        random.Random(args.seed).shuffle(lib_mutants)
        mutants += lib_mutants
    pool = collections.OrderedDict((lib, []) for lib in LIBRARIES if lib in files.values())
    n_equivalent = collections.Counter()
    if args.survivors_of:
        listed = set(re.findall(r"^(\S+):\d+: (.*)\n    -> (.*)$", open(os.path.join(ROOT, args.survivors_of)).read(), re.M))
        listed = {(f, "" if o == "(new line)" else o, "" if n == "(line deleted)" else n) for f, o, n in listed}
        mutants = [m for m in mutants if (m["file"], m["orig"], m["new"]) in listed]
        args.mutants = "all"
    for m in mutants:
        lib = files[m["file"]]
        if is_equivalent(m, equivalent):
            n_equivalent[lib] += 1
            continue
        pool[lib].append(m)
    quota = None if args.mutants == "all" else int(args.mutants)
    per_lib = {lib: (None if quota is None else quota // len(pool) + (1 if i < quota % len(pool) else 0))
               for i, lib in enumerate(pool)}
    print("# mutate: %s mutants (universalmutator), %s; seed %d, %s" % (
        len(mutants), ", ".join("%s %d (%d equivalent)" % (l, len(pool[l]), n_equivalent[l]) for l in pool),
        args.seed, "every mutant" if quota is None else "%d viable a library" % (quota // len(pool))))
    sys.stdout.flush()

    # Workers: each its own copy of lib/ and test/.
    workers = []
    for w in range(args.jobs):
        wdir = os.path.join(out, "w%d" % w)
        if os.path.isdir(wdir):
            shutil.rmtree(wdir)
        os.makedirs(wdir)
        for d in ("lib", "test"):
            shutil.copytree(os.path.join(base, d), os.path.join(wdir, d))
        workers.append(wdir)

    results = collections.defaultdict(collections.Counter)
    survivors = []
    free = list(workers)
    # Draw mutants per library until its quota of viable ones is met (invalid ones are
    # drawn again from the rest).
    queues = {lib: collections.deque(pool[lib]) for lib in pool}
    viable_started = collections.Counter()
    in_flight = {}
    done_count = 0
    invalid_in_a_row = 0

    def next_mutant():
        for lib in queues:
            q = queues[lib]
            if q and (per_lib[lib] is None or viable_started[lib] < per_lib[lib]):
                viable_started[lib] += 1
                return lib, q.popleft()
        return None

    with concurrent.futures.ThreadPoolExecutor(args.jobs) as ex:
        while True:
            while free:
                nm = next_mutant()
                if nm is None:
                    break
                lib, m = nm
                w = free.pop()
                fut = ex.submit(test_mutant, m, lib, w, base, lib_objs, test_objs, deps, obj_dir, timeout_s)
                in_flight[fut] = (lib, m, w)
            if not in_flight:
                break
            done, _ = concurrent.futures.wait(in_flight, return_when=concurrent.futures.FIRST_COMPLETED)
            for fut in done:
                lib, m, w = in_flight.pop(fut)
                free.append(w)
                status, how = fut.result()
                results[lib][status] += 1
                if status == "invalid":
                    viable_started[lib] -= 1
                    invalid_in_a_row += 1
                    if invalid_in_a_row >= 100:
                        sys.exit("mutate: 100 mutants in a row did not compile or link: the build is broken")
                else:
                    invalid_in_a_row = 0
                if status == "survived":
                    survivors.append((lib, m))
                    print("#   survived: %s:%d: %s -> %s" % (m["file"], m["line"], m["orig"], m["new"]))
                elif status == "killed" and args.survivors_of:
                    # After tests were written for them: which test fails on each.
                    print("#   killed by %s: %s:%d: %s -> %s" % (how, m["file"], m["line"], m["orig"], m["new"]))
                done_count += 1
                if done_count % 25 == 0:
                    print("#   %d mutants run (%.0f s)" % (done_count, time.time() - start))
                    sys.stdout.flush()

    elapsed = time.time() - start
    report = []
    report.append("# mutate: kill score per library (equivalent mutants listed in %s left out)" % EQUIVALENT_FILE)
    for lib in pool:
        c = results[lib]
        viable = c["killed"] + c["survived"]
        score = 100.0 * c["killed"] / viable if viable else 0.0
        report.append("%-20s %5.1f %%  killed %d of %d (not compiling: %d, equivalent left out: %d)" % (
            lib, score, c["killed"], viable, c["invalid"], n_equivalent[lib]))
    report.append("# survivors (file:line: original -> mutant); list an equivalent one in %s" % EQUIVALENT_FILE)
    for lib, m in sorted(survivors, key=lambda x: (x[1]["file"], x[1]["line"])):
        report.append("%s:%d: %s\n    -> %s" % (m["file"], m["line"], m["orig"] or "(new line)",
                                                m["new"] or "(line deleted)"))
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = usage.ru_utime + usage.ru_stime
    report.append("# mutate: %.0f s on %d jobs (CPU %.0f s: %.0f s on %d idle cores), %d mutants run, seed %d" % (
        elapsed, args.jobs, cpu_s, cpu_s / args.jobs, args.jobs, done_count, args.seed))
    text = "\n".join(report)
    print(text)
    with open(os.path.join(out, "report.txt"), "w") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()
