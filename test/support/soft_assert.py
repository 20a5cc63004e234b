# SPDX-License-Identifier: GPL-3.0-or-later
"""Non-fatal assertions for the Python tests: a failed soft_assert records its reason and
the test goes on, so that one run lists every failure; finish() prints them and returns
the exit status (1 if any failed)."""

failures = []


def soft_assert(cond, what):
    """Records `what` as a failure unless cond holds; returns cond as a bool."""
    if not cond:
        failures.append(what)
    return bool(cond)


def finish(title, ok_message):
    if failures:
        print("%s: %d failure(s)" % (title, len(failures)))
        for f in failures:
            print("  " + f)
        return 1
    print(ok_message)
    return 0
