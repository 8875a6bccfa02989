#!/usr/bin/env python3
"""Median lateral and longitudinal distance to the nearest bird ahead, in wingspans, of a
footage's frames (a params file from `formation extract`) and of the key shapes of a steady
flight (`formation steady`/`animate` JSON), to compare the spacing of generated flocks with the
footage they learned from (docs/model.md).

Usage: python3 scripts/spacing_medians.py params.json [animation.json ...]
"""
import json
import statistics
import sys


def nearest_ahead(birds):
    """(|dx|, dy) to the nearest bird ahead (smaller y) for every bird but the front-most."""
    out = []
    for i, (xi, yi) in enumerate(birds):
        best = None
        for j, (xj, yj) in enumerate(birds):
            if j == i or yj >= yi:
                continue
            d = (xi - xj) ** 2 + (yi - yj) ** 2
            if best is None or d < best[0]:
                best = (d, abs(xi - xj), yi - yj)
        if best:
            out.append(best[1:])
    return out


def medians(shapes):
    pairs = [p for s in shapes for p in nearest_ahead(s)]
    return statistics.median(p[0] for p in pairs), statistics.median(p[1] for p in pairs), len(shapes), len(shapes[0]) if shapes else 0


def main():
    params = json.load(open(sys.argv[1]))
    footage = [[(p["x"], p["y"]) for p in f["positions"]] for f in params["frames"] if f.get("positions")]
    lat, lon, k, n = medians(footage)
    print(f"footage  {sys.argv[1]}: {k} frames of {n} birds: lateral {lat:.3f}, longitudinal {lon:.3f}")
    for path in sys.argv[2:]:
        anim = json.load(open(path))
        keys = [[(b["x"], b["y"]) for b in ks["birds"]] for ks in anim["key_shapes"]]
        l2, g2, k2, n2 = medians(keys)
        print(f"generated {path}: {k2} key shapes of {n2} birds: lateral {l2:.3f} ({100 * (l2 / lat - 1):+.0f} %), longitudinal {g2:.3f} ({100 * (g2 / lon - 1):+.0f} %)")


if __name__ == "__main__":
    main()
