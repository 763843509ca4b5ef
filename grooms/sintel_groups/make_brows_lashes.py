#!/usr/bin/env python3
"""Draws the guides of Sintel's eyebrows and upper eyelashes on her head mesh (../sintel/sintel.obj,
Y up, +Z to the front, about 1 unit = 1 cm), for the hair groups of sintel_groups.groom.yaml.
Python 3 standard library only; the same files every run.

    python3 grooms/sintel_groups/make_brows_lashes.py     # writes brows.hair, lashes.hair

- Lashes: the mesh's eyes are holes; each eye's rim is a boundary loop of the mesh. A guide grows
  from every rim vertex of the upper lid (the middle of the loop's upper half), leaving the lid
  nearly along its normal (to the front) and curling up, 0.75 long, fanning out toward the corners.
- Brows: an arched band above each eye, two rows of roots found by casting rays along -Z onto the
  face. A guide leaves the skin at a low angle, combed up at the inner end of the brow and outward
  (toward the temple) along the rest, bending back toward the skin; 0.55 long at the inner end,
  0.4 at the outer.
"""

import collections
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
from plumegen import add, combed_guide, cross, dot, mul, norm, sub, unit, write_hair  # noqa: E402

MESH = os.path.join(HERE, "..", "sintel", "sintel.obj")
LASH_ROOT_UP = 0.12  # how far up the lid from its rim a lash guide grows
LASH_FAN = 0.25  # how much the lashes fan out toward the corners


def read_obj(path):
    positions, triangles = [], []
    with open(path) as obj:
        for line in obj:
            if line.startswith("v "):
                positions.append(tuple(float(c) for c in line.split()[1:4]))
            elif line.startswith("f "):
                face = [int(token.split("/")[0]) - 1 for token in line.split()[1:]]
                for k in range(1, len(face) - 1):
                    triangles.append((face[0], face[k], face[k + 1]))
    return positions, triangles


def face_normal(positions, t):
    a, b, c = (positions[i] for i in t)
    return unit(cross(sub(b, a), sub(c, a)))


def front_normal(n):
    """The face's normals point out of the head, to +Z on the face."""
    return n if n[2] >= 0.0 else mul(n, -1.0)


def boundary_loops(positions, triangles):
    """The mesh's boundary loops, each an ordered list of vertex indices."""
    edges = collections.Counter()
    for t in triangles:
        for k in range(3):
            a, b = t[k], t[(k + 1) % 3]
            edges[(min(a, b), max(a, b))] += 1
    neighbours = collections.defaultdict(list)
    for (a, b), count in sorted(edges.items()):
        if count == 1:
            neighbours[a].append(b)
            neighbours[b].append(a)
    loops, seen = [], set()
    for start in sorted(neighbours):
        if start in seen:
            continue
        loop, previous, current = [start], None, start
        seen.add(start)
        while True:
            following = [n for n in neighbours[current] if n != previous]
            if not following or following[0] == start:
                break
            previous, current = current, following[0]
            if current in seen:
                break
            seen.add(current)
            loop.append(current)
        loops.append(loop)
    return loops


def vertex_normals(positions, triangles):
    sums = [(0.0, 0.0, 0.0)] * len(positions)
    for t in triangles:
        a, b, c = (positions[i] for i in t)
        n = cross(sub(b, a), sub(c, a))  # area-weighted
        for i in t:
            sums[i] = add(sums[i], n)
    return [front_normal(unit(n)) for n in sums]


def cast_front(positions, triangles, x, y):
    """The frontmost point of the mesh at (x, y) (a ray along -Z) and its triangle's normal."""
    best = None
    for t in triangles:
        a, b, c = (positions[i] for i in t)
        # Barycentric coordinates of (x, y) in the triangle's XY projection.
        det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        if abs(det) < 1e-12:
            continue
        u = ((b[1] - c[1]) * (x - c[0]) + (c[0] - b[0]) * (y - c[1])) / det
        v = ((c[1] - a[1]) * (x - c[0]) + (a[0] - c[0]) * (y - c[1])) / det
        w = 1.0 - u - v
        if min(u, v, w) < 0.0:
            continue
        z = u * a[2] + v * b[2] + w * c[2]
        if best is None or z > best[0][2]:
            best = ((x, y, z), front_normal(face_normal(positions, t)))
    return best


