"""Small geometry helpers for the scripts that generate the example grooms (Python 3 standard
library only): vectors, quad-grid meshes written as OBJ, guides written as Cem Yuksel's .hair, and
seeded surface sampling. Every script writes the same files on every run and machine."""

import math
import struct


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return mul(a, 1.0 / n) if n > 0.0 else a


def rotate(v, axis, angle):
    """v turned by `angle` radians about the unit vector `axis` (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return add(add(mul(v, c), mul(cross(axis, v), s)), mul(axis, dot(axis, v) * (1.0 - c)))


def smoothstep(t):
    t = min(max(t, 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


class Grid:
    """A mesh of (rows + 1) x (cols + 1) vertices joined by quads, each quad in a named group.
    Vertex (i, j) is at index i * (cols + 1) + j. `wrap` joins the last column to the first."""

    def __init__(self, rows, cols, wrap=False):
        self.rows, self.cols, self.wrap = rows, cols, wrap
        self.width = cols if wrap else cols + 1
        self.quads = []  # (a, b, c, d, group)
        self.extra_faces = []  # (vertex indices, group): caps

    def index(self, i, j):
        return i * self.width + (j % self.width if self.wrap else j)

    def add_quads(self, group_of):
        for i in range(self.rows):
            for j in range(self.cols):
                a, b = self.index(i, j), self.index(i, j + 1)
                c, d = self.index(i + 1, j + 1), self.index(i + 1, j)
                self.quads.append((a, b, c, d, group_of(i, j)))

    def faces(self):
        for a, b, c, d, group in self.quads:
            yield (a, b, c, d), group
        for face, group in self.extra_faces:
            yield face, group

    def triangles(self):
        """The triangles Plume's reader makes of the faces (fans about the first corner), with groups."""
        for face, group in self.faces():
            for k in range(1, len(face) - 1):
                yield (face[0], face[k], face[k + 1]), group


def write_obj(path, positions, grid, comment):
    """An OBJ with the grid's faces grouped by `usemtl` (Plume's face groups), 4 decimals."""
    lines = ["# " + line for line in comment.splitlines()]
    lines += ["v %.4f %.4f %.4f" % p for p in positions]
    current = None
    for face, group in grid.faces():
        if group != current:
            lines.append("usemtl " + group)
            current = group
        lines.append("f " + " ".join(str(v + 1) for v in face))
    with open(path, "w", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


def write_hair(path, strands, info):
    """Cem Yuksel's .hair: a 128-byte header, u16 segments per strand, f32 points."""
    point_count = sum(len(s) for s in strands)
    header = b"HAIR" + struct.pack("<IIII", len(strands), point_count, 1 | 2, 0)
    header += struct.pack("<f f 3f", 0.0, 1.0, 1.0, 1.0, 1.0)
    header += info.encode("ascii")[:87].ljust(88, b"\0")
    assert len(header) == 128
    body = struct.pack("<%dH" % len(strands), *[len(s) - 1 for s in strands])
    body += struct.pack("<%df" % (3 * point_count), *[c for s in strands for p in s for c in p])
    with open(path, "wb") as out:
        out.write(header + body)


def triangle_area(a, b, c):
    return 0.5 * norm(cross(sub(b, a), sub(c, a)))


def sample_surface(positions, triangles, count, rng):
    """`count` points on the triangles (area-weighted), as (point, unit face normal, index of the
    triangle in `triangles`)."""
    areas = [triangle_area(positions[t[0]], positions[t[1]], positions[t[2]]) for t in triangles]
    total = sum(areas)
    cumulative, acc = [], 0.0
    for a in areas:
        acc += a
        cumulative.append(acc)
    samples = []
    for _ in range(count):
        r = rng.random() * total
        lo, hi = 0, len(cumulative) - 1
        while lo < hi:
            mid = (lo + hi) // 2
            if cumulative[mid] < r:
                lo = mid + 1
            else:
                hi = mid
        a, b, c = (positions[v] for v in triangles[lo])
        u, v = rng.random(), rng.random()
        if u + v > 1.0:
            u, v = 1.0 - u, 1.0 - v
        point = add(a, add(mul(sub(b, a), u), mul(sub(c, a), v)))
        samples.append((point, unit(cross(sub(b, a), sub(c, a))), lo))
    return samples


def combed_guide(root, normal, comb, length, points, elevation_deg, droop_deg, side_deg=0.0):
    """A guide from `root`: leaving the skin at `elevation_deg` above the tangent plane toward `comb`
    (turned `side_deg` about the normal), bending by `droop_deg` toward the skin (negative: away) over
    its length, in equal segments."""
    normal = unit(normal)
    along = unit(sub(comb, mul(normal, dot(comb, normal))))
    along = rotate(along, normal, math.radians(side_deg))
    bend_axis = unit(cross(normal, along))  # turning `along` about it by a positive angle raises it
    strand, p = [root], root
    for k in range(1, points):
        t = (k - 1) / max(1, points - 2)
        angle = math.radians(elevation_deg - droop_deg * t)
        direction = rotate(along, bend_axis, -angle)
        p = add(p, mul(direction, length / (points - 1)))
        strand.append(p)
    return strand


def spaced(samples, distance, count):
    """The first `count` samples no closer than `distance` to an earlier kept one (dart throwing)."""
    kept, cell = [], {}
    key = lambda p: tuple(int(math.floor(c / distance)) for c in p)
    for sample in samples:
        k = key(sample[0])
        near = [q for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                for q in cell.get((k[0] + dx, k[1] + dy, k[2] + dz), [])]
        if all(norm(sub(sample[0], q)) >= distance for q in near):
            kept.append(sample)
            cell.setdefault(k, []).append(sample[0])
            if len(kept) == count:
                break
    return kept
