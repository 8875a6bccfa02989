#!/usr/bin/env python3
"""scipy's MINPACK Levenberg–Marquardt (least_squares(method="lm")) on the same key-shape problems
as benches/solve.rs: targets are the ξ of a V of N birds (gap 1.05 wingspans, 0.6 back per rank),
the start is that V with each bird moved by 0.3·cos(2.3k) wingspans, unknowns are the N−1 free
longitudinal positions, residuals ξ_i − ξ̂_i, analytic Jacobian. Same stable form of Hummel's g as
src/aero. Prints one line per N with the median wall time of several runs.

Usage: pip install numpy scipy && python3 benches/solve_scipy.py [N ...]
       python3 benches/solve_scipy.py --write-targets DIR N ...   (target files for `formation solve`)
(Unset OPENBLAS_CORETYPE/OPENBLAS_L2_SIZE for this command only, if set, to let numpy pick its
fastest kernel: env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE python3 benches/solve_scipy.py)
"""
import math
import statistics
import sys
import time

import numpy as np
from scipy.optimize import least_squares

A = math.pi / 4
C = 2 / math.pi**2


def pair_terms(x, y):
    """Returns (π²/2)·g for the bird y behind, and (π²/2)·dg/dy (stable forms; x > a)."""
    yy = np.abs(y)
    y2 = yy * yy
    r0 = np.sqrt(x * x + y2)
    xp, xm = x + A, x - A
    rp = np.sqrt(xp * xp + y2)
    rm = np.sqrt(xm * xm + y2)
    dp = A * (2 * x + A) / (rp + r0)
    dm = -A * (2 * x - A) / (rm + r0)
    small = yy < x
    with np.errstate(divide="ignore", invalid="ignore"):
        s_over_y2 = np.where(small, 1 / (rp + xp) + 1 / (rm + xm) - 2 / (r0 + x), (dp + dm) / np.where(y2 > 0, y2, 1))
    q = yy + r0
    d = -np.log1p(dm / q) - np.log1p(dp / q) + s_over_y2 * yy
    a = -np.log1p(-(A / x) ** 2)
    gval = np.where(y > 0, 2 * a - d, d)
    return gval, s_over_y2


def problem(n):
    x = [0.0]
    y = [0.0]
    for k in range(1, n):
        rank = (k + 1) // 2
        side = 1.0 if k % 2 == 1 else -1.0
        x.append(side * rank * 1.05)
        y.append(rank * 0.6 + 0.05 * math.sin(k * 1.7))
    x = np.array(x)
    y = np.array(y)
    guess = y + 0.3 * np.cos(np.arange(n) * 2.3)
    return x, y, guess


def model(x):
    dx = np.abs(x[:, None] - x[None, :])
    np.fill_diagonal(dx, 10.0)  # placeholder, masked below
    mask = ~np.eye(len(x), dtype=bool)
    total = float(np.sum(np.where(mask, -np.log1p(-(A / dx) ** 2), 0.0))) * C  # Σ_i Σ_j g(x,0) = Σ_pairs 2g0

    def e_and_jac(y):
        dy = y[:, None] - y[None, :]  # i behind j
        gval, slope = pair_terms(dx, dy)
        gval = np.where(mask, gval, 0.0) * C
        slope = np.where(mask, slope, 0.0) * C
        e = gval.sum(axis=1)
        jac = -slope
        jac[np.diag_indices_from(jac)] = slope.sum(axis=1)
        return e, jac

    return total, e_and_jac


def solve(n):
    x, y, guess = problem(n)
    total, e_and_jac = model(x)
    xi_hat = e_and_jac(y)[0] / total
    fixed = int(np.argmin(guess))
    free = np.array([i for i in range(n) if i != fixed])

    def full(p):
        yy = guess.copy()
        yy[free] = p
        return yy

    def fun(p):
        return e_and_jac(full(p))[0] / total - xi_hat

    def jac(p):
        return e_and_jac(full(p))[1][:, free] / total

    t = time.perf_counter()
    res = least_squares(fun, guess[free], jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    dt = time.perf_counter() - t
    resid = float(np.linalg.norm(fun(res.x)))
    return dt, resid, res.nfev


def relative_savings_chunked(x, y, rows=500):
    """ξ of a large flock, a block of rows at a time (the dense model needs N² memory)."""
    e = np.zeros(len(x))
    for lo in range(0, len(x), rows):
        hi = min(lo + rows, len(x))
        dx = np.abs(x[lo:hi, None] - x[None, :])
        dy = y[lo:hi, None] - y[None, :]
        mask = dx > 0
        dx = np.where(mask, dx, 10.0)
        gval, _ = pair_terms(dx, dy)
        e[lo:hi] = np.where(mask, gval, 0.0).sum(axis=1) * C
    return e / e.sum()


def write_targets(directory, sizes):
    """Writes DIR/tN.json ({"x", "xi", "y"}: the targets and the perturbed start) for
    `formation solve`, the whole-process side of benches/compare_solve.sh."""
    import json
    import os

    os.makedirs(directory, exist_ok=True)
    for n in sizes:
        x, y, guess = problem(n)
        if n <= 2000:
            total, e_and_jac = model(x)
            xi_hat = e_and_jac(y)[0] / total
        else:
            xi_hat = relative_savings_chunked(x, y)
        with open(os.path.join(directory, f"t{n}.json"), "w") as f:
            json.dump({"x": x.tolist(), "xi": xi_hat.tolist(), "y": guess.tolist()}, f)


def main():
    args = sys.argv[1:]
    if args and args[0] == "--write-targets":
        write_targets(args[1], [int(a) for a in args[2:]])
        return
    sizes = [int(a) for a in args] or [10, 40, 200, 1000]
    for n in sizes:
        runs = 5 if n <= 200 else 1
        times = []
        for _ in range(runs):
            dt, resid, nfev = solve(n)
            times.append(dt)
        print(f"scipy least_squares(method='lm') N={n}: median {statistics.median(times)*1e3:.2f} ms over {runs} run(s), {nfev} evaluations, residual {resid:.1e}")


if __name__ == "__main__":
    main()
