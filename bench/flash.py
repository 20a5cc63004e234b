# SPDX-License-Identifier: GPL-3.0-or-later
"""Flash per library, and the image against its budget: a section of `make bench`'s report.

    flash_section(build_dir) -> (markdown, figures)

Every byte of the image is given to the part of the tree it comes from, in the image as it
is (LTO inlines across files, so a function's symbol says little: setup() and loop() are
inlined into the core's main(), lib/LinAlg's helpers into their callers):
- code: the source file of each instruction, from the debug lines of BUILD/flash-attr
  (`make flash-attr`: the firmware built again with -g, whose flash bytes must be the
  firmware's: checked here), read by `avr-objdump -d -l`; inlined code counts where it
  was written (a lib/LinAlg helper inlined into lib/DCM counts to lib/LinAlg);
- code without debug lines (libgcc, libc, libm, the start-up code, the core's assembly):
  the archive member the link map names;
- data in flash (PROGMEM strings and tables) and the initial values of RAM (.data): the
  part that defines a global of that name (the objects' symbol tables, avr-gcc-nm), else
  the part of the function, class or namespace it belongs to (a string's function), else
  the part whose code refers to it (the relocations of the same link made with -Wl,-q).
The figures go to BUILD/bench/flash.json too. Run alone: python3 bench/flash.py [BUILD].
"""
import json
import os
import re
import subprocess
import sys
from collections import Counter, defaultdict

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUDGET = 204800       # the flash budget with every feature (200 KB)
UPLOAD_MAX = 253952   # what the Mega 2560's bootloader leaves for the sketch
BOUNDARY = 131072     # past it, indirect calls go through trampolines (e2e.Beyond128K)


def run(cmd, cwd=None):
    return subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=cwd).stdout


def part_of_path(path):
    """The part of the tree a source file belongs to (None: not one of ours to name)."""
    p = path.replace("\\", "/")
    if p.startswith(REPO + "/"):
        p = p[len(REPO) + 1:]
    m = re.match(r"lib/([^/]+)/", p)
    if m:
        return "lib/" + m.group(1)
    if p.startswith("firmware/"):
        return "firmware/"
    if re.search(r"(^|/)mavlink/", p):
        return "MAVLink C headers (build/mavlink)"
    m = re.search(r"/libraries/(\w+)/", p)
    if m:
        return "Arduino %s library" % m.group(1)
    if "/cores/arduino/" in p or "/variants/" in p:
        return "Arduino core"
    if "/avr/include/" in p or "/avr-libc" in p:
        return "avr-libc"
    return None


def part_of_member(obj):
    """The part an input file of the link belongs to, from the map's file name."""
    if "linker stubs" in obj:
        return "trampolines (linker)"
    if "libgcc.a" in obj:
        return "libgcc"
    if "libm.a" in obj:
        return "libm (avr-libc's float maths)"
    if "libc.a" in obj:
        return "avr-libc"
    if re.search(r"/crt\w*\.o", obj):
        return "start-up (vectors, crt)"
    if "core.a(" in obj:
        m = re.search(r"core\.a\((\w+)", obj)
        return {"Wire": "Arduino Wire library", "twi": "Arduino Wire library",
                "SPI": "Arduino SPI library"}.get(m.group(1) if m else "", "Arduino core")
    if ".ltrans" in obj or "padding" in obj:
        return None
    return part_of_path(obj)


def symbols(elf):
    """[(address, size, type, section index, name)] with sizes, from avr-readelf."""
    out = []
    for line in run(["avr-readelf", "-sW", elf]).splitlines():
        f = line.split()
        if len(f) >= 8 and f[0].endswith(":") and f[2].isdigit() and int(f[2]) > 0 and f[6].isdigit():
            out.append((int(f[1], 16), int(f[2]), f[3], int(f[6]), f[7]))
    return out


def sections(elf):
    out = {}
    for line in run(["avr-readelf", "-SW", elf]).splitlines():
        m = re.match(r"\s*\[\s*(\d+)\]\s+(\S+)\s+\S+\s+([0-9a-f]+)\s+[0-9a-f]+\s+([0-9a-f]+)", line)
        if m:
            out[m.group(2)] = (int(m.group(1)), int(m.group(3), 16), int(m.group(4), 16))
    return out


def code_files(elf):
    """{address: part} for every instruction with a debug line, and each instruction's size."""
    part_at, size_at = {}, {}
    current = None
    for line in run(["avr-objdump", "-d", "-l", "-j", ".text", elf], cwd=REPO).splitlines():
        # A new function: its code does not carry the last line of the one before it. main()
        # (the sketch's loop as LTO inlined it, ~15 KB) has no lines of its own, and was
        # counted to the function before it in the image (lib/MS5611's constructor).
        m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if m:
            current = "code without debug lines" + (" (main)" if m.group(1) == "main" else "")
            continue
        m = re.match(r"^(\S.*):(\d+)( \(discriminator \d+\))?$", line)
        if m and not line.endswith("():"):
            current = part_of_path(m.group(1)) or "other sources"
            continue
        m = re.match(r"^\s+([0-9a-f]+):\t((?:[0-9a-f]{2} )+)", line)
        if m:
            a = int(m.group(1), 16)
            size_at[a] = len(m.group(2).split())
            if current:
                part_at[a] = current
    return part_at, size_at


