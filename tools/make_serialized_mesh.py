#!/usr/bin/env python3
"""Writes tests/data/mitsuba/meshes/quads.serialized: a Mitsuba .serialized file (format
version 3, written from the format description in Mitsuba 3's documentation of its
`serialized` shape plugin) with two shapes, each a unit quad of two triangles in z = 0:
shape 0 float32 with vertex normals (+z) and uvs, shape 1 float64 without normals, shifted
by +2 in x. Used by the malformed-input catalogue (truncated copies) and the loader tests.

Usage: python3 tools/make_serialized_mesh.py
"""
import pathlib
import struct
import zlib

OUT = pathlib.Path(__file__).resolve().parent.parent / "tests/data/mitsuba/meshes/quads.serialized"


def shape(flags, positions, normals, uvs, faces, real):
    body = struct.pack("<I", flags) + struct.pack("<QQ", len(positions), len(faces))
    for group in (positions, normals, uvs):
        for v in group or []:
            body += struct.pack("<" + real * len(v), *v)
    for f in faces:
        body += struct.pack("<III", *f)
    return struct.pack("<HH", 0x041C, 3) + zlib.compress(body)


quad = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
faces = [(0, 1, 2), (0, 2, 3)]
s0 = shape(0x1000 | 0x1 | 0x2, quad, [(0, 0, 1)] * 4, [(0, 0), (1, 0), (1, 1), (0, 1)], faces, "f")
s1 = shape(0x2000, [(x + 2, y, z) for x, y, z in quad], None, None, faces, "d")
data = s0 + s1 + struct.pack("<II", 0, len(s0)) + struct.pack("<I", 2)
OUT.write_bytes(data)
print(f"wrote {OUT} ({len(data)} bytes; shape 1 at offset {len(s0)})")
