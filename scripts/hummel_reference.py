#!/usr/bin/env python3
"""Reference values of Hummel's g(x, y) and dg/dy at 250 working digits (mpmath), evaluated
with the formula exactly as printed in Klotsman & Tal §5. Writes tests/data/hummel_reference.json,
which tests/aero.rs compares the stable double-precision implementation against.

Usage: pip install mpmath && python3 scripts/hummel_reference.py
"""
import json
import os

import mpmath as mp

mp.mp.dps = 250
A = mp.pi / 4


def g(x, y):
    x = mp.mpf(x)
    y = mp.mpf(y)
    if y == 0:  # the printed formula is 0/0 there; its limit
        return 2 / mp.pi**2 * mp.log(x**2 / ((x - A) * (x + A)))
    r0 = mp.sqrt(x**2 + y**2)
    rm = mp.sqrt((x - A) ** 2 + y**2)
    rp = mp.sqrt((x + A) ** 2 + y**2)
    t = (
        mp.log(x**2 / ((x - A) * (x + A)))
        + 2 * mp.log((x - y + r0) / (x + y + r0))
        - mp.log((x - A - y + rm) / (x - A + y + rm))
        - mp.log((x + A - y + rp) / (x + A + y + rp))
        + (2 * r0 - rp - rm) / y
    )
    return 2 / mp.pi**2 * t


def dgdy(x, y):
    h = mp.mpf("1e-60")
    y = mp.mpf(y)
    return (g(x, y + h) - g(x, y - h)) / (2 * h)


xs = ["0.7854", "0.79", "0.8", "0.9", "1.0", "1.2", "1.6", "2.5", "4.0", "10.0", "40.0", "250.0", "1000.0"]
ys = ["-1e6", "-3e4", "-1000", "-50", "-7.5", "-2.0", "-1.0", "-0.3", "-1e-3", "-1e-9", "0",
      "1e-9", "1e-3", "0.3", "1.0", "2.0", "7.5", "50", "1000", "3e4", "1e6"]
rows = []
for x in xs:
    for y in ys:
        rows.append({"x": float(x), "y": float(y), "g": mp.nstr(g(x, y), 25), "dg_dy": mp.nstr(dgdy(x, y), 25)})
out = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "hummel_reference.json")
with open(out, "w") as f:
    json.dump({"source": "scripts/hummel_reference.py (mpmath, 250 working digits)", "values": rows}, f, indent=1)
print(f"wrote {len(rows)} values to {out}")
