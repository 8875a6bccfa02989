"""Writes a small static (unskinned) bird-like .glb for the --bird-model checks in .ci/run: a
flat fan 4 units across X and 1 along Z, no normals (formation computes them).
Usage: python3 .ci/static_bird.py out.glb"""
import json
import math
import struct
import sys

n = 40
pos = []
for i in range(n):
    a = i / n * 2 * math.pi
    pos += [2 * math.cos(a), 0.1 * math.sin(3 * a), 0.5 * math.sin(a)]
idx = [v for i in range(1, n - 1) for v in (0, i, i + 1)]
b = struct.pack("<%df" % len(pos), *pos)
io = len(b)
b += struct.pack("<%dI" % len(idx), *idx)
g = {
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "name": "bird"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
         "min": [-2, -0.1, -0.5], "max": [2, 0.1, 0.5]},
        {"bufferView": 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
    ],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": io},
        {"buffer": 0, "byteOffset": io, "byteLength": len(idx) * 4},
    ],
    "buffers": [{"byteLength": len(b)}],
}
j = json.dumps(g).encode()
j += b" " * ((4 - len(j) % 4) % 4)
b += b"\0" * ((4 - len(b) % 4) % 4)
total = 12 + 8 + len(j) + 8 + len(b)
with open(sys.argv[1], "wb") as f:
    f.write(b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
            + struct.pack("<I", len(b)) + b"BIN\0" + b)
