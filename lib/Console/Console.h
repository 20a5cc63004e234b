// SPDX-License-Identifier: GPL-3.0-or-later
// The serial console: one command per line, answered with "# " lines.
//
//   help                 the command list
//   rate <Hz>            output lines per second, whole number 1..100
//   decl <degrees>       magnetic declination, east positive, -180..180 (2 decimals kept)
//   mode plot|csv|quat|raw|mavlink|quiet
//                        output format (csv prints its header "t_ms,roll,pitch,yaw" first;
//                        quat and raw lines: Format.h; mavlink: MAVLink 2, lib/MavLink)
//   status               sensor health, loop load, overruns, gyro bias, temperature, uptime
//   cal gyro             measure the gyro bias again (keep the board still ~1 s)
//   cal mag              hard iron + scale: turn the board every way for 30 s
//   cal level            AHRS_TRIM_X/Y: the airframe level and still ~1 s
//   cal accel            INS_ACCOFFS/SCAL in six positions: again for each one asked
//   save                 write settings and calibration to EEPROM
//   defaults             back to the defaults (not saved until `save`)
//   flight MODE          the flight mode by name, a mode of lib/Flight/Modes.h (manual,
//                        stabilize, fbwa); the mode switch's next move overrides it
//   arm, disarm          the throttle armed (the pre-arm checks first) or disarmed
//   rc                   the receiver's eight channel widths, us (radio set-up)
//   servo                the eight output widths, us
//   gps                  the GPS: fix, satellites, hDOP, position, speed, course, age, counters
//   params               every parameter (lib/Settings/Params.h) and its value, one a line
//   baro                 the barometer: pressure, temperature, height, climb, counters
//   mission              the mission stored (MissionLink): a command a line
//   get NAME             one parameter
//   set NAME VALUE       set one (range-checked; `save` keeps it)
//
// Anything else (unknown words, bad or out-of-range numbers, extra arguments, a line
// over kLineCapacity characters, control or non-ASCII bytes) is answered with
// "# error: ..." and changes nothing. Commands are case-insensitive; '\r', '\n' or
// "\r\n" end a line; backspace (0x08 or 0x7F) deletes the last character.
//
// Pure C++: the firmware feeds received bytes and executes what comes back; the
// commands that only change settings are executed here (apply_setting) so that the
// host tests cover them.
#pragma once

#include <stdint.h>

#include "Format.h"
#include "Settings.h"
#include "Text.h"