def map_ranges(mapfile):
    """[(start, size, part)] of the input sections whose file the map names (no ltrans)."""
    out = []
    text = open(mapfile).read()
    text = text[text.find("Linker script and memory map"):]
    for m in re.finditer(r"^ (\.\S+)\s*\n?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$", text, re.M):
        start, size, obj = int(m.group(2), 16), int(m.group(3), 16), m.group(4)
        part = part_of_member(obj)
        if size and part and start < 0x800000:
            out.append((start, size, part))
    return out


def relocation_users(elf):
    """[(offset, target)] of the relocations kept in the ELF (-Wl,-q)."""
    out = []
    for line in run(["avr-readelf", "-rW", elf]).splitlines():
        m = re.match(r"^([0-9a-f]{8})\s+[0-9a-f]+\s+R_AVR_\S+\s+([0-9a-f]+)\s+\S+(?:\s*([+-])\s*([0-9a-f]+))?", line)
        if m:
            target = int(m.group(2), 16) + (int(m.group(4), 16) * (-1 if m.group(3) == "-" else 1) if m.group(4) else 0)
            out.append((int(m.group(1), 16), target))
    return out


def global_definitions(build):
    """{symbol: part} of the globals the objects define (LTO objects read through the plugin)."""
    objs = []
    for root, _, files in os.walk(os.path.join(build, "avr")):
        objs += [os.path.join(root, f) for f in files if f.endswith(".o") and "/arduino/" not in root]
    core = os.path.join(build, "avr", "core.a")
    out = {}
    try:
        text = run(["avr-gcc-nm", "-A", "--defined-only"] + sorted(objs) + ([core] if os.path.exists(core) else []))
    except (OSError, subprocess.CalledProcessError):
        return out
    for line in text.splitlines():
        m = re.match(r"^(.*?):(?:(\w[\w.+-]*\.o):)?[0-9a-f]*\s+[A-Za-z]\s+(\S+)$", line)
        if not m:
            continue
        path, member, name = m.groups()
        if member:
            part = part_of_member("core.a(" + member + ")")
        else:
            rel = os.path.relpath(path, os.path.join(build, "avr"))
            part = "firmware/" if rel.startswith("sketch/") else part_of_path(os.path.join(REPO, rel))
        if part:
            out.setdefault(name, part)
    return out


def demangle(names):
    names = sorted(set(names))
    try:
        out = subprocess.run(["avr-c++filt"], input="\n".join(names), capture_output=True, text=True,
                             check=True).stdout.splitlines()
        return dict(zip(names, out)) if len(out) == len(names) else {n: n for n in names}
    except (OSError, subprocess.CalledProcessError):
        return {n: n for n in names}


def namespace_of(readable):
    """'a::b::f(int)::__c' -> ['a::b::f', 'a::b', 'a'] (the longest first)."""
    head = re.sub(r"\(.*", "", readable)
    head = re.sub(r" \[clone .*", "", head)
    parts = head.split("::")
    return ["::".join(parts[:i]) for i in range(len(parts), 0, -1)]


def attribute(build):
    """{part: bytes} of the image's flash, and notes."""
    elf = os.path.join(build, "flash-attr", "firmware.elf")
    secs = sections(elf)
    text_idx, text_addr, text_size = secs[".text"]
    data_idx, data_addr, data_size = secs.get(".data", (None, 0, 0))
    owner = [None] * text_size  # part per flash byte of .text
    # objdump names a line only where it changes: an instruction without one carries the
    # last one named, so the map's members (no debug lines) are laid over the code's lines.
    part_at, size_at = code_files(elf)
    for a, part in part_at.items():
        for b in range(a, min(a + size_at[a], text_size)):
            owner[b] = part
    for start, size, part in map_ranges(os.path.join(build, "flash-attr", "firmware.map")):
        for a in range(max(start, 0), min(start + size, text_size)):
            owner[a] = part

    syms = symbols(elf)
    names = demangle(s[4] for s in syms)
    funcs = [s for s in syms if s[2] == "FUNC" and s[3] == text_idx]
    # Which part each function, class and namespace is in (by its functions' first lines).
    votes = defaultdict(Counter)
    for a, size, _, _, name in funcs:
        part = part_at.get(a)
        if part:
            for ns in namespace_of(names[name]):
                votes[ns][part] += size
    # Which parts refer to each address (code with a debug line at the relocation).
    users = defaultdict(Counter)
    for off, target in relocation_users(os.path.join(build, "flash-attr", "firmware-relocs.elf")):
        a = off - (off % 2)
        part = part_at.get(a) or part_at.get(a - 2)
        if part:
            users[target][part] += 1
    globals_ = global_definitions(os.path.join(build, "flash-attr"))

    def data_part(addr, size, name):
        if name in globals_:  # a global: the object that defines it
            return globals_[name]
        for ns in namespace_of(names[name]):  # a function's static, a class's or namespace's
            if votes.get(ns):
                return votes[ns].most_common(1)[0][0]
        refs = Counter()  # else the code that uses it
        for t in range(addr, addr + max(size, 1)):
            refs.update(users.get(t, {}))
        return refs.most_common(1)[0][0] if refs else None

    parts = Counter()
    for a, size, typ, idx, name in syms:
        if typ != "OBJECT":
            continue
        if idx == text_idx:
            part = data_part(a, size, name)
            for b in range(a, min(a + size, text_size)):
                owner[b] = part or owner[b] or "data in flash, not attributed"
        elif idx == data_idx and size:
            parts[data_part(a, size, name) or "initial RAM values (.data), not attributed"] += size
            data_size -= size
    if data_size > 0:
        parts["initial RAM values (.data), not attributed"] += data_size
    parts.update(p or "not attributed" for p in owner)
    return parts


