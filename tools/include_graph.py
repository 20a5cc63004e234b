#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The include graph between the libraries in lib/, and the layering rules it must keep.

    tools/include_graph.py              print the graph and check it (exit 1 on a breach)
    tools/include_graph.py --dot        the graph in Graphviz's dot language
    tools/include_graph.py --self-test  check that the check catches a planted breach

Every lib/ folder is on one flat include path (the Makefile, CMake, arduino-builder and
PlatformIO all build so), so `#include "X.h"` names the folder that holds X.h. A folder A
depends on B when a file of A includes a header of B. The rules:
  - no cycle between folders (A needs B and B needs A: neither can be built, tested or
    reused alone);
  - no header name in two folders (which one an include finds would depend on the order
    of the include path);
  - only the sketch (firmware/) and the AVR test images (test/e2e/support/avr/) include
    the Arduino core (Arduino.h): the libraries, the simulator, the tools and the host
    tests build without it.
Headers of no lib/ folder (the C library, the generated MAVLink headers) are not edges.
"""
import argparse
import os
import re
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')
SOURCE_SUFFIXES = (".h", ".hpp", ".c", ".cpp", ".ino")
# Where the Arduino core may be included (paths relative to the root, with a trailing /).
ARDUINO_ALLOWED = ("firmware/", "test/e2e/support/avr/")
ARDUINO_HEADERS = ("Arduino.h", "WProgram.h")
# Folders searched for Arduino includes besides lib/.
SCANNED = ("lib", "firmware", "sim", "tools", "bench", "test")


def source_files(top):
    for dirpath, dirnames, filenames in os.walk(top):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        for name in sorted(filenames):
            if name.endswith(SOURCE_SUFFIXES):
                yield os.path.join(dirpath, name)


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if m:
                yield number, m.group(1)


def analyse(root):
    """(libs, edges, problems): edges[a][b] = the first 'file:line' where a includes b."""
    lib_dir = os.path.join(root, "lib")
    libs = sorted(d for d in os.listdir(lib_dir) if os.path.isdir(os.path.join(lib_dir, d)))
    problems = []
    owner = {}
    for lib in libs:
        for path in source_files(os.path.join(lib_dir, lib)):
            name = os.path.basename(path)
            if name.endswith((".h", ".hpp")):
                if name in owner and owner[name] != lib:
                    problems.append("header %s is in both lib/%s and lib/%s" % (name, owner[name], lib))
                owner.setdefault(name, lib)
    edges = {lib: {} for lib in libs}
    for lib in libs:
        for path in source_files(os.path.join(lib_dir, lib)):
            for number, target in includes(path):
                dep = owner.get(target) if "/" not in target else None
                if dep is not None and dep != lib:
                    edges[lib].setdefault(dep, "%s:%d" % (os.path.relpath(path, root), number))
    for top in SCANNED:
        for path in source_files(os.path.join(root, top)):
            rel = os.path.relpath(path, root).replace(os.sep, "/")
            if rel.startswith(ARDUINO_ALLOWED):
                continue
            for number, target in includes(path):
                if os.path.basename(target) in ARDUINO_HEADERS:
                    problems.append("%s:%d includes %s (only %s may)" % (rel, number, target, " and ".join(ARDUINO_ALLOWED)))
    return libs, edges, problems


def cycles(libs, edges):
    """The strongly connected components with more than one folder (Tarjan), each as a
    closed path through it."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(closed_path(sorted(component), edges))

    for v in libs:
        if v not in index:
            visit(v)
    return found


def closed_path(component, edges):
    """A path from the component's first folder back to it, inside the component
    (breadth first: the shortest)."""
    start, members = component[0], set(component)
    previous, frontier = {start: None}, [start]
    while frontier:
        following = []
        for v in frontier:
            for w in sorted(edges[v]):
                if w == start:
                    path = [v]
                    while previous[path[-1]] is not None:
                        path.append(previous[path[-1]])
                    return list(reversed(path)) + [start]
                if w in members and w not in previous:
                    previous[w] = v
                    following.append(w)
        frontier = following
    return component + [start]


def levels(libs, edges):
    """Each folder's layer: 0 for one that includes no other, else one above its highest
    dependency (only meaningful without cycles)."""
    level = {}

    def of(v, seen=()):
        if v not in level:
            level[v] = 1 + max((of(w, seen + (v,)) for w in edges[v] if w not in seen), default=-1)
        return level[v]

    for v in libs:
        of(v)
    return level


