#!/usr/bin/env python3
"""Grooms nobody tuned the growth on: generated scenes of several kinds, regrown and checked.

    bench/hair_probe.py PLUME OUT_DIR [--scene patch|sphere|ringlets|layered] [--seeds 1-11] [--scale 1]
                        [--points 24] [--interpolation YAML]

For each seed, one groom of the chosen kind:
- `patch`: a sine height field (40 x 40 quads, 10 units across, random amplitude and frequencies)
  and 49 guides on a jittered 7 x 7 grid, 16 points each. Their comb turns smoothly across the
  patch, their lengths vary up to 2x, and they curl 1 to 3 turns with a phase that varies across
  the patch.
- `sphere`: a closed sphere (radius 2, 48 x 24 facets) and 60 guides of lengths 0.4 to 1.6 radii
  (4x apart) draped down it from its upper half, each along the same family of swirling curves on
  the sphere, at heights that grow along them and differ from guide to guide.
- `layered`: a bumpy patch and 64 guides combed along one smooth flow, lying over the roots
  downstream (lengths 1.5 to 5 units, over 3x apart), each at a height that grows as the root of
  its distance along the flow, so the longer guides from upstream hover over the shorter ones.
- `ringlets`: a gently curved patch and 49 helical guides on a jittered grid, 2 to 4 turns of
  random radius (up to 0.45 of the guides' spacing), each with its own random phase, lengths up to
  2x apart.
The groom grows 3,000 roots of `--points` points (24) with the format's defaults (streamline, the
separation pass on), or with `--interpolation` appended to its `interpolation:` map (for example
`"separate: false"` for the field alone, or `"method: fur"`). Then `plume regrow --frames 1` and
`plume check --groom --frame 1 --strict --json`; one line per seed: transversal and touching
pairs, points inside the skin, strands at guide roots over the limit, and the check's exit code.
`--scale` multiplies every length (the groom must behave alike in any unit).
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'grooms', 'tools'))
import plumegen as pg  # noqa: E402


def write_patch(seed, scale, folder):
    rng = random.Random(seed)
    cells, size = 40, 10.0
    amp, fx, fy = rng.uniform(0.2, 0.8), rng.uniform(0.3, 0.9), rng.uniform(0.3, 0.9)

    def height(x, y):
        return amp * math.sin(fx * x) * math.cos(fy * y)

    def normal(x, y):
        e = 1e-4
        dx = (height(x + e, y) - height(x - e, y)) / (2 * e)
        dy = (height(x, y + e) - height(x, y - e)) / (2 * e)
        return pg.unit((-dx, 1.0, -dy))

    write_height_patch(os.path.join(folder, 'patch.obj'), height, cells, size, scale, 'bumpy patch, seed %d' % seed)

    side_count, points = 7, 16
    phase0, phase_slope = rng.uniform(0, 2 * math.pi), rng.uniform(0.0, 1.2)
    curl_radius, length_var = rng.uniform(0.0, 0.5), rng.uniform(0.3, 0.7)
    turns, tilt = rng.uniform(1.0, 3.0), rng.uniform(0.3, 1.2)
    guides = []
    for j in range(side_count):
        for i in range(side_count):
            x = -4 + 8 * (i + rng.uniform(-0.3, 0.3)) / (side_count - 1)
            y = -4 + 8 * (j + rng.uniform(-0.3, 0.3)) / (side_count - 1)
            n, root = normal(x, y), (x, height(x, y), y)
            comb_angle = 0.4 * math.sin(0.3 * x + 0.2 * y)
            comb = (math.cos(comb_angle), 0.0, math.sin(comb_angle))
            length = 3.0 * (1 + length_var * math.sin(0.5 * x - 0.4 * y))
            phase = phase0 + phase_slope * (x + y)
            d = pg.unit(pg.add(pg.mul(n, math.cos(tilt)), pg.mul(comb, math.sin(tilt))))
            across = pg.cross(d, n)
            side = pg.unit(across) if pg.norm(across) > 1e-6 else (0, 0, 1)
            up = pg.unit(pg.cross(side, d))
            strand = []
            for k in range(points):
                s = k / (points - 1)
                angle, radius = phase + 2 * math.pi * turns * s, curl_radius * s
                p = pg.add(root, pg.mul(d, s * length))
                p = pg.add(p, pg.add(pg.mul(side, radius * (math.cos(angle) - math.cos(phase))),
                                     pg.mul(up, radius * (math.sin(angle) - math.sin(phase)) + 0.02)))
                p = pg.add(p, pg.mul(n, 0.02 if k > 0 else 0.0))
                strand.append(pg.mul(p, scale))
            guides.append(strand)
    pg.write_hair(os.path.join(folder, 'guides.hair'), guides, 'bumpy patch guides, seed %d' % seed)
    return 1.2


def write_triangles(path, vertices, triangles, comment):
    with open(path, 'w') as f:
        f.write('# %s\n' % comment)
        for v in vertices:
            f.write('v %.9g %.9g %.9g\n' % v)
        for a, b, c in triangles:
            f.write('f %d %d %d\n' % (a + 1, b + 1, c + 1))


def write_height_patch(path, height, cells, size, scale, comment):
    """A square of `cells` x `cells` quads, `size` across, at heights y = height(x, z), as triangles."""
    vertices, triangles = [], []
    for j in range(cells + 1):
        for i in range(cells + 1):
            x, y = -size / 2 + size * i / cells, -size / 2 + size * j / cells
            vertices.append(pg.mul((x, height(x, y), y), scale))
    for j in range(cells):
        for i in range(cells):
            a = j * (cells + 1) + i
            b, c = a + 1, a + cells + 1
            triangles += [(a, c, b), (b, c, c + 1)]
    write_triangles(path, vertices, triangles, comment)


def write_sphere(seed, scale, folder):
    rng = random.Random(seed)
    radius, rings, sectors = 2.0, 24, 48

    def on_sphere(theta, phi, r):
        return (r * math.sin(theta) * math.cos(phi), r * math.cos(theta), r * math.sin(theta) * math.sin(phi))

    vertices = [on_sphere(0.0, 0.0, radius)]
    for i in range(1, rings):
        for j in range(sectors):
            vertices.append(on_sphere(math.pi * i / rings, 2 * math.pi * j / sectors, radius))
    vertices.append(on_sphere(math.pi, 0.0, radius))
    south = len(vertices) - 1

    def ring(i, j):
        return 1 + (i - 1) * sectors + j % sectors

    triangles = []
    for j in range(sectors):
        triangles.append((0, ring(1, j + 1), ring(1, j)))
        triangles.append((south, ring(rings - 1, j), ring(rings - 1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(sectors):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            triangles += [(a, b, c), (a, c, d)]
    write_triangles(os.path.join(folder, 'sphere.obj'), [pg.mul(v, scale) for v in vertices], triangles,
                    'closed sphere, seed %d' % seed)

    swirl, points = rng.uniform(-1.0, 1.0), 16
    roots = []
    while len(roots) < 60:
        theta, phi = math.acos(rng.uniform(math.cos(1.3), math.cos(0.15))), rng.uniform(0, 2 * math.pi)
        if all(math.acos(max(-1.0, min(1.0, pg.dot(on_sphere(theta, phi, 1), on_sphere(t, f, 1))))) > 0.2
               for t, f in roots):
            roots.append((theta, phi))
    guides = []
    for theta0, phi0 in roots:
        length = radius * rng.uniform(0.4, 1.6)
        lift0, lift1 = radius * rng.uniform(0.01, 0.03), radius * rng.uniform(0.05, 0.2)
        strand = [on_sphere(theta0, phi0, radius * 1.0005)]
        sweep = length / radius
        for k in range(1, points):
            s = k / (points - 1)
            theta = min(theta0 + sweep * s, math.pi - 0.3)
            strand.append(on_sphere(theta, phi0 + swirl * (theta - theta0), radius + lift0 + lift1 * s))
        guides.append([pg.mul(p, scale) for p in strand])
    pg.write_hair(os.path.join(folder, 'guides.hair'), guides, 'sphere drape guides, seed %d' % seed)
    return 0.5


def write_ringlets(seed, scale, folder):
    rng = random.Random(seed)
    cells, size, bow = 40, 10.0, rng.uniform(0.0, 0.04)

    def height(x, y):
        return -bow * (x * x + y * y)

    write_height_patch(os.path.join(folder, 'patch.obj'), height, cells, size, scale, 'curved patch, seed %d' % seed)

    side_count, points, spacing = 7, 32, 8.0 / 6
    coil = spacing * rng.uniform(0.15, 0.45)
    guides = []
    for j in range(side_count):
        for i in range(side_count):
            x = -4 + spacing * (i + rng.uniform(-0.25, 0.25))
            y = -4 + spacing * (j + rng.uniform(-0.25, 0.25))
            n = pg.unit((2 * bow * x, 1.0, 2 * bow * y))
            root = (x, height(x, y), y)
            length, turns, phase = rng.uniform(2.0, 4.0), rng.uniform(2.0, 4.0), rng.uniform(0, 2 * math.pi)
            side = pg.unit(pg.cross(n, (0.0, 0.0, 1.0)))
            up = pg.cross(side, n)
            strand = []
            for k in range(points):
                s = k / (points - 1)
                angle, radius = phase + 2 * math.pi * turns * s, coil * min(1.0, 4 * s)
                p = pg.add(root, pg.mul(n, 0.02 + s * length))
                p = pg.add(p, pg.add(pg.mul(side, radius * (math.cos(angle) - math.cos(phase))),
                                     pg.mul(up, radius * (math.sin(angle) - math.sin(phase)))))
                strand.append(pg.mul(p if k > 0 else root, scale))
            guides.append(strand)
    pg.write_hair(os.path.join(folder, 'guides.hair'), guides, 'ringlet guides, seed %d' % seed)
    return 1.0


def write_layered(seed, scale, folder):
    rng = random.Random(seed)
    cells, size = 40, 12.0
    amp, fx, fy = rng.uniform(0.1, 0.6), rng.uniform(0.2, 0.6), rng.uniform(0.2, 0.6)
    turn, hover = rng.uniform(0.1, 0.5), rng.uniform(0.02, 0.4)

    def height(x, y):
        return amp * math.sin(fx * x) * math.cos(fy * y)

    def comb(x, y):
        a = turn * math.sin(0.3 * y + 0.2 * x)
        return math.cos(a), math.sin(a)

    write_height_patch(os.path.join(folder, 'patch.obj'), height, cells, size, scale, 'layered patch, seed %d' % seed)

    side_count, points, spacing = 8, 16, 8.0 / 7
    guides = []
    for j in range(side_count):
        for i in range(side_count):
            x = -5 + spacing * (i + rng.uniform(-0.3, 0.3))
            y = -4 + spacing * (j + rng.uniform(-0.3, 0.3))
            length, step = rng.uniform(1.5, 5.0), 0.002
            track, t = [(x, y, 0.0)], 0.0
            while t < length:
                cx, cy = comb(x, y)
                x, y, t = x + step * cx, y + step * cy, t + step
                track.append((x, y, t))
            strand = []
            for k in range(points):
                px, py, pt = track[round(k / (points - 1) * (len(track) - 1))]
                lift = hover * math.sqrt(pt) if k > 0 else 0.0
                strand.append(pg.mul((px, height(px, py) + lift, py), scale))
            guides.append(strand)
    pg.write_hair(os.path.join(folder, 'guides.hair'), guides, 'layered guides, seed %d' % seed)
    return 1.0


SCENES = {'patch': ('patch.obj', write_patch), 'sphere': ('sphere.obj', write_sphere),
          'ringlets': ('patch.obj', write_ringlets), 'layered': ('patch.obj', write_layered)}


def write_scene(kind, seed, scale, points, folder, interpolation):
    mesh, write = SCENES[kind]
    near_guides = write(seed, scale, folder)
    extra = ', ' + interpolation if interpolation else ''
    groom = os.path.join(folder, 'probe.groom.yaml')
    with open(groom, 'w') as f:
        f.write('plume: 1\nname: probe%d\nemitter: {mesh: %s}\nguides: {file: guides.hair}\n'
                'roots: {count: 3000, seed: %d, near_guides: %.9g}\nstrands: {points: %d}\n'
                'interpolation: {k: 4%s}\noutput: {frames: 1, path: out/hair.####.usda}\n'
                % (seed, mesh, seed, near_guides * scale, points, extra))
    return groom


def seeds_of(text):
    first, _, last = text.partition('-')
    return range(int(first), int(last or first) + 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('plume')
    parser.add_argument('out_dir')
    parser.add_argument('--scene', choices=sorted(SCENES), default='patch')
    parser.add_argument('--seeds', default='1-11')
    parser.add_argument('--points', type=int, default=24)
    parser.add_argument('--scale', type=float, default=1.0)
    parser.add_argument('--interpolation', default='')
    args = parser.parse_args()
    args.plume = os.path.abspath(args.plume)
    print('seed  transversal  touching  inside  guides_over  check_exit')
    for seed in seeds_of(args.seeds):
        folder = os.path.join(args.out_dir, 'seed%d' % seed)
        os.makedirs(folder, exist_ok=True)
        groom = write_scene(args.scene, seed, args.scale, args.points, folder, args.interpolation)
        subprocess.run([args.plume, 'regrow', groom, '--frames', '1', '--no-preview'], cwd=folder, check=True,
                       stdout=subprocess.DEVNULL)
        check = subprocess.run([args.plume, 'check', 'out/hair.0001.usda', '--groom', groom, '--frame', '1',
                                '--strict', '--json'], cwd=folder, stdout=subprocess.PIPE, text=True)
        report = json.loads(check.stdout)
        crossings = report['crossings']
        print('%4d  %11d  %8d  %6d  %11d  %10d' % (seed, crossings['transversal_pairs'], crossings['touching_pairs'],
                                                   report['inside_skin']['points'], report['guides']['over_limit'],
                                                   check.returncode), flush=True)


if __name__ == '__main__':
    main()
