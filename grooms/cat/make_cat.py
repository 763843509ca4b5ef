#!/usr/bin/env python3
"""Generates the cat example: a cat's back and tail as one closed tube around a spine (42 cm from
the neck to the tail tip, head toward +x, up +y), about 600 fur guides
combed toward the tail, and 24 frames of the cat arching its back and raising its tail (an OBJ
sequence). Python 3 standard library only; the same files on every run.

    python3 grooms/cat/make_cat.py      # writes cat.obj, fur.hair, anim/
"""

import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
from plumegen import (Grid, add, combed_guide, cross, dot, mul, norm, rotate, sample_surface, smoothstep, spaced,  # noqa: E402
                      sub, unit, write_hair, write_obj)

# The spine at rest, neck to tail tip (x, y), cm; the tail starts at index 5.
SPINE = [(15.0, 9.0), (10.0, 10.0), (3.0, 10.3), (-4.0, 10.0), (-10.0, 9.0), (-13.5, 8.2),
         (-17.0, 8.4), (-21.0, 10.0), (-24.0, 13.5), (-25.5, 18.0)]
TAIL_START = 5
RINGS, AROUND = 56, 20
FRAMES = 24


def arch(frame):
    return smoothstep((frame - 4) / 8.0)      # the back arches over frames 4-12


def tail_up(frame):
    return smoothstep((frame - 5) / 7.0)      # the tail rises over frames 5-12


def spine_points(frame):
    """The spine's control points at `frame`: the middle of the back lifted up to 4.5 cm, the tail
    turned up to 35 degrees about its base."""
    points = []
    base = SPINE[TAIL_START]
    for k, (x, y) in enumerate(SPINE):
        if k < TAIL_START:
            y += 4.5 * arch(frame) * math.exp(-((x - 1.0) / 8.0) ** 2)
        else:
            angle = -math.radians(35.0) * tail_up(frame)
            dx, dy = x - base[0], y - base[1]
            x = base[0] + dx * math.cos(angle) - dy * math.sin(angle)
            y = base[1] + dx * math.sin(angle) + dy * math.cos(angle)
            y += 4.5 * arch(frame) * math.exp(-((SPINE[TAIL_START][0] - 1.0) / 8.0) ** 2)
        points.append((x, y, 0.0))
    return points


def catmull_rom(points, t):
    """The uniform Catmull-Rom curve through `points` at t in [0, len - 1]."""
    i = min(int(t), len(points) - 2)
    u = t - i
    p0, p1, p2 = points[max(i - 1, 0)], points[i], points[i + 1]
    p3 = points[min(i + 2, len(points) - 1)]
    return tuple(0.5 * ((2 * b) + (-a + c) * u + (2 * a - 5 * b + 4 * c - d) * u * u + (-a + 3 * b - 3 * c + d) * u ** 3)
                 for a, b, c, d in zip(p0, p1, p2, p3))


def ring_params():
    """Curve parameter of each ring: denser along the tail."""
    params = []
    torso_rings = 30
    for i in range(RINGS + 1):
        if i <= torso_rings:
            params.append(TAIL_START * i / torso_rings)
        else:
            params.append(TAIL_START + (len(SPINE) - 1 - TAIL_START) * (i - torso_rings) / (RINGS - torso_rings))
    return params


def radius(param):
    """Tube radius along the spine: the torso (6 cm), narrowing at the rump into the tail (1.5 to 0.5)."""
    if param <= 3.2:
        return 6.0 - 0.5 * smoothstep((1.0 - param) / 1.0)
    if param <= TAIL_START:
        return 1.5 + 4.5 * (1.0 - smoothstep((param - 3.2) / (TAIL_START - 3.2)))
    return 1.5 - 1.0 * (param - TAIL_START) / (len(SPINE) - 1 - TAIL_START)


