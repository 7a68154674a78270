#!/usr/bin/python3
"""Reads a `handlabel export --format glb` file as a glTF 2.0 viewer does (Khronos
glTF 2.0 specification: GLB container, accessors, node hierarchy, skins with inverse
bind matrices, morph targets applied before skinning, animation samplers) and poses the
mesh at every keyframe, for tests/apps/export_command_test.cc. Written with numpy
alone; compares the posed vertices and joint nodes with the label files.

Usage: gltf_reader.py --glb FILE --labels DIR
Prints a JSON report; the C++ test holds the tolerances.
"""
import argparse
import glob
import json
import os
import struct
import sys

import numpy as np

COMPONENTS = {5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF" and version == 2 and length == len(data), "GLB header"
    json_length, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    document = json.loads(data[20:20 + json_length])
    bin_at = 20 + json_length
    bin_length, bin_type = struct.unpack_from("<I4s", data, bin_at)
    assert bin_type == b"BIN\0"
    return document, data[bin_at + 8:bin_at + 8 + bin_length]


def accessor(document, binary, index):
    a = document["accessors"][index]
    view = document["bufferViews"][a["bufferView"]]
    dtype = COMPONENTS[a["componentType"]]
    width = WIDTH[a["type"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    values = np.frombuffer(binary, dtype=dtype, count=a["count"] * width, offset=start)
    return values.reshape(a["count"], width).astype(np.float64)


def quaternion_matrix(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def local_matrix(node, rotation=None, translation=None):
    m = np.eye(4)
    r = rotation if rotation is not None else node.get("rotation", [0, 0, 0, 1])
    t = translation if translation is not None else node.get("translation", [0, 0, 0])
    m[:3, :3] = quaternion_matrix(np.asarray(r, dtype=np.float64))
    m[:3, 3] = t
    return m


def pose_at_key(document, binary, key):
    """Each node's animated local values at keyframe `key` (the sampler's key-th
    output: the keyframe times are the samplers' inputs)."""
    animation = document["animations"][0]
    values = {}
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        times = accessor(document, binary, sampler["input"])[:, 0]
        output = accessor(document, binary, sampler["output"])
        target = channel["target"]
        if target["path"] == "weights":
            count = output.size // len(times)
            values[(target["node"], "weights")] = output.reshape(len(times), count)[key]
        else:
            values[(target["node"], target["path"])] = output[key]
    return values, len(times)


def world_matrices(document, values):
    nodes = document["nodes"]
    world = {}

    def visit(index, parent):
        node = nodes[index]
        world[index] = parent @ local_matrix(node, values.get((index, "rotation")),
                                             values.get((index, "translation")))
        for child in node.get("children", []):
            visit(child, world[index])

    for root in document["scenes"][document.get("scene", 0)]["nodes"]:
        visit(root, np.eye(4))
    return world


def posed_vertices(document, binary, values, world):
    mesh_node = next(i for i, n in enumerate(document["nodes"]) if "skin" in n)
    node = document["nodes"][mesh_node]
    primitive = document["meshes"][node["mesh"]]["primitives"][0]
    skin = document["skins"][node["skin"]]
    positions = accessor(document, binary, primitive["attributes"]["POSITION"])
    weights = values.get((mesh_node, "weights"))
    for w, target in zip(weights, primitive.get("targets", [])):
        if w != 0:
            positions = positions + w * accessor(document, binary, target["POSITION"])
    inverse_binds = accessor(document, binary, skin["inverseBindMatrices"])
    joint_matrices = [np.linalg.inv(world[mesh_node]) @ world[j] @
                      inverse_binds[k].reshape(4, 4).T  # column-major
                      for k, j in enumerate(skin["joints"])]
    joints = accessor(document, binary, primitive["attributes"]["JOINTS_0"]).astype(int)
    skin_weights = accessor(document, binary, primitive["attributes"]["WEIGHTS_0"])
    homogeneous = np.hstack([positions, np.ones((len(positions), 1))])
    out = np.zeros((len(positions), 3))
    for v in range(len(positions)):
        m = sum(skin_weights[v, k] * joint_matrices[joints[v, k]] for k in range(4))
        out[v] = (m @ homogeneous[v])[:3]
    return out, [world[j][:3, 3] for j in skin["joints"]], skin_weights


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--glb", required=True)
    parser.add_argument("--labels", required=True)
    args = parser.parse_args()
    document, binary = read_glb(args.glb)
    labels = []
    for path in sorted(glob.glob(os.path.join(args.labels, "*.json"))):
        with open(path) as f:
            labels.append(json.load(f))
    labels.sort(key=lambda label: label["frame"])
    report = {"vertices": 0.0, "joints_native": 0.0, "weight_sums": 0.0}
    _, keys = pose_at_key(document, binary, 0)
    report["keyframes"] = keys
    report["morph_targets"] = len(document["meshes"][0]["primitives"][0]["targets"])
    for key, label in enumerate(labels[:keys]):
        values, _ = pose_at_key(document, binary, key)
        world = world_matrices(document, values)
        vertices, joints, weights = posed_vertices(document, binary, values, world)
        report["vertices"] = max(report["vertices"], float(np.max(np.abs(
            vertices - np.array(label["vertices"])))))
        report["joints_native"] = max(report["joints_native"], float(np.max(np.abs(
            np.array(joints) - np.array(label["joints_native"])))))
        report["weight_sums"] = float(np.max(np.abs(weights.sum(axis=1) - 1)))
    # Without the morph targets the skin alone is what a viewer shows between keys.
    values, _ = pose_at_key(document, binary, 0)
    values = {k: (v * 0 if k[1] == "weights" else v) for k, v in values.items()}
    skin_only, _, _ = posed_vertices(document, binary, values,
                                     world_matrices(document, values))
    report["skin_only_vertices"] = float(np.max(np.abs(
        skin_only - np.array(labels[0]["vertices"]))))
    json.dump(report, sys.stdout, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