def flash_of(elf):
    sec = {}
    for line in run(["avr-size", "-A", elf]).splitlines():
        f = line.split()
        if len(f) >= 2 and f[0].startswith(".") and f[1].isdigit():
            sec[f[0]] = int(f[1])
    return sec.get(".text", 0) + sec.get(".data", 0)


def same_flash(a, b):
    bins = []
    for elf in (a, b):
        out = elf + ".flash.bin"
        subprocess.run(["avr-objcopy", "-O", "binary", "-R", ".eeprom", elf, out], check=True)
        with open(out, "rb") as f:
            bins.append(f.read())
        os.unlink(out)
    return bins[0] == bins[1]


def fmt(n):
    return "{:,}".format(n)


def flash_section(build_dir):
    """The report's section (markdown) and its figures (dict)."""
    build = os.path.abspath(build_dir)
    elf = os.path.join(build, "firmware.elf")
    attr = os.path.join(build, "flash-attr", "firmware.elf")
    md = ["## Flash per library", ""]
    if not os.path.exists(elf):
        return "\n".join(md + ["Not measured: no %s (make firmware)." % os.path.relpath(elf, REPO), ""]), {}
    total = flash_of(elf)
    figures = dict(flash_bytes=total, flash_budget_bytes=BUDGET, flash_budget_left_bytes=BUDGET - total,
                   flash_upload_max_bytes=UPLOAD_MAX)
    md += ["Flash %s bytes: %.1f %% of the %s-byte budget (200 KB with every feature, navigation "
           "included), %s bytes left; %.1f %% of the %s bytes the Mega 2560's bootloader leaves for "
           "the sketch. %s" % (
               fmt(total), 100.0 * total / BUDGET, fmt(BUDGET), fmt(BUDGET - total), 100.0 * total / UPLOAD_MAX,
               fmt(UPLOAD_MAX),
               "Past 128 KB (131,072 bytes) code is reached through EIND and the linker's trampolines: "
               "the test e2e.Beyond128K runs the firmware padded to the budget (`make big`)." if total <= BOUNDARY
               else "The image is past 128 KB: e2e.Beyond128K's checks apply to the firmware itself."), ""]
    if not os.path.exists(attr):
        return "\n".join(md + ["Per library: not measured (no %s: make flash-attr)." % os.path.relpath(attr, REPO),
                               ""]), figures
    if not same_flash(elf, attr):
        md += ["Note: the -g build's flash differs from the firmware's (%s vs %s bytes): the parts below are "
               "its own." % (fmt(flash_of(attr)), fmt(total)), ""]
    try:
        parts = attribute(build)
    except (OSError, subprocess.CalledProcessError, KeyError) as e:
        return "\n".join(md + ["Per library: failed (%s)." % e, ""]), figures
    counted = sum(parts.values())
    rows = sorted(parts.items(), key=lambda kv: (-kv[1], kv[0]))
    md += ["Each byte of the image given to the part of the tree it comes from (bench/flash.py: code by "
           "the source file of each instruction, as LTO inlined it, from a -g build with the same flash "
           "bytes; libgcc, libc and libm by the link map; PROGMEM data and .data's initial values by the "
           "file, function or namespace that defines them). Inlined code counts where it was written: "
           "lib/LinAlg's inline vector and fixed-point helpers count to lib/LinAlg wherever they run.", "",
           "| part | bytes | share |", "|---|---:|---:|"]
    md += ["| %s | %s | %.1f %% |" % (p, fmt(n), 100.0 * n / counted) for p, n in rows]
    md += ["| **total** | **%s** | |" % fmt(counted), ""]
    figures["flash_by_part"] = dict(rows)
    out_dir = os.path.join(build, "bench")
    if os.path.isdir(out_dir):
        with open(os.path.join(out_dir, "flash.json"), "w") as f:
            json.dump(figures, f, indent=2)
            f.write("\n")
    return "\n".join(md), figures


if __name__ == "__main__":
    text, _ = flash_section(sys.argv[1] if len(sys.argv) > 1 else os.path.join(REPO, "build"))
    print(text)
