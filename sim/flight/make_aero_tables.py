#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Prints the lift and drag tables of aircraft/rascal110/rascal110.xml from their formulas.

Lift in angle of attack (Beard & McLain, Small Unmanned Aircraft, Princeton 2012, eq. 4.9):
the linear lift CL0 + CLa a blended by the sigmoid sigma(a) (M = 50, a0 = 0.47 rad) into the
flat plate 2 sign(a) sin^2 a cos a past the stall. Drag: the parasitic CD0 plus the induced
drag CL_lin^2 / (pi e AR) of the linear lift, blended the same way into the flat plate's
CD0 + 2 sin^2 a. The coefficients are the ones cited in the aircraft file; AR is the
Rascal 110's own (b^2 / S). Run it and paste the output when a coefficient changes:

    build/venv/bin/python sim/flight/make_aero_tables.py
"""
import math

CL0, CLA, CD0, OSWALD_E = 0.23, 5.61, 0.043, 0.9
SPAN_M, AREA_M2 = 2.794, 0.7613
M_BLEND, ALPHA0_RAD = 50.0, 0.47
ASPECT_RATIO = SPAN_M ** 2 / AREA_M2


def sigma(alpha):
    a = math.exp(-M_BLEND * (alpha - ALPHA0_RAD))
    b = math.exp(M_BLEND * (alpha + ALPHA0_RAD))
    return (1 + a + b) / ((1 + a) * (1 + b))


def lift(alpha):
    s = sigma(alpha)
    flat = 2 * math.copysign(1.0, alpha) * math.sin(alpha) ** 2 * math.cos(alpha)
    return (1 - s) * (CL0 + CLA * alpha) + s * flat


def drag(alpha):
    s = sigma(alpha)
    induced = (CL0 + CLA * alpha) ** 2 / (math.pi * OSWALD_E * ASPECT_RATIO)
    return (1 - s) * (CD0 + induced) + s * (CD0 + 2 * math.sin(alpha) ** 2)


def alphas_deg():
    out = list(range(-90, -40, 10)) + list(range(-40, -20, 2)) + list(range(-20, 21)) + \
        list(range(22, 42, 2)) + list(range(50, 91, 10))
    return out


def main():
    for name, f in (("lift", lift), ("drag", drag)):
        print("<!-- %s -->" % name)
        for a in alphas_deg():
            r = math.radians(a)
            print("              %8.4f  %8.4f" % (r, f(r)))
    print("<!-- AR = %.3f -->" % ASPECT_RATIO)


if __name__ == "__main__":
    main()