def lashes(positions, triangles, eyes, normals):
    strands = []
    for loop in eyes:
        points = [positions[i] for i in loop]
        cx = sum(p[0] for p in points) / len(points)
        cy = sum(p[1] for p in points) / len(points)
        height = max(p[1] for p in points) - min(p[1] for p in points)
        width = max(p[0] for p in points) - min(p[0] for p in points)
        upper = sorted((i for i in loop if positions[i][1] > cy + 0.2 * height), key=lambda i: positions[i][0])
        for i in upper:
            rim = positions[i]
            # The root a little up the lid from the rim vertex, inside the skin's surface rather than
            # on its open edge.
            hit = cast_front(positions, triangles, rim[0], rim[1] + LASH_ROOT_UP)
            root, normal = hit if hit is not None else (rim, normals[i])
            across = (rim[0] - cx) / (0.5 * width)  # -1 .. 1 from one corner to the other
            # To the front and up, fanning out a little toward the corners.
            comb = unit((LASH_FAN * across, 1.0, 0.0))
            strands.append(combed_guide(root, normal, comb, 0.75, 8, elevation_deg=70.0, droop_deg=40.0))
    return strands


def brows(positions, triangles, eyes):
    strands = []
    for loop in eyes:
        points = [positions[i] for i in loop]
        cx = sum(p[0] for p in points) / len(points)
        top = max(p[1] for p in points)
        side = 1.0 if cx > 0.0 else -1.0
        inner, outer = abs(cx) - 1.9, abs(cx) + 2.1
        for row, lift in enumerate((0.55, 0.9)):
            for k in range(8):
                s = k / 7.0
                x = side * (inner + (outer - inner) * s)
                y = top + lift + 0.45 * math.sin(math.pi * min(1.0, 1.15 * s))
                hit = cast_front(positions, triangles, x, y)
                if hit is None:
                    continue
                root, normal = hit
                # Up at the inner end, out toward the temple along the rest.
                turn = min(1.0, s / 0.35)
                comb = unit((side * turn, 1.0 - 0.75 * turn, 0.0))
                length = 0.55 - 0.15 * s
                strands.append(combed_guide(root, normal, comb, length, 6, elevation_deg=22.0, droop_deg=14.0))
    return strands


def main():
    positions, triangles = read_obj(MESH)
    loops = boundary_loops(positions, triangles)
    # The eyes: the two loops in front, above the mouth, a few units across.
    eyes = []
    for loop in loops:
        points = [positions[i] for i in loop]
        c = [sum(p[k] for p in points) / len(points) for k in range(3)]
        width = max(p[0] for p in points) - min(p[0] for p in points)
        if c[2] > 4.0 and c[1] > 28.0 and 2.0 < width < 6.0:
            eyes.append(loop)
    eyes.sort(key=lambda loop: positions[loop[0]][0])
    assert len(eyes) == 2, "expected two eye holes in the mesh, found %d" % len(eyes)
    normals = vertex_normals(positions, triangles)
    lash_strands = lashes(positions, triangles, eyes, normals)
    brow_strands = brows(positions, triangles, eyes)
    write_hair(os.path.join(HERE, "lashes.hair"), lash_strands, "Sintel's upper eyelash guides (make_brows_lashes.py)")
    write_hair(os.path.join(HERE, "brows.hair"), brow_strands, "Sintel's eyebrow guides (make_brows_lashes.py)")
    print("lashes.hair: %d guides, brows.hair: %d guides" % (len(lash_strands), len(brow_strands)))


if __name__ == "__main__":
    main()
