#!/usr/bin/python3
"""Independent NumPy re-implementations of the MANO forward pass as two public layers
compute it, used to prove what a handlabel label's `mano` fields mean
(docs/exports.md; tests/apps/export_command_test.cc runs this with Debian's
/usr/bin/python3 and numpy, nothing else):

  smplx    smplx.MANO(use_pca=False, flat_hand_mean=F)(betas, global_orient,
           hand_pose, transl): full_pose = [global_orient, hand_pose] + [0, hands_mean
           unless F]; LBS with 4x4 transforms chained from the root; vertices and the 16
           skinned joints (native order), transl added to both; metres.
  manopth  manopth.ManoLayer(use_pca=False, flat_hand_mean=F, center_idx=None)(
           pose_coeffs (48), betas, trans): hand pose = hands_mean (unless F) +
           pose_coeffs[3:]; transforms built level by level (root, then the 5 finger
           bases, middles, ends); joints + fingertip vertices (745, 317, 444, 556, 673;
           445 for the middle finger of a left hand) in SNAP order; trans added;
           millimetres.
  manotorch  manotorch.manolayer.ManoLayer(rot_mode="axisang"|"quat", center_idx=None|j,
           use_pca=False, flat_hand_mean=F)(pose_coeffs, betas): manopth's skinning and
           joints (SNAP order, the same fingertips) in metres, no translation argument
           (add transl to the output), hands_mean added in axisang mode unless F, full
           rotations as (w, x, y, z) quaternions in quat mode, and with center_idx the
           output relative to that joint (center_joint returned).

Written from the layers' documented behaviour and public code; no code is copied.

Usage: mano_layers.py --model MANO_RIGHT.pkl --labels DIR [--npz conv:flat:FILE ...]
Prints a JSON report of the largest differences (metres) for every case; the C++ test
holds the tolerances.
"""
import argparse
import glob
import json
import os
import pickle
import sys

import numpy as np


# ---- reading an official-layout MANO pickle without chumpy or old scipy ----
class _State:
    """Stands in for chumpy.ch.Ch, chumpy.reordering.Select and scipy's csc_matrix:
    keeps the pickled instance dict."""

    def __setstate__(self, state):
        self.__dict__.update(state)


class _ManoUnpickler(pickle.Unpickler):
    STAND_INS = {("chumpy.ch", "Ch"), ("chumpy.reordering", "Select"),
                 ("scipy.sparse.csc", "csc_matrix"), ("scipy.sparse._csc", "csc_matrix")}

    def find_class(self, module, name):
        if (module, name) in self.STAND_INS:
            return type(name, (_State,), {})
        return super().find_class(module, name)


def _dense(value):
    if isinstance(value, np.ndarray):
        return value
    kind = type(value).__name__
    if kind == "Ch":
        return np.asarray(value.x)
    if kind == "Select":  # chumpy's a.r.ravel()[idxs].reshape(preferred_shape)
        return _dense(value.a).ravel()[value.idxs].reshape(value.preferred_shape)
    if kind == "csc_matrix":
        rows, cols = value._shape
        out = np.zeros((rows, cols))
        for c in range(cols):
            for k in range(value.indptr[c], value.indptr[c + 1]):
                out[value.indices[k], c] = value.data[k]
        return out
    raise TypeError(f"unexpected pickled object {kind}")


def load_mano(path):
    with open(path, "rb") as f:
        raw = _ManoUnpickler(f, encoding="latin1").load()
    model = {key: _dense(raw[key]) for key in
             ("v_template", "shapedirs", "posedirs", "J_regressor", "weights",
              "kintree_table", "hands_mean", "f")}
    if "hands_components" in raw:
        model["hands_components"] = _dense(raw["hands_components"])
    parents = model["kintree_table"][0].astype(np.int64)
    parents[0] = -1  # MANO stores the root's parent as 4294967295
    model["parents"] = parents
    return model


