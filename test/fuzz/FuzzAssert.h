// SPDX-License-Identifier: GPL-3.0-or-later
// The fuzz targets' assertion: a broken invariant aborts, which libFuzzer reports as a
// crash and saves with the input that caused it (build/fuzz/crash-*). Not assert():
// it must hold in every build, NDEBUG or not.
#pragma once

#include <cstdlib>

inline void fuzz_assert(bool ok) {
    if (!ok) std::abort();
}
