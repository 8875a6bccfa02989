"""Writes tests/data/sleap/flock.analysis.h5 with h5py, in the layout SLEAP's
`sleap-convert --format analysis` writes (its write_tracking_h5 with the default transpose, as
MATLAB reads it): every array is stored transposed and gzip-compressed (level 9, hence chunked),
strings as fixed-length byte strings.

  tracks            float64 (tracks, 2, nodes, frames)   NaN where a node was not found
  track_occupancy   uint8   (tracks, frames)
  point_scores      float64 (tracks, nodes, frames)
  instance_scores   float64 (tracks, frames)
  tracking_scores   float64 (tracks, frames)
  track_names       |S      (tracks,)   b"track_0", ...
  node_names        |S      (nodes,)    b"head", b"tail"
  edge_names        |S      (edges, 2), edge_inds int (edges, 2)
  labels_path, video_path, provenance: scalar strings; video_ind: scalar int

The birds are those of tests/trackers.rs (a 4-bird V moving right): `head` is the bird, `tail`
8 px behind it; bird 3 is not seen in frame 1 (NaN, occupancy 0).

Usage: python3 scripts/sleap_h5_fixture.py tests/data/sleap/flock.analysis.h5
"""
import json
import os
import sys

import h5py
import numpy as np

FRAMES, BIRDS = 3, 4
NODES = ["head", "tail"]


def bird(k, i):
    lat = [0.0, -1.0, 1.0, -2.0][i]
    return 300.0 + 5.0 * k - 14.0 * abs(lat), 200.0 + 22.0 * lat + 0.25 * k


def main():
    out = sys.argv[1]
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    # SLEAP's in-memory layout: (frames, nodes, 2, tracks) and (frames, tracks).
    loc = np.full((FRAMES, len(NODES), 2, BIRDS), np.nan, dtype=np.float64)
    occ = np.zeros((FRAMES, BIRDS), dtype=np.uint8)
    pts = np.full((FRAMES, len(NODES), BIRDS), np.nan, dtype=np.float64)
    inst = np.full((FRAMES, BIRDS), np.nan, dtype=np.float64)
    trk = np.full((FRAMES, BIRDS), np.nan, dtype=np.float64)
    for k in range(FRAMES):
        for i in range(BIRDS):
            if i == 3 and k == 1:
                continue
            x, y = bird(k, i)
            loc[k, 0, :, i] = (x, y)
            loc[k, 1, :, i] = (x - 8.0, y)
            occ[k, i] = 1
            pts[k, :, i] = (0.9, 0.8)
            inst[k, i] = 0.97
            trk[k, i] = 0.95
    data = {
        "track_names": np.array([f"track_{i}".encode() for i in range(BIRDS)], dtype="S"),
        "node_names": np.array([n.encode() for n in NODES], dtype="S"),
        "edge_names": np.array([[b"head", b"tail"]], dtype="S"),
        "edge_inds": np.array([[0, 1]], dtype=np.int64),
        # Transposed as SLEAP does by default.
        "tracks": np.transpose(loc),
        "track_occupancy": np.transpose(occ),
        "point_scores": np.transpose(pts),
        "instance_scores": np.transpose(inst),
        "tracking_scores": np.transpose(trk),
    }
    with h5py.File(out, "w") as f:
        for key, val in data.items():
            f.create_dataset(key, data=val, compression="gzip", compression_opts=9)
        f.create_dataset("labels_path", data="flock.slp")
        f.create_dataset("video_path", data="flock.mp4")
        f.create_dataset("video_ind", data=0)
        f.create_dataset("provenance", data=json.dumps({"sleap_version": "1.3.3"}))


if __name__ == "__main__":
    main()
