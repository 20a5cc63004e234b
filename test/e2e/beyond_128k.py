#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The firmware past 128 KB: the padded image works as the firmware does.

Past 128 KB of flash the ATmega2560 reaches code differently: an indirect call (ICALL,
EICALL, a function pointer, a switch's jump table, -mcall-prologues' return) carries a
16-bit word address, so a target above 0x20000 is reached through a trampoline (a JMP in
the lowest 128 KB, which the linker writes for every gs() reference beyond it); LPM, which
pgm_read_byte and the text's PROGMEM strings use, reads the lowest 64 KB only.

  beyond_128k.py check BIG.elf           where the linker put things, and every function
                                         pointer followed (the ELF must keep its relocations:
                                         linked with -Wl,-q)
  beyond_128k.py compare A.out B.out     two serial outputs the same but for timing
  beyond_128k.py run --tools DIR --work DIR [--base ELF] [--big ELF] [--no-controls]
                                         check the padded image, run both in apm25sim on the
                                         same scenario, console input and receiver, and compare
                                         their serial output, servo pulses and EEPROM

`run` is the ctest e2e.Beyond128K (the images from `make firmware big`); the sketch test
(test/sketch/arduino_builder.sh) runs it on its arduino-builder images. The last line is
"N passed, M failed"; the exit status is 1 on any failure.

