"""Blender's interpolated hair children on Sintel, timed: the tool groomers use, beside Plume's growth.

Loads Sintel's head (grooms/sintel/sintel.obj) and her 228 guides (sintel_guides.hair, 32 points
each) into a legacy hair particle system of Blender 3.4 (Debian's `blender` package), as its parent
hairs, and asks for interpolated children: 439 per parent (100,092 children, the nearest to
100,000 that Blender's per-parent count gives), 2^5 + 1 = 33 points each (display_step 5: Blender
gives 2^n + 1 points, and 33 is the nearest to Plume's 32 from above). No clump, kink, roughness or
length variation: the plain interpolation Plume's growth also does. Then it times the evaluation of
the particle system (the depsgraph update after a change that redoes the children), median of
repeated runs, with the children and without them (parents only); the children's time is the
difference.

Run (from the repository's root; Blender's own -t sets its threads):

    apt-get install blender            # Debian 12: Blender 3.4
    blender -b --factory-startup -t 2 --python bench/blender_children.py -- [--runs 7] [--children 100000]

bench/vs_blender.sh runs this and Plume's bench_sintel in one go and prints the ratio. The last line
printed is machine-readable:

    BLENDER_CHILDREN children=100092 points=33 threads=2 median_s=... children_s=... points_per_s=...
"""

import argparse
import math
import os
import statistics
import struct
import sys
import time

import bpy
import mathutils

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_obj(path):
    """Vertices and faces of an OBJ (first index of each corner; faces of any size)."""
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith('v '):
                vertices.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith('f '):
                faces.append([int(c.split('/')[0]) - 1 for c in line.split()[1:]])
    return vertices, faces


