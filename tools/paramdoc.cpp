// SPDX-License-Identifier: GPL-3.0-or-later
// paramdoc: prints the parameter reference, docs/parameters.md, from the parameter table
// (lib/Settings/Params.cpp: each row's name, type, range, default and the words beside it).
//
//   build/paramdoc > docs/parameters.md      (what `make docs` does)
//
// The ctest docs.parameters_current prints it again and fails when the committed file
// differs, so the reference cannot drift from the table. Exit status 1 when a row's words
// cannot go in a markdown table cell (a '|' or a line break) or are missing.
#include <stdio.h>
#include <string.h>

#include "Params.h"

namespace {

// A table cell's text: no '|' (it would end the cell), no line break (the row).
bool cell_safe(const char* s) { return s != nullptr && strpbrk(s, "|\n\r") == nullptr; }

// The row's name with the number's '#' as 'n' ("RC#_MIN" -> "RCn_MIN").
void print_name(const params::RowDoc& r) {
    for (const char* p = r.name; *p != '\0'; ++p) putchar(*p == '#' ? 'n' : *p);
}

}  // namespace

int main() {
    const uint8_t rows = params::row_count();
    printf("# Parameters\n\n");
    printf("<!-- Printed by tools/paramdoc from the parameter table in lib/Settings/Params.cpp: `make docs`\n"
           "     writes this file, and the test docs.parameters_current fails when it is not what the\n"
           "     table says. Edit the table, not this file. -->\n\n");
    printf("The flight settings and the declination as named parameters: the console lists them with\n"
           "`params`, reads one with `get NAME` and changes one with `set NAME VALUE` (`save` keeps it in\n"
           "EEPROM); a ground station sees them as its parameter list (MAVLink PARAM_*), and a value it\n"
           "sets is saved at once. Names are ArduPlane's where ArduPlane has the parameter, and so are\n"
           "their units. A value out of range, a fraction for a whole-number parameter, or end points out\n"
           "of order (MIN <= TRIM <= MAX) are refused and change nothing.\n\n");
    printf("%u parameters in %u rows: a row named with `n` stands for one parameter per number, n as given\n"
           "beside the name (`RCn_MIN` (n 1-8) is RC1_MIN to RC8_MIN). Units: cdeg centi-degrees (4500 is\n"
           "45 degrees, and full throw of a surface), us microseconds of pulse width.\n\n",
           (unsigned)params::count(), (unsigned)rows);
    printf("| name | unit | range | default | description |\n");
    printf("|---|---|---|---|---|\n");
    int status = 0;
    for (uint8_t i = 0; i < rows; ++i) {
        params::RowDoc r;
        params::row_doc(i, r);
        if (!cell_safe(r.display_name) || !cell_safe(r.units) || !cell_safe(r.description) ||
            r.display_name[0] == '\0' || r.description[0] == '\0') {
            fprintf(stderr, "paramdoc: %s: its words are missing or hold '|' or a line break\n", r.name);
            status = 1;
            continue;
        }
        printf("| `");
        print_name(r);
        putchar('`');
        // The numbers as the names spell them: digits, or letters ("COMPASS_OFS_n" (n X-Z)).
        if (r.count > 1 && r.first + r.count - 1 <= 9)
            printf(" (n %u-%u)", (unsigned)r.first, (unsigned)(r.first + r.count - 1));
        else if (r.count > 1)
            printf(" (n %c-%c)", (char)('0' + r.first), (char)('0' + r.first + r.count - 1));
        // ", whole": as the console says when `set` is given a fraction.
        printf(" | %s | %g to %g%s | %g | **%s.** %s |\n", r.units, (double)r.min, (double)r.max,
               params::is_integer(r.type) ? ", whole" : "", (double)r.def, r.display_name, r.description);
    }
    return status;
}
