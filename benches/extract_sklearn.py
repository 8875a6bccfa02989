#!/usr/bin/env python3
"""scikit-learn's RANSACRegressor on the same line fits as `cargo bench --bench extract`.

Reads the arms written by the bench (CSV: fit,x,y,rust_slope,rust_intercept; one row per
point, formation frame, wingspans), fits each arm with RANSACRegressor(LinearRegression,
residual_threshold=0.5 wingspans, min_samples=2, max_trials=100, random_state=0), times all fits
with time.perf_counter, and compares the slopes with the Rust fits. Prints one JSON line.

Usage: python3 benches/extract_sklearn.py target/extract-bench-arms.csv
"""
import csv
import json
import sys
import time

import numpy as np
import sklearn
from sklearn.linear_model import LinearRegression, RANSACRegressor


def main(path):
    fits = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            k = int(row["fit"])
            d = fits.setdefault(k, {"x": [], "y": [], "slope": float(row["rust_slope"])})
            d["x"].append(float(row["x"]))
            d["y"].append(float(row["y"]))
    arms = [(np.array(d["x"]).reshape(-1, 1), np.array(d["y"]), d["slope"]) for _, d in sorted(fits.items())]
    t0 = time.perf_counter()
    slopes = []
    for x, y, _ in arms:
        r = RANSACRegressor(
            estimator=LinearRegression(),
            residual_threshold=0.5,
            min_samples=2,
            max_trials=100,
            random_state=0,
        )
        r.fit(x, y)
        slopes.append(float(r.estimator_.coef_[0]))
    dt = time.perf_counter() - t0
    diffs = np.abs(np.array(slopes) - np.array([a[2] for a in arms]))
    print(json.dumps({
        "sklearn": sklearn.__version__,
        "fits": len(arms),
        "points": int(sum(len(a[1]) for a in arms)),
        "seconds": dt,
        "us_per_fit": dt / len(arms) * 1e6,
        "median_abs_slope_diff_vs_rust": float(np.median(diffs)),
        "max_abs_slope_diff_vs_rust": float(np.max(diffs)),
    }))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "target/extract-bench-arms.csv")