def read_hair(path):
    """The strands of a Cem Yuksel .hair file, as lists of (x, y, z)."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:4] != b'HAIR':
        sys.exit(f'{path}: not a .hair file')
    hair_count, point_count, flags, default_segments = struct.unpack_from('<IIII', data, 4)
    offset = 128
    if flags & 1:
        segments = struct.unpack_from(f'<{hair_count}H', data, offset)
        offset += 2 * hair_count
    else:
        segments = [default_segments] * hair_count
    if not flags & 2:
        sys.exit(f'{path}: no points')
    points = struct.unpack_from(f'<{3 * point_count}f', data, offset)
    strands, at = [], 0
    for s in segments:
        strands.append([tuple(points[3 * (at + j):3 * (at + j) + 3]) for j in range(s + 1)])
        at += s + 1
    return strands


def main():
    argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
    parser = argparse.ArgumentParser(prog='blender_children.py')
    parser.add_argument('--mesh', default=os.path.join(ROOT, 'grooms/sintel/sintel.obj'))
    parser.add_argument('--guides', default=os.path.join(ROOT, 'grooms/sintel/sintel_guides.hair'))
    parser.add_argument('--children', type=int, default=100000)
    parser.add_argument('--display-step', type=int, default=5, help='children get 2^n + 1 points')
    parser.add_argument('--runs', type=int, default=7)
    args = parser.parse_args(argv)

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    vertices, faces = read_obj(args.mesh)
    guides = read_hair(args.guides)
    keys = len(guides[0])
    if any(len(g) != keys for g in guides):
        sys.exit(f'{args.guides}: Blender parent hairs need one point count; resample the guides first')

    mesh = bpy.data.meshes.new('emitter')
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    obj = bpy.data.objects.new('emitter', mesh)
    bpy.context.collection.objects.link(obj)

    # The parents: the guides as poly splines of a curve object, converted to hair curves whose
    # surface is the head, then to the head's hair particle system (Blender attaches each to the
    # skin point nearest its root). Legacy particle hair is the system with interpolated children.
    curve = bpy.data.curves.new('guides', type='CURVE')
    curve.dimensions = '3D'
    for guide in guides:
        spline = curve.splines.new('POLY')
        spline.points.add(len(guide) - 1)
        spline.points.foreach_set('co', [c for point in guide for c in (*point, 1.0)])
    guide_object = bpy.data.objects.new('guides', curve)
    bpy.context.collection.objects.link(guide_object)
    obj.select_set(False)
    bpy.context.view_layer.objects.active = guide_object
    guide_object.select_set(True)
    bpy.ops.object.convert(target='CURVES')
    hair_curves = bpy.context.view_layer.objects.active
    hair_curves.data.surface = obj
    bpy.ops.curves.convert_to_particle_system()
    bpy.data.objects.remove(hair_curves)
    # Children only on the scalp, as Plume's grooms scatter roots (roots.near_guides: 2.0): the
    # vertices within 2 of a guide's first point weigh 1 in the density group, the others 0.
    scalp = obj.vertex_groups.new(name='scalp')
    near = [i for i, v in enumerate(vertices)
            if any((v[0] - g[0][0]) ** 2 + (v[1] - g[0][1]) ** 2 + (v[2] - g[0][2]) ** 2 <= 4.0 for g in guides)]
    scalp.add(near, 1.0, 'REPLACE')
    obj.particle_systems[0].vertex_group_density = 'scalp'
    settings = obj.particle_systems[0].settings
    settings.display_step = args.display_step
    settings.render_step = args.display_step
    settings.display_percentage = 100
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()

    # The parents' paths start and end where the guides do (co_hair reads the evaluated paths).
    evaluated = obj.evaluated_get(depsgraph)
    psys = evaluated.particle_systems[0]
    last = 2 ** args.display_step
    root_off = tip_off = 0.0
    for i, guide in enumerate(guides):
        root_off = max(root_off, (psys.co_hair(evaluated, particle_no=i, step=0) - mathutils.Vector(guide[0])).length)
        tip_off = max(tip_off, (psys.co_hair(evaluated, particle_no=i, step=last) - mathutils.Vector(guide[-1])).length)
    print(f'parents: {len(psys.particles)} hairs from {len(guides)} guides of {keys} points, attached to the skin: '
          f'roots moved by up to {root_off:.3g} (the guides float above it), tips by up to {tip_off:.3g}')

    per_parent = math.ceil(args.children / len(guides))
    settings.child_type = 'INTERPOLATED'
    settings.child_nbr = per_parent
    settings.rendered_child_count = per_parent
    settings.virtual_parents = 0.0
    settings.clump_factor = 0.0
    settings.roughness_1 = 0.0
    settings.roughness_2 = 0.0
    settings.roughness_endpoint = 0.0
    settings.kink = 'NO'
    settings.child_length = 1.0

    def evaluate_seconds():
        """One evaluation of the particle system, children redone: a child setting is written (its
        update tags the children for recalculation) and the depsgraph updated."""
        settings.child_length = 1.0
        start = time.perf_counter()
        depsgraph.update()
        return time.perf_counter() - start

    evaluate_seconds()  # the first evaluation allocates the caches
    psys = obj.evaluated_get(depsgraph).particle_systems[0]
    child_count = len(psys.child_particles)
    points = 2 ** args.display_step + 1
    evaluated = obj.evaluated_get(depsgraph)
    lowest = min(psys.co_hair(evaluated, particle_no=len(guides) + c, step=0).y for c in range(0, child_count, 97))
    print(f'children: {child_count} interpolated, {points} points each; the lowest child root (of every 97th) at '
          f'y = {lowest:.2f} (the scalp: guide roots from y = {min(g[0][1] for g in guides):.2f})')
    with_children = [evaluate_seconds() for _ in range(args.runs)]

    settings.child_type = 'NONE'
    evaluate_seconds()
    parents_only = [evaluate_seconds() for _ in range(args.runs)]

    median = statistics.median(with_children)
    children_seconds = median - statistics.median(parents_only)
    threads = bpy.context.scene.render.threads
    print(f'evaluation with children: median {median * 1e3:.1f} ms of {args.runs} '
          f'(min {min(with_children) * 1e3:.1f}, max {max(with_children) * 1e3:.1f}); '
          f'parents only {statistics.median(parents_only) * 1e3:.1f} ms')
    print(f'BLENDER_CHILDREN children={child_count} points={points} threads={threads} median_s={median:.6f} '
          f'children_s={children_seconds:.6f} points_per_s={child_count * points / median:.4e}')


main()