namespace console {

constexpr uint8_t kLineCapacity = 40;  // longest accepted line, characters

enum class CommandId : uint8_t {
    None,      // nothing complete yet (or an empty line)
    Error,     // Command::error says what
    Help,
    Rate,      // value = Hz
    Decl,      // value = hundredths of a degree
    Mode,      // mode
    Status,
    CalGyro,
    CalMag,
    Save,
    Defaults,
    Flight,    // arg = the mode's row in lib/Flight/Modes.h, or kArm, kDisarm
    Show,      // arg = Show*
    Set,       // arg = parameter index, value = the value x kParamScale
    Get,       // arg = parameter index
    CalLevel,  // the level calibration (AHRS_TRIM_X/Y)
    CalAccel,  // the six-position calibration: starts it, or confirms the position asked
};

// Flight's arg for `arm` and `disarm` (the modes' rows are below them).
constexpr uint8_t kArm = 14;
constexpr uint8_t kDisarm = 15;

enum Show : uint8_t { kShowRc = 0, kShowServo = 1, kShowParams = 2, kShowGps = 3, kShowBaro = 4, kShowMission = 5 };
// `set` values are parsed with four decimals (parse_fixed) and carried as integers.
constexpr int32_t kParamScale = 10000;

enum class Error : uint8_t {
    None,
    Unknown,          // not a command
    TooLong,          // line over kLineCapacity
    Garbage,          // control or non-ASCII bytes
    MissingArgument,
    ExtraArgument,
    BadNumber,        // not a number of the expected form
    RateRange,        // not 1..100 or not whole
    DeclRange,        // outside -180..180
    BadMode,          // not plot|csv|quat|raw|mavlink|quiet
    BadCalTarget,     // cal without gyro|mag|level|accel
    UnknownParam,     // get/set of a name the table does not have
    ParamRange,       // set: outside the parameter's range, or not whole for an integer (arg: the index)
    BadFlightMode,    // flight without a mode's name
    NoSuchMode,       // set FLTMODEn to a number that is not a mode the board has (arg: the index)
};

struct Command {
    CommandId id;
    Error error;
    int32_t value;  // Rate: Hz, Decl: hundredths of a degree; Error: further bad lines merged in (CommandQueue)
    fmt::OutputMode mode;
    uint8_t arg;    // Flight, Show, Set, Get, Error ParamRange: see CommandId
};

// Parses one complete line (NUL-terminated, without the line ending).
Command parse_line(const char* line);

// Parses a decimal number "[+-]digits[.digits]" into hundredths, rounding half away
// from zero on the third decimal. False for anything else (empty, letters, "1e3",
// "nan", two points, more than 7 integer digits).
bool parse_centi(const char* s, int32_t& out);
// The same with `decimals` (0..4) decimals kept and at most int_digits integer digits.
bool parse_fixed(const char* s, uint8_t decimals, uint8_t int_digits, int32_t& out);

// Collects bytes into lines and parses them.
class LineReader {
public:
    // Feeds one received byte; returns the command when it ended a line, else None.
    Command feed(uint8_t byte);

private:
    char buf_[kLineCapacity + 1] = {};
    uint8_t len_ = 0;
    bool too_long_ = false;
    bool garbage_ = false;
    bool last_was_cr_ = false;
};

// Replies go out a part at a time: the firmware writes a part only when its output
// queue has room for it and an output line after it, so the queue holds a part, not a
// whole reply (help is ~310 bytes). A part is one "# " line of at most kPartReply bytes
// (with the csv header after `mode csv`'s); the functions below that take `part` write
// nothing and return false past the last one.
constexpr uint8_t kPartReply = 96;

// "# error: <why>\n" for a parse error (part 0), then, when bad lines were merged into
// it (CommandQueue), "# error: <n> more bad lines ..." (part 1).
bool print_error(const Command& c, uint8_t part, const text::Sink* out);
// Help, one line a part.
bool print_help(uint8_t part, const text::Sink* out);
// The whole reply at once (host tests and tools).
void print_error(const Command& c, const text::Sink* out);
void print_help(const text::Sink* out);

// Executes Rate, Decl, Mode, Defaults, Set and Get on `s` and writes the reply; returns
// false (and touches nothing) for every other command. Defaults keeps nothing:
// calibration too returns to zero bias and unit scale.
bool apply_setting(const Command& c, settings::Settings& s, const text::Sink* out);

// "# NAME VALUE" (floats with four decimals); false past the last parameter: `params`
// writes one a part.
bool print_param(uint16_t index, const settings::Settings& s, const text::Sink* out);

// The reply to `defaults`.
void print_defaults(const text::Sink* out);

// "t_ms,roll,pitch,yaw\n": the csv header (after `mode csv` and at start in csv mode).
text::Flash csv_header();

// "plot", "csv", "quiet", "quat", "raw" or "mavlink".
text::Flash mode_name(fmt::OutputMode m);

// Parsed commands waiting to run, oldest first. The firmware parses input as soon as it
// arrives (so the UART's small receive ring never overflows) but answers a command only
// when its reply has room to go out: a paste of several lines waits here.
//
// A queued command takes 1 byte (id and error or mode), 2 for rate, 3 for decl or for an
// error with merged ones: kBytes = 64 hold 62 help or status commands (each ~300 bytes
// of reply, 26 ms of the UART: a paste of the whole command set seven times over), 31
// rates or 21 decls, whose replies (13..20 bytes) go out nearly as fast as their lines
// (9..15 bytes) arrive, so that pastes of ~75 rate or ~60 decl lines fit. Garbage makes
// an error line (~50 bytes of reply) for every ~20 bytes received wherever its line ends
// are close, faster than the UART answers: beyond kErrorBytes (40) a bad line is merged
// (below), so that a stream of random bytes with commands between (the console's e2e
// tests) never crowds out a command.
class CommandQueue {
public:
    static constexpr uint8_t kBytes = 64;  // a power of two (index wrap by mask)
    // Once this many bytes are queued, a bad line is merged into the newest item if that
    // is an error (its value counts them) instead of taking a byte: garbage that makes
    // more errors than the UART can answer one by one (a line end every few bytes) never
    // crowds out a command (the last 24 bytes hold 8 of any kind), and replies keep the
    // order of the lines.
    static constexpr uint8_t kErrorBytes = kBytes - 8 * 3;

    // True when a command of some kind might not fit: stop reading input.
    bool full() const { return (uint8_t)(kBytes - used_) < kMaxItem; }
    static constexpr uint8_t kMaxItem = 6;  // a set: id, index, value (int32)
    bool empty() const { return count_ == 0; }
    uint8_t size() const { return count_; }  // commands
    // False (nothing stored) when c does not fit; an error beyond kErrorBytes is merged (true).
    bool push(const Command& c);
    // The oldest command; call only when not empty.
    Command pop();
    // The oldest command, left in place; call only when not empty.
    Command peek() const { return decode(head_); }

private:
    // First byte: the id in the low 4 bits (kMergedError: an error with a 16-bit count of
    // merged ones after it), the error, the mode or the arg (Flight, Show) in the high 4;
    // then rate (1 byte), decl (int16, little-endian), get (the index) or set (the index,
    // the value as int32), values parse_line keeps within those ranges.
    static constexpr uint8_t kMergedError = 0x0F;
    static constexpr uint8_t kMask = kBytes - 1u;
    static uint8_t item_bytes(uint8_t first);
    uint8_t byte(uint8_t at) const { return items_[at & kMask]; }
    uint16_t word(uint8_t at) const { return (uint16_t)(byte(at) | (uint16_t)((uint16_t)byte((uint8_t)(at + 1u)) << 8)); }
    void put_word(uint8_t at, uint16_t v) {
        items_[at & kMask] = (uint8_t)(v & 0xFFu);
        items_[(uint8_t)(at + 1u) & kMask] = (uint8_t)(v >> 8);
    }
    Command decode(uint8_t at) const;

    uint8_t items_[kBytes] = {};
    uint8_t head_ = 0;    // the oldest command's first byte
    uint8_t used_ = 0;    // bytes
    uint8_t newest_ = 0;  // the newest command's first byte
    uint8_t count_ = 0;   // commands
};

}  // namespace console
