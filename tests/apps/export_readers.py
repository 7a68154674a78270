#!/usr/bin/python3
"""Reads `handlabel export` files back the way their users' tools do (numpy's CSV
reader, the json module, COCO-WholeBody's field layout as mmpose's hand dataset reads
it) and compares the numbers with the label files, for tests/apps/export_command_test.cc.
The 2D check projects the labels' keypoints itself (pinhole and OpenCV models, the rig
JSON of docs/capture-format.md): an independent implementation of the projection.

Usage: export_readers.py --labels DIR [--csv FILE] [--coco FILE --rig RIG.json]
Prints a JSON report (largest differences, counts); the C++ test holds the tolerances.
"""
import argparse
import csv
import glob
import json
import os
import sys

import numpy as np


def read_labels(folder):
    labels = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        with open(path) as f:
            label = json.load(f)
        labels[label["frame"]] = label
    return labels


def check_csv(path, labels):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names, frames = rows[0], [row[0] for row in rows[1:]]
    coords = np.loadtxt(path, delimiter=",", skiprows=1, usecols=range(2, len(names)),
                        ndmin=2)
    worst = max(float(np.max(np.abs(coords[i].reshape(21, 3) -
                                    np.array(labels[f]["keypoints_3d"]))))
                for i, f in enumerate(frames))
    return {"rows": len(frames), "columns": len(names), "frames_in_order":
            frames == sorted(labels), "first_columns": names[:5], "keypoints_3d": worst}


def quaternion_matrix(x, y, z, w):
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def project(camera, point):
    pose = camera["cam_from_world"]
    p = quaternion_matrix(*pose["rotation_xyzw"]) @ point + np.array(pose["translation"])
    x, y = p[0] / p[2], p[1] / p[2]
    params = camera["params"]
    if camera["model"] == "OPENCV":  # k1, k2 radial, p1, p2 tangential
        k1, k2, p1, p2 = params[4:8]
        r2 = x * x + y * y
        radial = 1 + k1 * r2 + k2 * r2 * r2
        x, y = (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)
    elif camera["model"] != "PINHOLE":
        raise ValueError("this reader projects PINHOLE and OPENCV cameras only")
    return np.array([params[0] * x + params[2], params[1] * y + params[3]]), p[2]


def check_coco(path, rig_path, labels):
    with open(path) as f:
        coco = json.load(f)
    with open(rig_path) as f:
        cameras = {c["name"]: c for c in json.load(f)["cameras"]}
    images = {image["id"]: image for image in coco["images"]}
    side = coco["info"]["hand_side"]
    worst_2d, outside_box, hands = 0.0, 0, 0
    for ann in coco["annotations"]:
        # As mmpose's COCO-WholeBody hand dataset takes a hand: valid and some v > 0.
        kpts = np.array(ann[side + "hand_kpts"], dtype=float).reshape(-1, 3)
        if not ann[side + "hand_valid"] or kpts[:, 2].max() <= 0:
            continue
        hands += 1
        image = images[ann["image_id"]]
        camera = cameras[image["camera"]]
        label = labels[image["frame"]]
        x, y, w, h = ann[side + "hand_box"]
        for k in range(21):
            if kpts[k, 2] == 0:
                continue
            uv, _ = project(camera, np.array(label["keypoints_3d"][k]))
            worst_2d = max(worst_2d, float(np.max(np.abs(uv - kpts[k, :2]))))
            if not (x - 1e-6 <= kpts[k, 0] <= x + w + 1e-6 and
                    y - 1e-6 <= kpts[k, 1] <= y + h + 1e-6):
                outside_box += 1
    files = all(os.path.exists(image["file_name"]) for image in coco["images"])
    return {"images": len(coco["images"]), "hands": hands, "keypoints_2d": worst_2d,
            "keypoints_outside_box": outside_box, "image_files_exist": files,
            "hand_keypoint_names": len(coco["categories"][0]["hand_keypoints"])}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--labels", required=True)
    parser.add_argument("--csv")
    parser.add_argument("--coco")
    parser.add_argument("--rig")
    args = parser.parse_args()
    labels = read_labels(args.labels)
    report = {}
    if args.csv:
        report["csv"] = check_csv(args.csv, labels)
    if args.coco:
        report["coco"] = check_coco(args.coco, args.rig, labels)
    json.dump(report, sys.stdout, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