def report(root, dot=False, out=sys.stdout):
    libs, edges, problems = analyse(root)
    found = cycles(libs, edges)
    if dot:
        out.write("digraph lib {\n    rankdir=BT;\n")
        for a in libs:
            out.write('    "%s";\n' % a)
            for b in sorted(edges[a]):
                out.write('    "%s" -> "%s";\n' % (a, b))
        out.write("}\n")
    else:
        width = max(len(lib) for lib in libs)
        out.write("# include graph between lib/ folders (A -> what A includes)\n")
        for a in libs:
            out.write("%-*s -> %s\n" % (width, a, ", ".join(sorted(edges[a])) or "-"))
        if not found:
            level = levels(libs, edges)
            out.write("# layers, lowest first\n")
            for n in range(max(level.values()) + 1):
                out.write("%d: %s\n" % (n, ", ".join(v for v in libs if level[v] == n)))
    for path in found:
        out.write("CYCLE: %s\n" % " -> ".join(path))
        for a, b in zip(path, path[1:]):
            out.write("  %s -> %s at %s\n" % (a, b, edges[a][b]))
    for p in problems:
        out.write("ERROR: %s\n" % p)
    ok = not found and not problems
    out.write("# %s: %d folders, %d edges, %d cycles, %d other problems\n" % (
        "ok" if ok else "FAILED", len(libs), sum(len(e) for e in edges.values()), len(found), len(problems)))
    return ok


def self_test():
    """A small tree: clean it passes; each planted breach fails it, named."""
    import io

    def tree(files):
        root = tempfile.mkdtemp(prefix="include_graph.")
        for rel, text in files.items():
            path = os.path.join(root, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                f.write(text)
        return root

    base = {
        "lib/Low/Low.h": "#pragma once\n#include <stdint.h>\n",
        "lib/Mid/Mid.h": '#pragma once\n#include "Low.h"\n',
        "lib/Mid/Mid.cpp": '#include "Mid.h"\n',
        "lib/Top/Top.cpp": '#include "Mid.h"\n#include "common/mavlink.h"\n',
        "firmware/firmware.ino": '#include <Arduino.h>\n#include "Top.h"\n',
    }
    cases = [
        ("clean", {}, True, None),
        ("planted cycle", {"lib/Low/Low.cpp": '#include "Low.h"\n#include "Top.h"\n', "lib/Top/Top.h": "#pragma once\n"},
         False, "CYCLE: Low -> Top -> Mid -> Low"),
        ("two-folder cycle", {"lib/Low/Low.cpp": '#include "Mid.h"\n'}, False, "CYCLE: Low -> Mid -> Low"),
        ("Arduino.h in lib/", {"lib/Low/Low.cpp": "#include <Arduino.h>\n"}, False, "lib/Low/Low.cpp:1 includes Arduino.h"),
        ("Arduino.h in sim/", {"sim/x.cpp": '#include "Arduino.h"\n'}, False, "sim/x.cpp:1 includes Arduino.h"),
        ("header in two folders", {"lib/Top/Low.h": "#pragma once\n"}, False, "header Low.h is in both"),
    ]
    failures = 0
    for name, extra, want_ok, want_text in cases:
        files = dict(base)
        files.update(extra)
        out = io.StringIO()
        ok = report(tree(files), out=out)
        text = out.getvalue()
        good = ok == want_ok and (want_text is None or want_text in text)
        failures += not good
        print("%s: %s" % ("ok" if good else "WRONG", name))
        if not good:
            print("  expected %s%s; got:\n%s" % ("pass" if want_ok else "failure",
                                                 " with '%s'" % want_text if want_text else "", text))
    print("# self-test: %d of %d cases right" % (len(cases) - failures, len(cases)))
    return failures == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."),
                    help="the project's root (default: this script's parent folder)")
    ap.add_argument("--dot", action="store_true", help="print the graph in Graphviz's dot language")
    ap.add_argument("--self-test", action="store_true", help="check the check on planted breaches")
    args = ap.parse_args()
    if args.self_test:
        return 0 if self_test() else 1
    return 0 if report(os.path.abspath(args.root), dot=args.dot) else 1


if __name__ == "__main__":
    sys.exit(main())
