#!/usr/bin/env python3
"""Writes a dome (half an ellipsoid, semi-axes 30 x 20 x 15 mm, on z = 0) as binary STL.

Usage: dome.py OUT.stl [A B C]   (semi-axes, mm; default 30 20 15)

A convex mesh part whose top is shallow and whose foot is a vertical wall: the
default strategy of a mesh (steep and shallow) finishes it with parallel planes
and waterline levels (bench/plan_only/check.sh).
"""
import math
import struct
import sys

A, B, C = (float(v) for v in (sys.argv[2:5] if len(sys.argv) > 4 else (30, 20, 15)))
RINGS, SEGMENTS = 24, 64


def point(i, j):
    """Ring i (0: the pole, RINGS: the foot), segment j."""
    t = 0.5 * math.pi * i / RINGS
    p = 2 * math.pi * j / SEGMENTS
    return (A * math.sin(t) * math.cos(p), B * math.sin(t) * math.sin(p), C * math.cos(t))


def triangles():
    out = []
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a, b = point(i, j), point(i, j + 1)
            c, d = point(i + 1, j), point(i + 1, j + 1)
            if i > 0:
                out.append((a, c, b))
            out.append((b, c, d))
    centre = (0.0, 0.0, 0.0)
    for j in range(SEGMENTS):
        out.append((centre, point(RINGS, j + 1), point(RINGS, j)))
    return out


def main():
    tris = triangles()
    data = bytearray(80) + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<3f", 0.0, 0.0, 0.0)
        for p in t:
            data += struct.pack("<3f", *p)
        data += b"\0\0"
    open(sys.argv[1], "wb").write(bytes(data))


if __name__ == "__main__":
    main()
