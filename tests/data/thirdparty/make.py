"""Writes the FOLD fixtures of tests/verify_thirdparty.rs: our own small files with the
properties of FOLD files from other tools (Origami Simulator's assets/Pleating examples:
a crease pattern in the plane y = 0 labelled foldedForm, float32 coordinates, null fold
angles on boundary edges; folded forms without a crease pattern; a flat-folded state;
no edges_assignment; coordinates rounded to 7 significant digits in a tilted plane).

Run from this directory: python3 make.py (deterministic; the files are committed)."""
import json
import math
import struct


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def g7(x):
    return float(f"{x:.7g}")


def rot(p, axis, ang):
    """Rodrigues: p rotated by ang (right-hand rule) about the unit axis through 0."""
    (x, y, z), (a, b, c) = p, axis
    s, co = math.sin(ang), math.cos(ang)
    kxp = (b * z - c * y, c * x - a * z, a * y - b * x)
    kdp = a * x + b * y + c * z
    return tuple(p[i] * co + kxp[i] * s + axis[i] * kdp * (1 - co) for i in range(3))


def write(name, doc):
    with open(name, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


# A 3x3-vertex sheet (2 x 2 units): centre vertex 4, the x-line 3-4-5 and the y-line 1-4-7.
GRID = [(float(i % 3), float(i // 3), 0.0) for i in range(9)]
FACES = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
EDGES = [[0, 1], [1, 2], [2, 5], [5, 8], [8, 7], [7, 6], [6, 3], [3, 0],  # boundary
         [3, 4], [4, 5], [1, 4], [4, 7]]                                # creases
BOUNDARY = 8


def fold_upper(ang):
    """The half y > 1 turned by ang about the x-line (valley positive, see src/geom.rs)."""
    out = []
    for (x, y, z) in GRID:
        if y > 1:
            q = rot((x - 1, y - 1, z), (1.0, 0.0, 0.0), ang)
            out.append((q[0] + 1, q[1] + 1, q[2]))
        else:
            out.append((x, y, z))
    return out


def angles(ang):
    """Fold angles (degrees) for the x-line folded by ang, the y-line flat."""
    return [None] * BOUNDARY + [math.degrees(ang)] * 2 + [0.0, 0.0]


ASSIGN = ["B"] * BOUNDARY + ["V", "V", "F", "F"]

# 1. Origami Simulator's style: crease pattern in the plane y = 0 (x, z in the sheet),
# labelled foldedForm, float32 coordinates with float32 noise in y, null on boundaries,
# target angles of +-180.
cols, rows = 5, 3
verts, faces, edges, assign, fa = [], [], [], [], []
for r in range(rows):
    for c in range(cols):
        x = -0.7071067690849304 + c * 1.4142135381698608 / (cols - 1)
        z = -0.7071067690849304 + r * 1.4142135381698608 / (rows - 1)
        verts.append([f32(x), f32(1e-22 * (1 + c + r)), f32(z)])
idx = lambda r, c: r * cols + c
for r in range(rows - 1):
    for c in range(cols - 1):
        faces.append([idx(r, c), idx(r + 1, c), idx(r + 1, c + 1), idx(r, c + 1)])
seen = {}
for fc in faces:
    for k in range(4):
        u, v = fc[k], fc[(k + 1) % 4]
        key = (min(u, v), max(u, v))
        if key in seen:
            continue
        seen[key] = len(edges)
        edges.append([u, v])
        (ru, cu), (rv, cv) = divmod(u, cols), divmod(v, cols)
        on_boundary = (cu == cv and cu in (0, cols - 1)) or (ru == rv and ru in (0, rows - 1))
        if on_boundary:
            assign.append("B")
            fa.append(None)
        elif cu == cv:  # a pleat line: mountain, valley, mountain
            a = "M" if cu % 2 == 1 else "V"
            assign.append(a)
            fa.append(-180 if a == "M" else 180)
        else:
            assign.append("F")
            fa.append(0)
write("pleat_in_plane_y0.fold", {
    "file_spec": 1.1, "file_creator": "foldsynth tests (in the style of Origami Simulator)",
    "file_classes": ["singleModel"], "frame_title": "pleats",
    "frame_classes": ["foldedForm"], "frame_attributes": ["3D"], "frame_unit": "unit",
    "vertices_coords": verts, "edges_vertices": edges, "edges_assignment": assign,
    "faces_vertices": faces, "edges_foldAngle": fa,
})

# 2. A folded form only (no crease pattern): the sheet at 90 degrees, then at 120.
write("folded_form_only.fold", {
    "file_spec": 1.2, "file_creator": "foldsynth tests", "frame_classes": ["foldedForm"],
    "frame_attributes": ["3D"], "vertices_coords": [list(p) for p in fold_upper(math.pi / 2)],
    "edges_vertices": EDGES, "edges_assignment": ASSIGN, "faces_vertices": FACES,
    "edges_foldAngle": angles(math.pi / 2),
    "file_frames": [{"frame_classes": ["foldedForm"], "frame_parent": 0, "frame_inherit": True,
                     "vertices_coords": [list(p) for p in fold_upper(2 * math.pi / 3)],
                     "edges_foldAngle": angles(2 * math.pi / 3)}],
})

# 3. A flat-folded state: the upper half folded onto the lower one.
write("flat_folded_state.fold", {
    "file_spec": 1.2, "file_creator": "foldsynth tests", "frame_classes": ["foldedForm"],
    "vertices_coords": [list(p) for p in fold_upper(math.pi)],
    "edges_vertices": EDGES, "edges_assignment": ASSIGN, "faces_vertices": FACES,
    "edges_foldAngle": angles(math.pi),
})

# 4. No edges_assignment: a 2D crease pattern and a folded frame at 60 degrees.
write("no_assignment.fold", {
    "file_spec": 1.2, "file_creator": "foldsynth tests", "frame_classes": ["creasePattern"],
    "vertices_coords": [[p[0], p[1]] for p in GRID], "edges_vertices": EDGES,
    "faces_vertices": FACES,
    "file_frames": [{"frame_classes": ["foldedForm"], "frame_parent": 0, "frame_inherit": True,
                     "vertices_coords": [list(p) for p in fold_upper(math.pi / 3)],
                     "edges_foldAngle": angles(math.pi / 3)}],
})

# 5. 7 significant digits, the sheet in a tilted plane, and a folded frame.
tilt = lambda p: rot(rot(p, (0.0, 1.0, 0.0), 0.7), (1.0, 0.0, 0.0), -0.4)
write("seven_digits_tilted.fold", {
    "file_spec": 1.2, "file_creator": "foldsynth tests", "frame_classes": ["creasePattern"],
    "vertices_coords": [[g7(x) for x in tilt(p)] for p in GRID],
    "edges_vertices": EDGES, "edges_assignment": ASSIGN, "faces_vertices": FACES,
    "edges_foldAngle": angles(math.pi / 4),
    "file_frames": [{"frame_classes": ["foldedForm"], "frame_parent": 0, "frame_inherit": True,
                     "vertices_coords": [[g7(x) for x in tilt(p)] for p in fold_upper(math.pi / 4)],
                     "edges_foldAngle": [None if a is None else g7(a) for a in angles(math.pi / 4)]}],
})
