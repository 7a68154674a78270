#!/usr/bin/python3
"""Reads `handlabel export --format dexycb|ho3d` folders the way the datasets' own
toolkits do, and compares every number with the label files, for
tests/apps/export_datasets_test.cc (Debian's /usr/bin/python3 with numpy and yaml):

  DexYCB  as dex-ycb-toolkit reads it: meta.yml (serials, num_frames, mano_sides,
          mano_calib, extrinsics), calibration/intrinsics/<serial>_<W>x<H>.yml
          `color`, extrinsics_<id>/extrinsics.yml (row-major 3x4 camera -> common),
          mano_<id>/mano.yml betas, labels_%06d.npz; pose_m through manopth's
          ManoLayer(use_pca=True, ncomps=45, flat_hand_mean=False) with trans =
          pose_m[48:51], divided by 1000 (the toolkit's MANOLayer), with the frame's
          own betas (mano_betas; mano.yml holds the first label's); joint_2d = K
          joint_3d / z.
  HO3D    as the HO3D repository reads it: pickle.load(f, encoding='latin1')
          (load_pickle_data), cam_orders.txt with np.loadtxt pairing the files with
          index i with camera folder <SEQ><cams_order[i]>, trans_<i>.txt (4x4 camera ->
          common), handJoints3D in OpenGL camera axes (flipped with diag(1, -1, -1)),
          MANO joint order + tips (jointsMapManoToSimple), and the MANO forward pass of
          its vis_HO3D.forwardKinematics: a flat_hand_mean=True MANO given fullpose =
          handPose, trans = handTrans, betas = handBeta (its patched loader appends
          vertices 744, 333, 444, 555, 672 as tips; handJoints3D holds the label's tips,
          the hand model's tip vertices, compared as such).

Written from the toolkits' documented formats and public code; no code is copied.
Usage: dataset_readers.py --model MANO.pkl --labels DIR [--dexycb ROOT] [--ho3d ROOT]
Prints a JSON report of the largest differences (metres, pixels); the C++ test holds
the tolerances.
"""
import argparse
import glob
import json
import os
import pickle
import sys

import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mano_layers import load_mano, manopth_layer, smplx_mano  # noqa: E402

# HO3D's joint order (MANO's 16 + tips thumb, index, middle, ring, pinky) -> SNAP.
JOINTS_MAP_MANO_TO_SIMPLE = [0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12,
                             19, 7, 8, 9, 20]
TIPS = [745, 317, 444, 556, 673]  # a MANO file's fingertips as handlabel loads it
GL_FROM_CV = np.diag([1.0, -1.0, -1.0])


def read_labels(folder):
    labels = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        with open(path) as f:
            label = json.load(f)
        labels[label["frame"]] = label
    return labels


def load_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)


def worst(a, b):
    return float(np.max(np.abs(np.asarray(a, dtype=np.float64) -
                               np.asarray(b, dtype=np.float64))))


def check_dexycb(root, labels, model):
    metas = glob.glob(os.path.join(root, "*", "*", "meta.yml"))
    assert len(metas) == 1, metas
    sequence = os.path.dirname(metas[0])
    meta = load_yaml(metas[0])
    calib = os.path.join(root, "calibration")
    extr = load_yaml(os.path.join(calib, "extrinsics_" + meta["extrinsics"],
                                  "extrinsics.yml"))["extrinsics"]
    betas = np.array(load_yaml(os.path.join(calib, "mano_" + meta["mano_calib"][0],
                                            "mano.yml"))["betas"])
    comps = model["hands_components"][:45]
    out = {"frames": meta["num_frames"], "cameras": len(meta["serials"]),
           "side": meta["mano_sides"][0], "views": 0, "joint_3d": 0.0, "joint_2d_px": 0.0,
           "pose_m_joints": 0.0, "pose_m_vertices": 0.0, "images_exist": True,
           "betas_as_labels": 0.0, "mano_yml_betas": 0.0,
           "WRONG pose_m as full axis-angle": 0.0}
    for serial in meta["serials"]:
        intr_files = glob.glob(os.path.join(calib, "intrinsics", f"{serial}_*x*.yml"))
        color = load_yaml(intr_files[0])["color"]
        k = np.array([[color["fx"], 0, color["ppx"]], [0, color["fy"], color["ppy"]],
                      [0, 0, 1]])
        cam_to_common = np.array(extr[serial]).reshape(3, 4)
        rotation, translation = cam_to_common[:, :3], cam_to_common[:, 3]
        for f in range(meta["num_frames"]):
            label = labels[meta["handlabel_frames"][f]]
            folder = os.path.join(sequence, serial)
            out["images_exist"] &= os.path.isfile(os.path.join(folder, f"color_{f:06d}.jpg"))
            npz = np.load(os.path.join(folder, f"labels_{f:06d}.npz"))
            to_cam = lambda p: (np.asarray(p) - translation) @ rotation  # R^T (p - t)
            joint_3d = npz["joint_3d"][0]
            out["joint_3d"] = max(out["joint_3d"], worst(joint_3d, to_cam(label["keypoints_3d"])))
            uvw = joint_3d.astype(np.float64) @ k.T
            out["joint_2d_px"] = max(out["joint_2d_px"],
                                     worst(npz["joint_2d"][0], uvw[:, :2] / uvw[:, 2:]))
            pose, trans = npz["pose_m"][0, :48].astype(np.float64), npz["pose_m"][0, 48:]
            full = np.concatenate([pose[:3], pose[3:] @ comps])  # PCA -> axis-angle
            # The subject's betas (mano.yml) are the first label's; a fit that shaped the
            # hand per frame gave the others their own, in mano_betas.
            frame_betas = npz["mano_betas"][0].astype(np.float64)
            if f == 0:
                out["mano_yml_betas"] = max(out["mano_yml_betas"],
                                            worst(betas, label["mano"]["betas"]))
            v, j = manopth_layer(model, full, frame_betas, trans.astype(np.float64), False)
            out["pose_m_joints"] = max(out["pose_m_joints"],
                                       worst(j / 1000, to_cam(label["keypoints_3d"])))
            out["pose_m_vertices"] = max(out["pose_m_vertices"],
                                         worst(v / 1000, to_cam(label["vertices"])))
            out["betas_as_labels"] = max(out["betas_as_labels"],
                                         worst(npz["mano_betas"][0], label["mano"]["betas"]))
            v, j = manopth_layer(model, pose, frame_betas, trans.astype(np.float64), True)
            out["WRONG pose_m as full axis-angle"] = max(
                out["WRONG pose_m as full axis-angle"],
                worst(j / 1000, to_cam(label["keypoints_3d"])))
            out["views"] += 1
    return out


