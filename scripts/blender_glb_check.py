"""Run inside Blender (scripts/check-blender-glb does): imports a `handlabel export
--format glb` file with Blender's own glTF importer, counts the animation's keyframes
and poses the mesh at each of them as Blender evaluates it (armature, skin, shape
keys), then compares every vertex with the label of that keyframe.

Usage: blender -b --factory-startup --python scripts/blender_glb_check.py -- \
           --glb FILE --labels DIR [--fps 30]
Prints one JSON line starting with BLENDER_GLB_CHECK (metres; the shell script holds
the tolerances).
"""
import argparse
import glob
import json
import os
import sys

import bpy
import numpy
from mathutils import Vector

# Debian 12's Blender 3.4 glTF importer still says `np.bool`, which Debian's numpy 1.24
# removed (the import then fails in set_poly_smoothing): give the old alias back.
if "bool" not in numpy.__dict__:
    numpy.bool = numpy.bool_


def read_labels(folder):
    labels = []
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        with open(path) as f:
            labels.append(json.load(f))
    return sorted(labels, key=lambda label: label["frame"])


def keyframes():
    """Every keyframe position of every imported action."""
    frames = set()
    for action in bpy.data.actions:
        for curve in action.fcurves:
            frames.update(round(k.co.x, 4) for k in curve.keyframe_points)
    return sorted(frames)


def from_gltf(p):
    """The importer turns glTF's +Y up into Blender's +Z up: (x, y, z) -> (x, -z, y)."""
    return Vector((p[0], -p[2], p[1]))


def posed_errors(mesh, label):
    """Distance of every vertex of the mesh as Blender poses it now (world space) from
    the label's vertex."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = mesh.evaluated_get(depsgraph)
    posed = evaluated.to_mesh()
    world = evaluated.matrix_world
    errors = [((world @ v.co) - from_gltf(label["vertices"][i])).length
              for i, v in enumerate(posed.vertices)]
    evaluated.to_mesh_clear()
    return errors


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    parser = argparse.ArgumentParser()
    parser.add_argument("--glb", required=True)
    parser.add_argument("--labels", required=True)
    parser.add_argument("--fps", type=int, default=30)
    args = parser.parse_args(argv)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = args.fps  # keyframe k / fps seconds lands on a whole frame
    bpy.ops.import_scene.gltf(filepath=args.glb)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    labels = read_labels(args.labels)
    frames = keyframes()
    mesh = meshes[0]
    report = {"blender": bpy.app.version_string, "meshes": len(meshes),
              "armatures": sum(o.type == "ARMATURE" for o in scene.objects),
              "actions": len(bpy.data.actions), "keyframes": len(frames),
              "labels": len(labels), "vertices": len(mesh.data.vertices),
              "max_vertex_error": 0.0, "vertex_0_error": 0.0, "first_frames": frames[:3]}
    for frame, label in zip(frames, labels):
        whole = int(frame // 1)
        scene.frame_set(whole, subframe=frame - whole)
        errors = posed_errors(mesh, label)
        report["max_vertex_error"] = max(report["max_vertex_error"], max(errors))
        report["vertex_0_error"] = max(report["vertex_0_error"], errors[0])
    # The same comparison without the shape keys (the skin alone) must fail: it shows
    # the check can tell a wrong pose from a right one.
    for block in mesh.data.shape_keys.key_blocks:
        block.mute = True
    scene.frame_set(int(frames[0] // 1), subframe=frames[0] % 1)
    report["skin_only_max_error"] = max(posed_errors(mesh, labels[0]))
    print("BLENDER_GLB_CHECK " + json.dumps(report))


main()