def frames_along(centres):
    """Rotation-minimising frames (projection method) along the ring centres: (tangent, n1, n2)."""
    frames = []
    n1 = (0.0, 1.0, 0.0)
    for i, c in enumerate(centres):
        a, b = centres[max(i - 1, 0)], centres[min(i + 1, len(centres) - 1)]
        t = unit(sub(b, a))
        n1 = unit(sub(n1, mul(t, dot(n1, t))))
        frames.append((t, n1, cross(t, n1)))
    return frames


def tube(frame):
    spine = spine_points(frame)
    centres = [catmull_rom(spine, p) for p in ring_params()]
    frames = frames_along(centres)
    positions = []
    for i, (c, (t, n1, n2)) in enumerate(zip(centres, frames)):
        r = radius(ring_params()[i])
        for j in range(AROUND):
            phi = 2.0 * math.pi * j / AROUND   # phi = 0 on top (n1 is up at the neck)
            positions.append(add(c, add(mul(n1, r * math.cos(phi)), mul(n2, r * math.sin(phi)))))
    # The tube's two ends: the chest before the first ring, the tail's tip after the last.
    positions.append(add(centres[0], mul(frames[0][0], -3.0)))
    positions.append(add(centres[-1], mul(frames[-1][0], 0.5)))
    return positions, frames


def grid():
    g = Grid(RINGS, AROUND, wrap=True)
    params = ring_params()

    def group(i, j):
        phi = 2.0 * math.pi * (j + 0.5) / AROUND
        if params[i] >= TAIL_START - 0.3:
            return "tail"
        # The back stops where the rump narrows into the tail: fur combed toward the tail there
        # would run into the hollow where the tail starts.
        if 0.3 <= params[i] <= 3.7 and math.cos(phi) > -0.35:
            return "back"
        return "skin"
    g.add_quads(group)
    chest, tip = (RINGS + 1) * AROUND, (RINGS + 1) * AROUND + 1
    for j in range(AROUND):
        g.extra_faces.append(((g.index(0, j + 1), g.index(0, j), chest), "skin"))
        g.extra_faces.append(((g.index(RINGS, j), g.index(RINGS, j + 1), tip), "tail"))
    return g


def fur(positions, frames, g):
    rng = random.Random(7)
    triangles = list(g.triangles())
    rows = [min(face[0] // AROUND, RINGS) for face, _ in triangles]
    strands = []
    # (group, guides, spacing, length, elevation, droop): the tail is thin and curved, so its fur
    # leaves the skin steeper and bends less, to stay out of it.
    for group, count, spacing, length, elevation, droop in (("back", 420, 0.75, 3.4, 15.0, 12.0),
                                                            ("tail", 200, 0.42, 2.6, 32.0, 4.0)):
        chosen = [k for k, (_, name) in enumerate(triangles) if name == group]
        samples = sample_surface(positions, [triangles[k][0] for k in chosen], 30 * count, rng)
        for root, normal, index in spaced(samples, spacing, count):
            comb = frames[rows[chosen[index]]][0]  # the spine's tangent: toward the tail tip
            strands.append(combed_guide(root, normal, comb, length * (0.85 + 0.3 * rng.random()), 10,
                                        elevation + 4.0 * rng.random(), droop, side_deg=10.0 * (rng.random() - 0.5)))
    return strands


def main():
    g = grid()
    positions, frames = tube(1)
    write_obj(os.path.join(HERE, "cat.obj"), positions, g,
              "A cat's back and tail: one closed tube around a spine, head toward +x.\n"
              "Generated by make_cat.py.")
    write_hair(os.path.join(HERE, "fur.hair"), fur(positions, frames, g), "plume cat fur guides")
    os.makedirs(os.path.join(HERE, "anim"), exist_ok=True)
    for frame in range(1, FRAMES + 1):
        write_obj(os.path.join(HERE, "anim", "cat.%04d.obj" % frame), tube(frame)[0], g,
                  "cat arching, frame %d (make_cat.py)" % frame)


if __name__ == "__main__":
    main()