def load_pickle_data(path):
    """HO3D's loader: latin1 first; the plain load must give the same arrays."""
    with open(path, "rb") as f:
        data = pickle.load(f, encoding="latin1")
    with open(path, "rb") as f:
        plain = pickle.load(f)
    assert all(np.array_equal(data[key], plain[key]) for key in data), path
    return data


def check_ho3d(root, labels, model):
    calib_dirs = glob.glob(os.path.join(root, "calibration", "*", "calibration"))
    assert len(calib_dirs) == 1, calib_dirs
    calib = calib_dirs[0]
    seq = os.path.basename(os.path.dirname(calib))
    with open(os.path.join(os.path.dirname(calib), "handlabel.json")) as f:
        frames = {entry["fid"]: entry["frame"] for entry in json.load(f)["frames"]}
    orders = np.atleast_1d(np.loadtxt(os.path.join(calib, "cam_orders.txt"))).astype(int)
    out = {"cameras": len(orders), "metas": 0, "joints_3d": 0.0, "fk_joints": 0.0,
           "fk_vertices": 0.0, "fk_label_tips": 0.0,
           "cam_mat": 0.0, "images_exist": True, "WRONG handJoints3D without GL flip": 0.0}
    for i, order in enumerate(orders):
        cam_to_common = np.loadtxt(os.path.join(calib, f"trans_{i}.txt"))
        rotation, translation = cam_to_common[:3, :3], cam_to_common[:3, 3]
        with open(os.path.join(calib, f"cam_{i}_intrinsics.txt")) as f:
            intr = dict(item.split(":") for item in f.read().strip().split(", "))
        folder = os.path.join(root, "train", f"{seq}{order}")
        for fid, frame in sorted(frames.items()):
            label = labels[frame]
            out["images_exist"] &= bool(glob.glob(os.path.join(folder, "rgb", fid + ".*")))
            anno = load_pickle_data(os.path.join(folder, "meta", fid + ".pkl"))
            to_gl = lambda p: ((np.asarray(p) - translation) @ rotation) @ GL_FROM_CV.T
            joints = anno["handJoints3D"].astype(np.float64)
            snap = joints[JOINTS_MAP_MANO_TO_SIMPLE]
            out["joints_3d"] = max(out["joints_3d"], worst(snap, to_gl(label["keypoints_3d"])))
            wrong = snap @ GL_FROM_CV.T  # read as if in OpenCV axes
            out["WRONG handJoints3D without GL flip"] = max(
                out["WRONG handJoints3D without GL flip"],
                worst(wrong, to_gl(label["keypoints_3d"])))
            v, j = smplx_mano(model, anno["handBeta"].astype(np.float64),
                              anno["handPose"][:3].astype(np.float64),
                              anno["handPose"][3:].astype(np.float64),
                              anno["handTrans"].astype(np.float64), True)
            out["fk_joints"] = max(out["fk_joints"], worst(j, joints[:16]))
            out["fk_vertices"] = max(out["fk_vertices"], worst(v, to_gl(label["vertices"])))
            out["fk_label_tips"] = max(out["fk_label_tips"], worst(v[TIPS], joints[16:]))
            k = np.array([[float(intr["fx"]), 0, float(intr["ppx"])],
                          [0, float(intr["fy"]), float(intr["ppy"])], [0, 0, 1]])
            out["cam_mat"] = max(out["cam_mat"], worst(anno["camMat"], k))
            out["metas"] += 1
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--model", required=True)
    parser.add_argument("--labels", required=True)
    parser.add_argument("--dexycb")
    parser.add_argument("--ho3d")
    args = parser.parse_args()
    model = load_mano(args.model)
    labels = read_labels(args.labels)
    report = {"labels": len(labels)}
    if args.dexycb:
        report["dexycb"] = check_dexycb(args.dexycb, labels, model)
    if args.ho3d:
        report["ho3d"] = check_ho3d(args.ho3d, labels, model)
    json.dump(report, sys.stdout, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
