#!/usr/bin/env python3
"""Grooms nobody tuned the growth on: bumpy patches of combed, curled guides, regrown and checked.

    bench/hair_probe.py PLUME OUT_DIR [--seeds 1-11] [--scale 1] [--interpolation YAML]

For each seed: a sine height field (40 x 40 quads, 10 units across, random amplitude and
frequencies) and 49 guides on a jittered 7 x 7 grid, 16 points each. Their comb turns smoothly
across the patch, their lengths vary up to 2x, and they curl 1 to 3 turns with a phase that varies
across the patch. The groom grows 3,000 roots of 24 points with the format's defaults (streamline,
the separation pass on), or with `--interpolation` appended to its `interpolation:` map (for
example `"separate: false"` for the field alone, or `"method: fur"`). Then `plume regrow --frames 1`
and `plume check --groom --frame 1 --strict --json`; one line per seed: transversal and touching
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


def write_scene(seed, scale, folder, interpolation):
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

    with open(os.path.join(folder, 'patch.obj'), 'w') as f:
        f.write('# bumpy patch, seed %d\n' % seed)
        for j in range(cells + 1):
            for i in range(cells + 1):
                x, y = -size / 2 + size * i / cells, -size / 2 + size * j / cells
                f.write('v %.9g %.9g %.9g\n' % (x * scale, height(x, y) * scale, y * scale))
        for j in range(cells):
            for i in range(cells):
                a = j * (cells + 1) + i + 1
                b, c = a + 1, a + cells + 1
                f.write('f %d %d %d\nf %d %d %d\n' % (a, c, b, b, c, c + 1))

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

    extra = ', ' + interpolation if interpolation else ''
    groom = os.path.join(folder, 'patch.groom.yaml')
    with open(groom, 'w') as f:
        f.write('plume: 1\nname: probe%d\nemitter: {mesh: patch.obj}\nguides: {file: guides.hair}\n'
                'roots: {count: 3000, seed: %d, near_guides: %.9g}\nstrands: {points: 24}\n'
                'interpolation: {k: 4%s}\noutput: {frames: 1, path: out/hair.####.usda}\n'
                % (seed, seed, 1.2 * scale, extra))
    return groom


def seeds_of(text):
    first, _, last = text.partition('-')
    return range(int(first), int(last or first) + 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('plume')
    parser.add_argument('out_dir')
    parser.add_argument('--seeds', default='1-11')
    parser.add_argument('--scale', type=float, default=1.0)
    parser.add_argument('--interpolation', default='')
    args = parser.parse_args()
    args.plume = os.path.abspath(args.plume)
    print('seed  transversal  touching  inside  guides_over  check_exit')
    for seed in seeds_of(args.seeds):
        folder = os.path.join(args.out_dir, 'seed%d' % seed)
        os.makedirs(folder, exist_ok=True)
        groom = write_scene(seed, args.scale, folder, args.interpolation)
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
