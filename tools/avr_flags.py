#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The AVR flags of mk/avr-flags.mk (the Makefile's) as PlatformIO's build_flags.

platformio.ini runs it through PlatformIO's dynamic build flags (a line of build_flags
that starts with `!` is a command whose output is the flags):

    build_flags = !python3 tools/avr_flags.py

PlatformIO puts -D in CPPDEFINES, -Wl, in LINKFLAGS and every other flag in CCFLAGS
(the compiler's, C and C++ alike: the C++-only ones draw a warning on the core's C files,
nothing more). So what the Makefile gives its link is said in the link's terms:
- the optimisation and target flags (-Os, -mcall-prologues, -mstrict-X ...) reach the
  link through the objects: LTO's link compiles with the flags the objects were compiled
  with (measured with the Makefile's objects: a link without them makes the same bytes);
- -mrelax, which the compiler driver passes to the linker as --relax, is also given as
  -Wl,--relax (without it the image is 1.6 KB larger);
- -Wl,--gc-sections as it is; -fuse-linker-plugin is PlatformIO's own; -flto-partition=one
  cannot be given to PlatformIO's link (the Makefile's image is the same without it).

  python3 tools/avr_flags.py           the flags, on one line
  python3 tools/avr_flags.py --list    NAME := flags, as mk/avr-flags.mk has them
"""
import os
import re
import sys

FLAGS_FILE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "mk", "avr-flags.mk")


def read_flags(path=FLAGS_FILE):
    """{NAME: [flags]} from the file's `NAME := flags` lines."""
    out = {}
    with open(path) as f:
        for line in f:
            m = re.match(r"^(AVR_SHARED_\w+)\s*:=\s*(.*)$", line.strip())
            if m:
                out[m.group(1)] = m.group(2).split()
    return out


def platformio_flags(flags):
    opt = flags["AVR_SHARED_OPT"] + flags.get("AVR_SHARED_PROJECT_OPT", [])
    link = [f for f in flags["AVR_SHARED_LINK"] if f.startswith("-Wl,")]
    if "-mrelax" in opt:
        link.append("-Wl,--relax")
    return flags["AVR_SHARED_DEFS"] + opt + flags["AVR_SHARED_CXX"] + flags["AVR_SHARED_WARN"] + link


def main(argv):
    flags = read_flags()
    if "--list" in argv:
        for name, values in flags.items():
            print("%s := %s" % (name, " ".join(values)))
    else:
        print(" ".join(platformio_flags(flags)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
