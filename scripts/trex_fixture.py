"""Writes the TRex fixtures of tests/trex.rs with NumPy, in TRex's published layout: one .npz per
individual (VIDEO_fishN.npz) holding equal-length arrays X#wcentroid, Y#wcentroid (the body
centre), X, Y (the head), SPEED#wcentroid, time, frame and missing, one element per frame the
individual was tracked in. The birds are those of tests/trackers.rs (a 4-bird V moving right,
25 frames per second); bird 3 is not seen in frame 1 (missing = 1, positions inf) and bird 2 is
first tracked in frame 1 (its arrays start there). `stored/` uses np.savez, `compressed/`
np.savez_compressed (deflate), with frame numbers as integers and as floats.

Usage: python3 scripts/trex_fixture.py tests/data/trex
"""
import os
import sys

import numpy as np

FRAMES, BIRDS = 3, 4


def bird(k, i):
    lat = [0.0, -1.0, 1.0, -2.0][i]
    return 300.0 + 5.0 * k - 14.0 * abs(lat), 200.0 + 22.0 * lat + 0.25 * k


def arrays(i, frame_dtype):
    frames = [k for k in range(FRAMES) if not (i == 2 and k == 0)]
    x = np.array([bird(k, i)[0] for k in frames], dtype=np.float32 if i % 2 else np.float64)
    y = np.array([bird(k, i)[1] for k in frames], dtype=x.dtype)
    missing = np.zeros(len(frames), dtype=np.bool_)
    if i == 3:
        j = frames.index(1)
        missing[j] = True
        x[j] = y[j] = np.inf
    return {
        "X#wcentroid": x,
        "Y#wcentroid": y,
        "X": x + 3.0,
        "Y": y,
        "SPEED#wcentroid": np.full(len(frames), 125.0, dtype=np.float32),
        "time": np.array(frames, dtype=np.float64) / 25.0,
        "frame": np.array(frames, dtype=frame_dtype),
        "missing": missing,
    }


def main():
    out = sys.argv[1]
    for sub, save, frame_dtype in (("stored", np.savez, np.int64), ("compressed", np.savez_compressed, np.float32)):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
        for i in range(BIRDS):
            save(os.path.join(out, sub, f"flock_fish{i}.npz"), **arrays(i, frame_dtype))


if __name__ == "__main__":
    main()