def rotation_matrices(axis_angles):
    """(N, 3) axis-angle -> (N, 3, 3), Rodrigues' formula."""
    out = np.empty((len(axis_angles), 3, 3))
    for i, w in enumerate(axis_angles):
        angle = np.linalg.norm(w)
        if angle == 0.0:
            out[i] = np.eye(3)
            continue
        k = w / angle
        cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        out[i] = np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross
    return out


def _shaped(model, betas):
    v_shaped = model["v_template"] + np.einsum("vcb,b->vc", model["shapedirs"],
                                               betas[: model["shapedirs"].shape[2]])
    return v_shaped, model["J_regressor"] @ v_shaped


def _homogeneous(rotation, translation):
    t = np.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = translation
    return t


def _skin(model, world, rest_joints, v_posed):
    """Blends world[j] @ [I | -J_j] by the skinning weights."""
    relative = world.copy()
    relative[:, :3, 3] -= np.einsum("jab,jb->ja", world[:, :3, :3], rest_joints)
    blended = np.einsum("vj,jab->vab", model["weights"], relative)
    return np.einsum("vab,vb->va", blended[:, :3, :3], v_posed) + blended[:, :3, 3]


def smplx_mano(model, betas, global_orient, hand_pose, transl, flat_hand_mean):
    pose_mean = np.zeros(48)
    if not flat_hand_mean:
        pose_mean[3:] = model["hands_mean"]
    full_pose = np.concatenate([global_orient, hand_pose]) + pose_mean
    rotations = rotation_matrices(full_pose.reshape(16, 3))
    v_shaped, rest = _shaped(model, betas)
    pose_feature = (rotations[1:] - np.eye(3)).reshape(-1)
    v_posed = v_shaped + np.einsum("vcp,p->vc", model["posedirs"], pose_feature)
    parents = model["parents"]
    world = np.empty((16, 4, 4))
    for j in range(16):
        offset = rest[j] - (rest[parents[j]] if parents[j] >= 0 else 0.0)
        local = _homogeneous(rotations[j], offset)
        world[j] = local if parents[j] < 0 else world[parents[j]] @ local
    vertices = _skin(model, world, rest, v_posed) + transl
    joints = world[:, :3, 3] + transl
    return vertices, joints


MANOPTH_SNAP_ORDER = [0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12, 19,
                      7, 8, 9, 20]


def _level_chain(model, rotations, betas, side):
    """manopth's and manotorch's skinning: transforms built level by level (root, then
    the 5 finger bases, middles, ends); joints + fingertip vertices in SNAP order;
    metres, no translation."""
    v_shaped, rest = _shaped(model, betas)
    pose_map = (rotations[1:] - np.eye(3)).reshape(-1)
    v_posed = v_shaped + model["posedirs"] @ pose_map
    world = np.empty((16, 4, 4))
    world[0] = _homogeneous(rotations[0], rest[0])
    for level in range(3):  # finger bases, middles, ends: joints 1 + 3f + level
        for finger in range(5):
            j = 1 + 3 * finger + level
            parent = 0 if level == 0 else j - 1
            world[j] = world[parent] @ _homogeneous(rotations[j], rest[j] - rest[parent])
    vertices = _skin(model, world, rest, v_posed)
    tips = [745, 317, 444, 556, 673] if side == "right" else [745, 317, 445, 556, 673]
    joints = np.concatenate([world[:, :3, 3], vertices[tips]])[MANOPTH_SNAP_ORDER]
    return vertices, joints


def manopth_layer(model, pose_coeffs, betas, trans, flat_hand_mean, side="right"):
    hands_mean = np.zeros(45) if flat_hand_mean else model["hands_mean"]
    full_pose = np.concatenate([pose_coeffs[:3], hands_mean + pose_coeffs[3:48]])
    vertices, joints = _level_chain(model, rotation_matrices(full_pose.reshape(16, 3)),
                                    betas, side)
    if np.linalg.norm(trans) != 0:  # manopth adds trans only when it is not zero
        joints = joints + trans
        vertices = vertices + trans
    return 1000.0 * vertices, 1000.0 * joints


