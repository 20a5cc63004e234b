// SPDX-License-Identifier: GPL-3.0-or-later
// The firmware's version: the start-up line says it, AUTOPILOT_VERSION carries it
// (mav::Version, packed as ArduPilot does), with the commit's hash when the build knows
// it (the Makefile writes build/.../git_version.h; the Arduino IDE's build has none:
// zeros).
#pragma once

#define APM25_VERSION_MAJOR 0
#define APM25_VERSION_MINOR 2
#define APM25_VERSION_PATCH 0
#define APM25_STR2(x) #x
#define APM25_STR(x) APM25_STR2(x)
#define APM25_VERSION_TEXT \
    APM25_STR(APM25_VERSION_MAJOR) "." APM25_STR(APM25_VERSION_MINOR) "." APM25_STR(APM25_VERSION_PATCH)

#if defined(__has_include)
#if __has_include("git_version.h")
#include "git_version.h"  // #define APM25_GIT_HASH "0123abcd"
#endif
#endif
#ifndef APM25_GIT_HASH
#define APM25_GIT_HASH ""
#endif
