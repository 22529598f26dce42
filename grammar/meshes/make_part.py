#!/usr/bin/env python3
"""Writes grammar/meshes/part.stl: the part the bundled task grammar/gripper_part.toml
closes around, a round-ended peg lying across the gripper's closing plane (standing in
for a part exported from CAD).

The peg is a capsule: its axis along y from y = -0.6 to y = 0.6 at x = 0, z = 0.5, radius
0.22, tessellated with SEGMENTS around the axis and RINGS per hemispherical cap. It is
closed (every edge in exactly two triangles, opposite directions), so foldsynth treats it
as a solid: a facet may neither come near its surface nor lie inside it.

Standard library only; the output is deterministic (same bytes on every machine), so the
task's digest is stable. Run from anywhere:

    python3 grammar/meshes/make_part.py

To use a mesh from CAD instead: export the part as STL (ASCII or binary) or OBJ, in the
task's units (the gripper's G0 crease is 1 unit long), and name it in the task file
(`[[obstacles]] shape = "mesh"`, `file = "..."`, optionally `scale` and `translate`).
"""
import math
import os

SEGMENTS = 16   # around the axis
RINGS = 4       # latitude rings per hemispherical cap
RADIUS = 0.22
HALF_LENGTH = 0.6   # of the straight part, along y
CENTER = (0.0, 0.0, 0.5)


def rings():
    """Latitude rings from the -y pole to the +y pole: (y, radius) of each ring."""
    out = []
    for k in range(1, RINGS + 1):  # -y cap, pole excluded
        a = -math.pi / 2 + k * (math.pi / 2) / RINGS
        out.append((-HALF_LENGTH + RADIUS * math.sin(a), RADIUS * math.cos(a)))
    for k in range(0, RINGS):  # +y cap, pole excluded
        a = k * (math.pi / 2) / RINGS
        out.append((HALF_LENGTH + RADIUS * math.sin(a), RADIUS * math.cos(a)))
    return out


def vertices():
    cx, cy, cz = CENTER
    pts = [(cx, cy - HALF_LENGTH - RADIUS, cz)]  # -y pole
    for y, r in rings():
        for s in range(SEGMENTS):
            phi = 2 * math.pi * s / SEGMENTS
            pts.append((cx + r * math.cos(phi), cy + y, cz + r * math.sin(phi)))
    pts.append((cx, cy + HALF_LENGTH + RADIUS, cz))  # +y pole
    return pts


def triangles():
    n_rings = 2 * RINGS
    ring = lambda i, s: 1 + i * SEGMENTS + (s % SEGMENTS)
    last = 1 + n_rings * SEGMENTS
    tris = []
    for s in range(SEGMENTS):  # -y pole fan (outward normals point to -y)
        tris.append((0, ring(0, s), ring(0, s + 1)))
    for i in range(n_rings - 1):
        for s in range(SEGMENTS):
            a, b = ring(i, s), ring(i, s + 1)
            c, d = ring(i + 1, s), ring(i + 1, s + 1)
            tris.append((a, c, b))
            tris.append((b, c, d))
    for s in range(SEGMENTS):  # +y pole fan
        tris.append((last, ring(n_rings - 1, s + 1), ring(n_rings - 1, s)))
    return tris


def normal(p, q, r):
    u = [q[i] - p[i] for i in range(3)]
    v = [r[i] - p[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    l = math.sqrt(sum(c * c for c in n))
    return [c / l for c in n]


def main():
    pts = vertices()
    lines = ["solid part"]
    for t in triangles():
        p, q, r = (pts[i] for i in t)
        n = normal(p, q, r)
        lines.append("  facet normal %.9e %.9e %.9e" % tuple(n))
        lines.append("    outer loop")
        for v in (p, q, r):
            lines.append("      vertex %.9e %.9e %.9e" % v)
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append("endsolid part")
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "part.stl")
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote %s: %d triangles" % (path, len(triangles())))


if __name__ == "__main__":
    main()