def quaternion_matrices(quaternions):
    """(N, 4) quaternions, real part first (w, x, y, z) -> (N, 3, 3)."""
    out = np.empty((len(quaternions), 3, 3))
    for n, (w, x, y, z) in enumerate(quaternions):
        s = 2.0 / (w * w + x * x + y * y + z * z)
        out[n] = [[1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
                  [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
                  [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)]]
    return out


def manotorch_layer(model, pose_coeffs, betas, flat_hand_mean, center_idx=None,
                    rot_mode="axisang", side="right"):
    """manotorch.manolayer.ManoLayer(rot_mode, center_idx, use_pca=False,
    flat_hand_mean)(pose_coeffs, betas): axisang adds hands_mean unless flat_hand_mean
    (48 values); quat takes 16 (w, x, y, z) quaternions as full rotations. No
    translation argument; metres; with center_idx, verts and joints minus that joint
    (returned as center_joint), else unshifted."""
    if rot_mode == "quat":
        rotations = quaternion_matrices(np.asarray(pose_coeffs).reshape(16, 4))
    else:
        hands_mean = np.zeros(45) if flat_hand_mean else model["hands_mean"]
        full_pose = np.concatenate([pose_coeffs[:3], hands_mean + pose_coeffs[3:48]])
        rotations = rotation_matrices(full_pose.reshape(16, 3))
    vertices, joints = _level_chain(model, rotations, betas, side)
    center = joints[center_idx] if center_idx is not None else np.zeros(3)
    return vertices - center, joints - center, center


def quaternions_wxyz(axis_angles):
    """(N, 3) axis-angle -> (N, 4) unit quaternions (w, x, y, z)."""
    out = np.empty((len(axis_angles), 4))
    for n, w in enumerate(axis_angles):
        angle = np.linalg.norm(w)
        axis = w / angle if angle > 0 else np.zeros(3)
        out[n] = [np.cos(angle / 2), *(np.sin(angle / 2) * axis)]
    return out


SNAP_FROM_NATIVE = [0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12, 19, 7,
                    8, 9, 20]


def keypoints_from_smplx(model, vertices, joints):
    """smplx's MANO returns no fingertips: the label's 21 keypoints are its 16 joints
    plus the model's tip vertices (manopth's for a MANO file), in SNAP order."""
    tips = vertices[[745, 317, 444, 556, 673]]
    return np.concatenate([joints, tips])[SNAP_FROM_NATIVE]


def label_cases(model, label):
    """Every (layer, flat_hand_mean) fed the label's parameters by the documented rule,
    plus the wrong rules a user could guess. Returns name -> (vertices, keypoints, joints)
    in metres (joints: the 16 native joints, None for manopth)."""
    mano = label["mano"]
    go, pose = np.array(mano["global_orient"]), np.array(mano["hand_pose"])
    betas, transl = np.array(mano["betas"]), np.array(mano["transl"])
    mean = model["hands_mean"]
    cases = {}
    for flat in (True, False):
        layer_pose = pose if flat else pose - mean  # the documented rule
        v, j = smplx_mano(model, betas, go, layer_pose, transl, flat)
        cases[f"smplx flat_hand_mean={flat}"] = (v, keypoints_from_smplx(model, v, j), j)
        v, k = manopth_layer(model, np.concatenate([go, layer_pose]), betas, transl, flat)
        cases[f"manopth flat_hand_mean={flat}"] = (v / 1000, k / 1000, None)
    for flat in (True, False):  # manotorch: no transl argument, add it to the output
        layer_pose = pose if flat else pose - mean
        v, k, _ = manotorch_layer(model, np.concatenate([go, layer_pose]), betas, flat)
        cases[f"manotorch flat_hand_mean={flat}"] = (v + transl, k + transl, None)
    # center_idx=9 (the middle MCP, a common choice): the output is relative to that
    # joint; center_joint + transl puts it back.
    v, k, center = manotorch_layer(model, np.concatenate([go, pose]), betas, True, 9)
    cases["manotorch center_idx=9"] = (v + center + transl, k + center + transl, None)
    quats = quaternions_wxyz(np.concatenate([go, pose]).reshape(16, 3))
    v, k, _ = manotorch_layer(model, quats.ravel(), betas, True, rot_mode="quat")
    cases["manotorch rot_mode=quat"] = (v + transl, k + transl, None)
    # Wrong guesses: hands_mean added once more, or manopth's output taken as metres,
    # or manotorch's centred output moved by transl alone.
    cases["WRONG manotorch center_idx=9 output + transl"] = (
        cases["manotorch center_idx=9"][0] - center,
        cases["manotorch center_idx=9"][1] - center, None)
    v, j = smplx_mano(model, betas, go, pose, transl, False)
    cases["WRONG smplx flat_hand_mean=False given the label's hand_pose"] = (
        v, keypoints_from_smplx(model, v, j), j)
    v, k = manopth_layer(model, np.concatenate([go, pose]), betas, transl, True)
    cases["WRONG manopth output read as metres"] = (v, k, None)
    return cases


def npz_cases(model, spec):
    """conv:flat:file -> feed the export's own parameter arrays to that layer."""
    convention, flat, path = spec.split(":", 2)
    flat = flat == "true"
    data = np.load(path)
    assert str(data["mano_convention"]) == convention, path
    assert bool(data["flat_hand_mean"]) == flat, path
    out = {}
    for i, frame in enumerate(data["frames"]):
        if not data["has_mano"][i]:
            continue
        if convention == "smplx":
            v, j = smplx_mano(model, data["betas"][i], data["global_orient"][i],
                              data["hand_pose"][i], data["transl"][i], flat)
            k = keypoints_from_smplx(model, v, j)
        elif convention == "manotorch":  # no translation argument: add transl after
            v, k, _ = manotorch_layer(model, data["pose_coeffs"][i], data["betas"][i],
                                      flat)
            v, k, j = v + data["transl"][i], k + data["transl"][i], None
        else:
            v, k = manopth_layer(model, data["pose_coeffs"][i], data["betas"][i],
                                 data["transl"][i], flat)
            v, k, j = v / 1000, k / 1000, None
        out[str(frame)] = (v, k, j, data["vertices"][i], data["keypoints_3d"][i])
    return f"npz {convention} flat_hand_mean={flat}", out


def max_diff(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--model", required=True)
    parser.add_argument("--labels", required=True)
    parser.add_argument("--npz", action="append", default=[])
    args = parser.parse_args()
    model = load_mano(args.model)
    labels = {}
    for path in sorted(glob.glob(os.path.join(args.labels, "*.json"))):
        with open(path) as f:
            label = json.load(f)
        if label["mano"] is not None:
            labels[label["frame"]] = label
    report = {"labels": len(labels), "cases": {}}

    def record(name, v, k, j, label):
        case = report["cases"].setdefault(name, {"vertices": 0.0, "keypoints_3d": 0.0,
                                                 "joints_native": 0.0})
        case["vertices"] = max(case["vertices"], max_diff(v, label["vertices"]))
        case["keypoints_3d"] = max(case["keypoints_3d"],
                                   max_diff(k, label["keypoints_3d"]))
        if j is not None:
            case["joints_native"] = max(case["joints_native"],
                                        max_diff(j, label["joints_native"]))

    for frame, label in labels.items():
        for name, (v, k, j) in label_cases(model, label).items():
            record(name, v, k, j, label)
    for spec in args.npz:
        name, frames = npz_cases(model, spec)
        if set(frames) != set(labels):
            print(f"{spec}: frames {sorted(frames)} differ from the labels'",
                  file=sys.stderr)
            return 1
        for frame, (v, k, j, npz_v, npz_k) in frames.items():
            record(name, v, k, j, labels[frame])
            record(name + " arrays", npz_v, npz_k, None, labels[frame])
    json.dump(report, sys.stdout, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