What the comparison allows, and why: the trampolines cost cycles (an indirect call to code
above 0x20000 runs one JMP more: 3 cycles), so what is timing may differ: the figures
measured from the clock (the loop load of `status` and SYS_STATUS, the uptime,
SERVO_OUTPUT_RAW's microseconds), the order in which replies and output lines interleave,
the output step a typed mode switch lands on (csv rows and MAVLink frames are matched by
their time stamps), the step a compass sample is read in (the console run has no compass;
below) and simavr's capture of a receiver edge (1 us; below). Every message
and reply, every angle, every frame's content, every servo pulse and the EEPROM must be the
same. Two controls linked beside the image (no trampolines; the PROGMEM data above 64 KB)
must be caught by the checks and by the comparison.
"""
import argparse
import os
import re
import struct
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench"))
from flash import demangle  # noqa: E402  (one reader of avr-c++filt, bench/flash.py's)

BOUNDARY_CALL = 0x20000  # 128 KB: above it, code is reached through EIND (trampolines)
BOUNDARY_LPM = 0x10000   # 64 KB: LPM (pgm_read_byte) reads below it
UPLOAD_MAX = 253952      # the Mega 2560's bootloader leaves this much for the sketch
DATA_VMA = 0x800000      # avr-ld's offset of the data address space

# AVR relocation types (binutils include/elf/avr.h) that hold a word address of code.
R_AVR_16_PM, R_AVR_LO8_LDI_GS, R_AVR_HI8_LDI_GS = 5, 24, 25
GS_RELOCS = (R_AVR_16_PM, R_AVR_LO8_LDI_GS, R_AVR_HI8_LDI_GS)
STT_OBJECT, STT_FUNC, STT_SECTION = 1, 2, 3

# ---------------------------------------------------------------------------
# A small ELF32 reader: sections, symbols, relocations.


class Elf:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            self.raw = f.read()
        r = self.raw
        if r[:4] != b"\x7fELF" or r[4] != 1 or r[5] != 1:
            raise ValueError("%s: not a little-endian ELF32 file" % path)
        shoff, = struct.unpack_from("<I", r, 0x20)
        shentsize, shnum, shstrndx = struct.unpack_from("<HHH", r, 0x2E)
        self.sections = []
        for i in range(shnum):
            name, typ, flags, addr, off, size, link, info, align, entsize = struct.unpack_from(
                "<IIIIIIIIII", r, shoff + i * shentsize)
            self.sections.append(dict(name_off=name, type=typ, flags=flags, addr=addr, off=off, size=size,
                                      link=link, info=info, entsize=entsize, index=i))
        strtab = self.sections[shstrndx]
        for s in self.sections:
            s["name"] = self._str(strtab, s["name_off"])
        self.by_name = {s["name"]: s for s in self.sections}
        self.symbols = self._symbols()

    def _str(self, sec, off):
        start = sec["off"] + off
        return self.raw[start:self.raw.index(b"\0", start)].decode("latin-1")

    def _symbols(self):
        sym = self.by_name.get(".symtab")
        if not sym:
            return []
        strs = self.sections[sym["link"]]
        out = []
        for i in range(sym["size"] // 16):
            name, value, size, info, other, shndx = struct.unpack_from("<IIIBBH", self.raw, sym["off"] + 16 * i)
            out.append(dict(name=self._str(strs, name), value=value, size=size, type=info & 15, bind=info >> 4,
                            shndx=shndx))
        return out

    def relocations(self):
        """(offset, type, target address) of every relocation kept in the ELF (-Wl,-q)."""
        out = []
        for s in self.sections:
            if s["type"] != 4:  # SHT_RELA
                continue
            applies_to = self.sections[s["info"]]["name"]
            if applies_to not in (".text", ".data"):
                continue
            for i in range(s["size"] // 12):
                off, info, addend = struct.unpack_from("<IIi", self.raw, s["off"] + 12 * i)
                sym = self.symbols[info >> 8]
                out.append((off, info & 0xFF, sym["value"] + addend))
        return out

    def section_at(self, addr):
        for s in self.sections:
            if s["type"] == 1 and s["flags"] & 2 and s["addr"] <= addr < s["addr"] + s["size"]:  # PROGBITS, ALLOC
                return s
        return None

    def u16(self, addr):
        s = self.section_at(addr)
        if s is None:
            raise ValueError("0x%x: in no loaded section" % addr)
        return struct.unpack_from("<H", self.raw, s["off"] + addr - s["addr"])[0]

    def size(self, name):
        s = self.by_name.get(name)
        return s["size"] if s else 0

    def flash(self):
        return self.size(".text") + self.size(".data")

    def sym(self, name):
        for s in self.symbols:
            if s["name"] == name:
                return s
        return None




def jmp_target(w1, w2):
    """The byte address a JMP (1001 010k kkkk 110k, k16) goes to, or None."""
    if w1 & 0xFE0E != 0x940C:
        return None
    return ((((w1 >> 3) & 0x3E) | (w1 & 1)) << 16 | w2) * 2


def call_targets(elf, start, size):
    """The targets of the CALL instructions in [start, start + size), by a linear sweep."""
    out = []
    a = start
    while a < start + size:
        w = elf.u16(a)
        if w & 0xFE0E == 0x940E:  # call
            out.append(((((w >> 3) & 0x3E) | (w & 1)) << 16 | elf.u16(a + 2)) * 2)
            a += 4
        elif w & 0xFE0E == 0x940C or w & 0xFC0F == 0x9000:  # jmp, lds, sts: two words
            a += 4
        else:
            a += 2
    return out


# ---------------------------------------------------------------------------
# Where things lie, and every function pointer followed.


class Checks:
    def __init__(self, quiet=False):
        self.passed = 0
        self.failed = 0
        self.failed_keys = set()
        self.quiet = quiet

    def ok(self, cond, what, detail="", key=None):
        if cond:
            self.passed += 1
        else:
            self.failed += 1
            self.failed_keys.add(key or what)
        if not self.quiet:
            print(("ok: %s" % what) if cond else ("FAIL: %s%s" % (what, (": " + detail) if detail else "")))
        return cond

    def note(self, text):
        if not self.quiet:
            print(text)


def hx(a):
    return "0x%05x" % a


def check_placement(elf, checks):
    checks.note("# %s" % elf.path)
    text = elf.by_name[".text"]
    flash = elf.flash()
    pad = elf.sym("apm25_padding")
    checks.ok(flash > BOUNDARY_CALL and flash <= UPLOAD_MAX,
              "the image is past 128 KB and fits: flash %d bytes (.text %d + .data %d), 131072 < it <= %d" % (
                  flash, elf.size(".text"), elf.size(".data"), UPLOAD_MAX),
              "the padding is %s" % ("%d bytes" % pad["size"] if pad else "missing"), key="size")
    if pad:
        checks.note("#   padding: apm25_padding, %d bytes at %s-%s" % (
            pad["size"], hx(pad["value"]), hx(pad["value"] + pad["size"])))
    in_text = [s for s in elf.symbols if s["shndx"] == text["index"] and s["size"] > 0]
    names = demangle(s["name"] for s in in_text)

    # PROGMEM and the other data in flash: LPM reads them, below 64 KB only.
    data = [s for s in in_text if s["type"] == STT_OBJECT]
    if data:
        lo = min(s["value"] for s in data)
        hi = max(s["value"] + s["size"] for s in data)
        checks.note("#   data in flash (PROGMEM strings and tables): %d objects, %d bytes, at %s-%s" % (
            len(data), sum(s["size"] for s in data), hx(lo), hx(hi)))
        above = [s for s in data if s["value"] + s["size"] > BOUNDARY_LPM]
        checks.ok(not above, "every PROGMEM object lies below 64 KB (LPM reaches it)",
                  "%d above 0x10000: %s" % (len(above), ", ".join(names[s["name"]] for s in above[:5])),
                  key="progmem")
    else:
        checks.ok(False, "data in flash found", "no OBJECT symbol in .text", key="progmem")
    d_load = elf.sym("__data_load_start")
    if d_load:
        checks.note("#   .data's initial values at %s (copied at start-up with ELPM: any address)" %
                    hx(d_load["value"]))

    # Trampolines: JMPs the linker writes low, one per gs() target above 128 KB.
    ts, te = elf.sym("__trampolines_start"), elf.sym("__trampolines_end")
    tramp = {}
    if ts and te:
        for a in range(ts["value"], te["value"], 4):
            t = jmp_target(elf.u16(a), elf.u16(a + 2))
            if t is not None:
                tramp[t] = a
        checks.note("#   trampolines: %d at %s-%s" % (len(tramp), hx(ts["value"]), hx(te["value"])))
        checks.ok(te["value"] <= BOUNDARY_CALL and tramp, "the trampolines lie below 128 KB (EIND = 0 reaches them)",
                  "%d trampolines ending at %s" % (len(tramp), hx(te["value"])), key="trampolines")

    # Code: the firmware's functions past the boundary.
    funcs = [s for s in in_text if s["type"] == STT_FUNC and s is not pad]
    above = [s for s in funcs if s["value"] >= BOUNDARY_CALL]
    straddle = [s for s in funcs if s["value"] < BOUNDARY_CALL < s["value"] + s["size"]]
    checks.note("#   functions: %d, %d of them (%d bytes) above 0x20000%s" % (
        len(funcs), len(above), sum(s["size"] for s in above),
        "; 0x20000 falls in %s" % names[straddle[0]["name"]] if straddle else ""))
    main = elf.sym("main")
    if checks.ok(main is not None and main["value"] >= BOUNDARY_CALL,
                 "main (setup and loop inlined in the core's main) lies above 128 KB",
                 "main at %s" % (hx(main["value"]) if main else "?")):
        calls = set(call_targets(elf, main["value"], main["size"]))
        high = sorted(t for t in calls if t >= BOUNDARY_CALL)
        checks.note("#   main at %s calls %d functions, %d of them above 0x20000" % (
            hx(main["value"]), len(calls), len(high)))
        checks.ok(high, "the loop calls functions above 128 KB", key="loop")

    # Every code address held as a word (gs(): function pointers in tables, the .ctors
    # list, switch jump tables, -mcall-prologues' returns, attachInterrupt's handler):
    # below 128 KB the target itself, above it a trampoline that jumps to the target.
    relocs = [r for r in elf.relocations() if r[1] in GS_RELOCS]
    if not checks.ok(relocs, "the ELF keeps its relocations (linked with -Wl,-q)"):
        return
    at = sorted(((s["value"], s) for s in elf.symbols if s["size"] > 0 and s["type"] in (STT_OBJECT, STT_FUNC)),
                key=lambda p: p[0])
    names.update(demangle(s["name"] for _, s in at))

    def owner(addr):
        best = None
        for v, s in at:
            if v > addr:
                break
            if addr < v + s["size"]:
                best = s
        return names.get(best["name"], best["name"]) if best else "?"

    func_at = {s["value"]: s for s in funcs}
    wrong = []
    tables = {}  # table symbol -> [(target, via trampoline)]
    kinds = {"RAM tables (.data)": 0, "flash tables (.ctors, jump tables, PROGMEM)": 0, "code (ldi gs())": 0}
    for off, typ, target in relocs:
        via = tramp.get(target) if target >= BOUNDARY_CALL else None
        want = (via if via is not None else target) // 2
        if typ == R_AVR_16_PM:
            got = elf.u16(off)
            ok = got == want
        else:
            w = elf.u16(off)
            got = ((w >> 4) & 0xF0) | (w & 0x0F)
            ok = got == (want & 0xFF if typ == R_AVR_LO8_LDI_GS else want >> 8)
        if target >= BOUNDARY_CALL and via is None:
            ok = False
        if not ok:
            wrong.append("%s at %s -> %s (%s)" % ({5: "word", 24: "ldi lo8", 25: "ldi hi8"}[typ], hx(off), hx(target),
                                                   owner(target)))
        if off >= DATA_VMA:
            kinds["RAM tables (.data)"] += 1
            tables.setdefault(owner(off), []).append((target, via))
        elif typ == R_AVR_16_PM:
            kinds["flash tables (.ctors, jump tables, PROGMEM)"] += 1
        else:
            kinds["code (ldi gs())"] += 1
    high = sorted({t for _, _, t in relocs if t >= BOUNDARY_CALL})
    checks.note("#   code addresses held as words: %d (%s); %d distinct targets above 0x20000" % (
        len(relocs), ", ".join("%d in %s" % (n, k) for k, n in kinds.items()), len(high)))
    for table, entries in sorted(tables.items()):
        shown = ", ".join("%s %s%s" % (names.get(func_at[t]["name"], "?") if t in func_at else owner(t), hx(t),
                                      " via %s" % hx(v) if v is not None else "")
                          for t, v in entries)
        checks.note("#     %s: %s" % (table, shown))
    checks.ok(not wrong, "every code address held as a word reaches its target (directly below 128 KB, "
              "through its trampoline above)", "%d wrong: %s" % (len(wrong), "; ".join(wrong[:6])), key="words")
    ram_high = [t for entries in tables.values() for t, v in entries if t >= BOUNDARY_CALL]
    checks.ok(ram_high, "function pointers in RAM tables point past 128 KB (through trampolines)",
              "none of the %d does" % sum(len(e) for e in tables.values()))


# ---------------------------------------------------------------------------
# Serial output compared but for timing.

# Figures that follow from the cycles spent: the loop's load (status, SYS_STATUS) and the
# uptime a reply is formatted at.
TIMING_TEXT = [(re.compile(r"load \d+%"), "load N%"), (re.compile(r"uptime [0-9.]+ s"), "uptime T s"),
               # the task table's overrun counts and longest runs (status)
               (re.compile(r"# tasks: .*"), "# tasks: T"),
               # The barometer's readings: a loop task starts its conversions when the loop
               # gets to it, so the instant each is taken (the pressure on a moving trajectory,
               # the noise a 10 Hz mean draws) is timing; its state word is not.
               (re.compile(r"^(# baro \w+: ).*"), r"\1readings"),
               (re.compile(r"ground \d+ Pa \(GND_ABS_PRESS\), -?[0-9.]+ C"), "ground P Pa (GND_ABS_PRESS), T C"),
               (re.compile(r"^# GND_ABS_PRESS [0-9.]+"), "# GND_ABS_PRESS P")]
# MAVLink fields that are measured time: (message id, payload offset, length).
TIMING_FIELDS = {1: [(12, 2)],   # SYS_STATUS.load
                 36: [(0, 4)],   # SERVO_OUTPUT_RAW.time_usec
                 24: [(0, 8)],   # GPS_RAW_INT.time_usec: the fix's arrival on the board's clock
                 # GLOBAL_POSITION_INT: its instant, the position moved on to it (lat, lon, alt,
                 # relative_alt) and the attitude's heading then; the fix's velocity is compared
                 33: [(0, 20), (26, 2)],
                 74: [(8, 10)],  # VFR_HUD: the barometer's height and climb, the heading, at its instant
                 2: [(0, 12)]}   # SYSTEM_TIME: its instant (a stream's timer, GPS time moved on to it)
# Receiver widths, in us, and what follows from them. simavr applies a pin edge at the end of
# the instruction running when it is due, so Timer5's capture (0.5 us a count) of the same
# edge may read one count apart when other instructions run (on the chip it is cycle-exact):
# a width read 1 us apart. In MANUAL the outputs follow it 1 us apart; in STABILIZE the
# stick's bank demand goes through the roll controller's P and its integrator, which sums
# a read's difference over the steps until the next frame: up to 2.25 us apart on OUT1 (3
# of 1000 pulses, STABILIZE from 10 s; a misplaced call is off by tens of us). The servo
# log stamps each edge at an instruction boundary too (within 0.3 us, apm25sim --help).
RC_TOLERANCE_US = 1
SERVO_TOLERANCE_US = 3
SERVO_LOG_STAMP_US = 0.6
# MAVLink messages whose fields are receiver or servo widths: (message id, first uint16
# field's offset, count, tolerance in us).
WIDTH_FIELDS = {65: (4, 18, RC_TOLERANCE_US),       # RC_CHANNELS chan1..18_raw
                36: (4, 8, SERVO_TOLERANCE_US)}     # SERVO_OUTPUT_RAW servo1..8_raw
# Messages matched by their time stamp (time_boot_ms, the first field): which output step a
# mode switch typed at the console lands on is timing too.
KEYED_MESSAGES = (30,)  # ATTITUDE
# Messages sent when a loop pass finds their period over: the millisecond they are stamped
# with is timing; matched in order, their stamps within this many ms.
# SCALED_PRESSURE goes a run of the streams task after RC_CHANNELS and SERVO_OUTPUT_RAW when
# due with them (one frame a run): a pass or two later, up to two samples apart.
ORDERED_MESSAGES = {65: 5,   # RC_CHANNELS (5 Hz)
                    29: 10}  # SCALED_PRESSURE (5 Hz, after them)
# The barometer's pressure and temperature are timing too (TIMING_TEXT): SCALED_PRESSURE's
# within 0.1 hPa (a conversion's noise) and 0.02 degC.
BARO_TOLERANCE_HPA = 0.1
BARO_TOLERANCE_CDEG = 2


def scaled_pressure_close(p, q):
    full = lambda b: bytes(b) + bytes(16 - len(b))  # trailing zeros trimmed
    a, b = struct.unpack("<Iffhh", full(p)), struct.unpack("<Iffhh", full(q))
    return a[0] == b[0] and abs(a[1] - b[1]) <= BARO_TOLERANCE_HPA and a[2] == b[2] and \
        abs(a[3] - b[3]) <= BARO_TOLERANCE_CDEG and a[4] == b[4]


# Payload comparisons other than equality, for ORDERED_MESSAGES (their stamps zeroed).
CLOSE = {29: scaled_pressure_close}


def split_stream(data):
    """Text lines and MAVLink 2 frames, in order: [("line", str) | ("frame", msgid, payload)]."""
    out = []
    i = 0
    while i < len(data):
        if data[i] == 0xFD and i + 10 <= len(data):
            n = data[i + 1]
            end = i + 12 + n + (13 if data[i + 2] & 1 else 0)
            msgid = data[i + 7] | data[i + 8] << 8 | data[i + 9] << 16
            if end > len(data):
                break  # the run stopped in the middle of this frame: no frame (both images' cut differs)
            out.append(("frame", msgid, bytes(data[i + 10:i + 10 + n])))
            i = end
            continue
        j = data.find(b"\n", i)
        j = len(data) if j < 0 else j + 1
        out.append(("line", data[i:j].decode("latin-1").rstrip("\r\n")))
        i = j
    return out


def streams(data):
    """The output as per-kind sequences, the timing figures masked:
    "# lines" (messages and replies), "plot lines" (angles without a time), "csv rows"
    (keyed by their t_ms), "other lines" (quat, raw), "MAVLink N" (payloads)."""
    kinds = {"# lines": [], "plot lines": [], "csv rows": [], "other lines": []}
    for item in split_stream(data):
        if item[0] == "line":
            line = item[1]
            if line.startswith("#"):
                for pat, rep in TIMING_TEXT:
                    line = pat.sub(rep, line)
                kinds["# lines"].append(line)
            elif line.startswith("roll:"):
                kinds["plot lines"].append(line)
            elif re.match(r"^\d+,", line):
                kinds["csv rows"].append(line)
            elif line:
                kinds["other lines"].append(line)
        else:
            _, msgid, payload = item
            p = bytearray(payload)
            for off, n in TIMING_FIELDS.get(msgid, []):
                p[off:off + n] = b"\0" * min(n, max(0, len(p) - off))
            if msgid == 22 and bytes(p[8:21]) == b"GND_ABS_PRESS":  # PARAM_VALUE: the barometer's reading
                p[0:4] = b"\0" * 4
            kinds.setdefault("MAVLink %d" % msgid, []).append(bytes(p))
    return kinds


# ATTITUDE's angles and rates: a compass sample is read on the first step that sees its
# DRDY pin high, so one whose edge falls near a step's start may be read a step apart when
# the two images' steps start a few cycles apart; the heading and the learned biases then
# differ by hundredths of a degree: within 1e-3 rad and rad/s.
ATTITUDE_TOLERANCE = 1e-3


def attitude_close(p, q):
    full = lambda b: bytes(b) + bytes(28 - len(b))  # MAVLink 2 trims the payload's trailing zeros
    a, b = struct.unpack("<I6f", full(p)), struct.unpack("<I6f", full(q))
    return a[0] == b[0] and all(abs(x - y) <= ATTITUDE_TOLERANCE for x, y in zip(a[1:], b[1:]))


def widths_close(msgid, p, q):
    off, n, tol = WIDTH_FIELDS[msgid]
    if len(p) != len(q) or p[:off] != q[:off] or p[off + 2 * n:] != q[off + 2 * n:]:
        return False
    if len(p) < off + 2 * n:  # trimmed, or the run's last frame cut short: byte for byte
        return p == q
    return all(abs(a - b) <= tol for a, b in zip(struct.unpack_from("<%dH" % n, p, off),
                                                 struct.unpack_from("<%dH" % n, q, off)))


def compare_kind(kind, x, y):
    """None when the two sequences agree, else what differs."""
    msgid = int(kind.split()[1]) if kind.startswith("MAVLink") else None
    if kind == "csv rows" or msgid in KEYED_MESSAGES:
        key = (lambda r: r.split(",", 1)[0]) if kind == "csv rows" else (lambda p: p[:4])
        dx, dy = {key(r): r for r in x}, {key(r): r for r in y}
        both = [k for k in dx if k in dy]
        same = (lambda p, q: p == q) if msgid not in WIDTH_FIELDS else (lambda p, q: widths_close(msgid, p, q))
        if msgid == 30:
            same = attitude_close
        bad = [k for k in both if not same(dx[k], dy[k])]
        if bad:
            return "%d of %d matched by time differ, first %r vs %r" % (len(bad), len(both), dx[bad[0]], dy[bad[0]])
        if len(both) < 0.95 * max(len(dx), len(dy)):
            return "only %d of %d vs %d matched by time" % (len(both), len(dx), len(dy))
        return None
    if msgid in ORDERED_MESSAGES:
        if abs(len(x) - len(y)) > 1:
            return "%d vs %d frames" % (len(x), len(y))
        stamp = lambda p: struct.unpack_from("<I", p, 0)[0]
        for i, (p, q) in enumerate(zip(x, y)):
            close = CLOSE.get(msgid) or (lambda a, b: widths_close(msgid, a, b))
            if abs(stamp(p) - stamp(q)) > ORDERED_MESSAGES[msgid] or not close(bytes(4) + p[4:], bytes(4) + q[4:]):
                return "frame %d differs: %r vs %r" % (i, p, q)
        return None
    if kind == "plot lines":  # from the start to the switch to another mode: one more or less
        if abs(len(x) - len(y)) > 1:
            return "%d vs %d lines" % (len(x), len(y))
        x, y = x[:min(len(x), len(y))], y[:min(len(x), len(y))]
    if msgid in WIDTH_FIELDS:
        if len(x) == len(y) and all(widths_close(msgid, p, q) for p, q in zip(x, y)):
            return None
    elif x == y:
        return None
    i = next((i for i, (p, q) in enumerate(zip(x, y)) if p != q), min(len(x), len(y)))
    return "%d vs %d, first difference at #%d: %r vs %r" % (
        len(x), len(y), i, x[i] if i < len(x) else "(end)", y[i] if i < len(y) else "(end)")


def compare_outputs(a, b):
    """Differences between two serial outputs (empty: the same but for timing)."""
    sa, sb = streams(a), streams(b)
    diffs = []
    for k in sorted(set(sa) | set(sb)):
        d = compare_kind(k, sa.get(k, []), sb.get(k, []))
        if d:
            diffs.append("%s: %s" % (k, d))
    return diffs


def summary(data):
    return ", ".join("%d %s" % (len(v), k) for k, v in sorted(streams(data).items()) if v)


# ---------------------------------------------------------------------------
# Both images on the same scenario, console input and receiver.

# Console commands that read PROGMEM strings and tables (help, the parameter table, the
# replies' and errors' words), write the EEPROM, and end in csv mode. (Commands whose effect
# depends on the step they land on, a calibration's window or the output rate's phase, are
# left out: which step that is is timing.)
CONSOLE = ["help", "status", "params", "get RLL2SRV_P", "set RLL2SRV_P 1.25", "get RLL2SRV_P",
           "flight stabilize", "rc", "servo", "bogus", "set NOPE 1", "save", "status", "mode csv"]
# The receiver: trim and idle, then sticks and throttle, the flight-mode switch (channel 8)
# over to stabilize and back, a loss of signal and its return.
RC = ["t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8",
      "0.5,1500,1500,1000,1500,1500,1500,1500,1000",
      "6,1700,1350,1600,1450,1500,1500,1500,1000",
      "10,1300,1650,1400,1550,1500,1500,1500,1500",
      "14,1500,1500,1000,1500,1500,1500,1500,1000",
      "16,,,,,,,,",
      "18,1500,1500,1200,1500,1500,1500,1500,1500"]
# Two runs of each image: the console in text modes without a receiver, then MAVLink with
# the receiver flying the outputs. The console run has no compass (the heading is the
# gyro's): a compass sample is read in the step that finds its DRDY pin high, and under the
# console's replies when a step starts is timing, so a sample may be taken one step earlier
# in one image than in the other and move the heading by hundredths of a degree.
RUNS = [("console", CONSOLE, None, ["mag:absent"]), ("flight", ["mode mavlink"], RC, [])]


def run_sim(tools, elf, work, tag, seconds, rc, faults=()):
    out, servo, eeprom = (os.path.join(work, tag + ext) for ext in (".out", ".servo.csv", ".eeprom"))
    for p in (out, servo, eeprom):
        if os.path.exists(p):
            os.unlink(p)
    cmd = [os.path.join(tools, "apm25sim"), "--elf", elf, "--trajectory", os.path.join(work, "tilt_tour.csv"),
           "--seconds", str(seconds), "--input", os.path.join(work, tag.split(".")[0] + ".input"),
           "--servo-log", servo, "--eeprom", eeprom]
    if rc:
        cmd += ["--rc", os.path.join(work, "rc.csv")]
    for f in faults:
        cmd += ["--fault", f]
    with open(out, "wb") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.PIPE, timeout=900)
    with open(out, "rb") as f:
        data = f.read()
    return r.returncode, r.stderr.decode(errors="replace"), data, servo, eeprom


def read(path):
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError:
        return None


def servo_pulses(path):
    """Per output, the pulse widths in order (us)."""
    out = {}
    for line in (read(path) or b"").decode().splitlines()[1:]:
        t, o, w = line.split(",")
        out.setdefault(o, []).append(float(w))
    return out


def compare_pulses(pa, pb, tol):
    diffs = []
    for o in sorted(set(pa) | set(pb)):
        x, y = pa.get(o, []), pb.get(o, [])
        if abs(len(x) - len(y)) > 1:  # a pulse still high at the end is not logged
            diffs.append("OUT%s: %d vs %d pulses" % (o, len(x), len(y)))
            continue
        worst = max((abs(p - q) for p, q in zip(x, y)), default=0.0)
        if worst > tol:
            diffs.append("OUT%s: widths up to %.2f us apart" % (o, worst))
    return diffs


def cmd_run(args):
    checks = Checks()
    base = args.base or os.path.join(args.tools, "firmware.elf")
    big = args.big or os.path.join(args.tools, "big", "firmware.elf")
    for p in (base, big):
        if not os.path.exists(p):
            checks.ok(False, "%s exists" % p, "build it: make firmware big")
            return checks
    os.makedirs(args.work, exist_ok=True)
    check_placement(Elf(big), checks)
    print("# the same firmware without the padding (%s): flash %d bytes" % (base, Elf(base).flash()))

    with open(os.path.join(args.work, "tilt_tour.csv"), "wb") as f:
        subprocess.run([os.path.join(args.tools, "scenario"), "tilt_tour"], stdout=f, check=True)
    with open(os.path.join(args.work, "rc.csv"), "w") as f:
        f.write("\n".join(RC) + "\n")
    base_output = {}
    for name, commands, rc, faults in RUNS:
        with open(os.path.join(args.work, name + ".input"), "w") as f:
            f.write("".join(c + "\r\n" for c in commands))
        runs = {}
        for tag, elf in (("base", base), ("big", big)):
            code, err, data, servo, eeprom = run_sim(args.tools, elf, args.work, name + "." + tag, args.seconds, rc,
                                                     faults)
            checks.ok(code == 0, "apm25sim ran the %s image, %s run (%g s of tilt_tour, %s%s%s)" % (
                tag, name, args.seconds, ", ".join(commands) if len(commands) < 3 else
                "%d console commands" % len(commands), ", a receiver" if rc else "",
                "".join(", --fault " + f for f in faults)), "exit %d: %s" % (code, err.strip()[-300:]))
            runs[tag] = (data, servo_pulses(servo), read(eeprom))
            print("#   %s: %d bytes: %s" % (tag, len(data), summary(data)))
        a, b = runs["base"], runs["big"]
        base_output[name] = a[0]
        diffs = compare_outputs(a[0], b[0])
        checks.ok(not diffs, "%s run: the serial output is the same but for timing" % name, "; ".join(diffs))
        tol = SERVO_TOLERANCE_US if rc else SERVO_LOG_STAMP_US
        diffs = compare_pulses(a[1], b[1], tol)
        checks.ok(a[1] and not diffs, "%s run: the servo pulses are the same within %g us (%d on %d outputs)" % (
            name, tol, sum(len(v) for v in a[1].values()), len(a[1])),
            "; ".join(diffs) or "no pulses")
        if name == "console":
            s = streams(a[0])
            checks.ok(len(s["plot lines"]) > 20 and len(s["csv rows"]) > 500 and
                      any("RLL2SRV_P 1.25" in x for x in s["# lines"]),
                      "the console run has angle lines, csv rows and the parameter replies")
            checks.ok(a[2] is not None and a[2] == b[2] and a[2] != b"\xff" * len(a[2]),
                      "the EEPROM written by `save` is the same")
        else:
            s = streams(a[0])
            checks.ok(len(s.get("MAVLink 30", [])) > 500 and s.get("MAVLink 65"),
                      "the flight run has ATTITUDE, RC_CHANNELS and SERVO_OUTPUT_RAW frames")

    # The controls (make big links them beside the image): what the checks above must catch.
    for control, key, what, build in ([] if args.no_controls else CONTROLS):
        path = os.path.join(os.path.dirname(big) if build is None else os.path.join(args.tools, build, "big"),
                            control + ".elf")
        if not os.path.exists(path):
            checks.ok(False, "the control %s exists" % path, "build it: make big")
            continue
        c = Checks(quiet=True)
        check_placement(Elf(path), c)
        code, err, data, _, _ = run_sim(args.tools, path, args.work, "console." + control, args.seconds, None,
                                        RUNS[0][3])
        reference = base_output["console"]
        if build is not None:  # against that build's own image, unpadded
            _, _, reference, _, _ = run_sim(args.tools, os.path.join(args.tools, build, "firmware.elf"), args.work,
                                            "console." + build, args.seconds, None, RUNS[0][3])
        diffs = compare_outputs(reference, data)
        checks.ok(key in c.failed_keys and diffs, "the control %s (%s) is caught: by the check of %s and "
                  "by the console run (%s)" % (control, what, key, diffs[0][:90] + "..." if diffs else "no difference"),
                  "failed checks: %s" % (", ".join(sorted(c.failed_keys)) or "none"))
    return checks


# Broken images the test must catch: (the ELF beside the padded one, the check that must
# fail, what is wrong with it, the build it comes from: None the firmware's, else the build
# folder whose firmware.elf its console run is compared with).
CONTROLS = [("no-trampolines", "words", "linked with --no-stubs: code addresses above 128 KB wrap round", None),
            ("progmem-high", "progmem", "padding before the PROGMEM data, whose end lies above 64 KB (the "
             "attitude-only build: the firmware and the padding overflow the 2560)", "attitude-only")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check")
    c.add_argument("elf")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    c = sub.add_parser("run")
    c.add_argument("--tools", required=True, help="build directory: apm25sim, scenario, firmware.elf, big/")
    c.add_argument("--work", required=True)
    c.add_argument("--base", help="the firmware (default TOOLS/firmware.elf)")
    c.add_argument("--big", help="the padded firmware (default TOOLS/big/firmware.elf)")
    c.add_argument("--seconds", type=float, default=20.0, help="simulated seconds of each run")
    c.add_argument("--no-controls", action="store_true", help="without the controls beside --big (make big's)")
    args = ap.parse_args()
    if args.cmd == "check":
        checks = Checks()
        check_placement(Elf(args.elf), checks)
    elif args.cmd == "compare":
        checks = Checks()
        diffs = compare_outputs(read(args.a) or b"", read(args.b) or b"")
        checks.ok(not diffs, "the serial outputs are the same but for timing", "; ".join(diffs))
    else:
        checks = cmd_run(args)
    print("%d passed, %d failed" % (checks.passed, checks.failed))
    return 1 if checks.failed else 0


if __name__ == "__main__":
    sys.exit(main())
