#!/usr/bin/python3
"""Writes metrics_fixture.json: random hand-like point sets and their metrics computed
here with NumPy/SciPy, following POEM's evaluation code (align_w_scale with
scipy.linalg.orthogonal_procrustes; PCK/AUC with np.trapz over np.linspace thresholds),
independently of the C++ code.

Run with /usr/bin/python3:  /usr/bin/python3 make_metrics_fixture.py
"""
import json
import os

import numpy as np
from scipy.linalg import orthogonal_procrustes
from scipy.spatial.transform import Rotation

rng = np.random.default_rng(20261129)


def align_w_scale(truth, pred):
    t1 = truth.mean(0)
    t2 = pred.mean(0)
    a = truth - t1
    b = pred - t2
    s1 = np.linalg.norm(a)
    s2 = np.linalg.norm(b)
    a = a / s1
    b = b / s2
    r, s = orthogonal_procrustes(a, b)
    return (b @ r.T) * s * s1 + t1


def mean_dist(x, y):
    return float(np.mean(np.linalg.norm(x - y, axis=1)))


frames = []
for f in range(6):
    n = 21 if f % 2 == 0 else 50
    truth = rng.normal(0.0, 0.04, (n, 3)) + np.array([0.0, 0.0, 0.6])
    rot = Rotation.from_rotvec(rng.normal(0.0, 0.5, 3)).as_matrix()
    scale = 1.0 + 0.1 * rng.normal()
    pred = scale * truth @ rot.T + rng.normal(0.0, 0.01, 3) + rng.normal(0.0, 0.004, (n, 3))
    if f == 5:
        pred = pred * np.array([-1.0, 1.0, 1.0])  # a mirrored prediction
    pred = np.round(pred, 6)
    truth = np.round(truth, 6)
    frames.append({
        "truth": truth.tolist(),
        "pred": pred.tolist(),
        "mean_error": mean_dist(pred, truth),
        "root_relative_error": mean_dist(pred - pred[0], truth - truth[0]),
        "pa_error": mean_dist(align_w_scale(truth, pred), truth),
    })

# PCK / AUC over a frames x points error matrix, per point then averaged (POEM).
errors = np.round(np.abs(rng.normal(0.0, 0.012, (30, 21))), 6)
val_min, val_max, steps = 0.0, 0.02, 20
thresholds = np.linspace(val_min, val_max, steps)
area_one = np.trapz(np.ones_like(thresholds), thresholds)
pck_per_kp = np.array([[np.mean(errors[:, k] <= t) for t in thresholds]
                       for k in range(errors.shape[1])])
auc = float(np.mean([np.trapz(c, thresholds) / area_one for c in pck_per_kp]))

out = {
    "frames": frames,
    "pck": {
        "errors": errors.tolist(),
        "min": val_min, "max": val_max, "steps": steps,
        "curve": np.mean(pck_per_kp, axis=0).tolist(),
        "auc": auc,
        "pck_at_10mm": float(np.mean([np.mean(errors[:, k] <= 0.01)
                                      for k in range(errors.shape[1])])),
    },
}
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "metrics_fixture.json")
with open(path, "w") as fh:
    json.dump(out, fh)
print("wrote", path)
