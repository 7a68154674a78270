#!/usr/bin/env python3
"""Compares handlabel's MediaPipe Hands (`handlabel detect --images`) with MediaPipe's own
runtime (tools/browser/mediapipe-peer.mjs) on the same images.

  mediapipe-compare.py parity OURS_DIR PEER_DIR [--report FILE]
      Per image: palms (box and keypoints, pixels), the ROIs made from them (centre and
      size in pixels, rotation), landmarks in pixels of the 224x224 crop, handedness score,
      and whether a hand is reported at all (the peer exposes the presence score only
      through that threshold). Exit 1 when a tolerance is exceeded.
  mediapipe-compare.py bench OURS_DIR PEER_DIR ANNOTATIONS.json [ANNOTATIONS.json ...]
      PCK@0.2 and normalised error per image against COCO-style 2D ground truth, for both,
      and their times per image.

Both folders hold <index>.json per image (same image order) and summary.json.
Only the standard library: runs wherever python3 does."""
import argparse
import json
import math
import os
import sys

TOL_LANDMARK_CROP_PX = 0.5
TOL_SCORE = 1e-3
TOL_PALM_PX = 1.0
CROP = 224


def load_dir(folder):
    records = []
    i = 0
    while os.path.exists(os.path.join(folder, f"{i}.json")):
        with open(os.path.join(folder, f"{i}.json")) as f:
            records.append(json.load(f))
        i += 1
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    return records, summary


def left_prob(handedness):
    """Probability of MediaPipe's label 'Left' (mirrored convention)."""
    return handedness["score"] if handedness["label"] == "Left" else 1.0 - handedness["score"]


def palm_px(palm, w, h):
    b = palm["box"]
    box = [b["xmin"] * w, b["ymin"] * h, b["width"] * w, b["height"] * h]
    kps = [(k[0] * w, k[1] * h) for k in palm["keypoints"]]
    return box, kps


def palm_diff(ours, peer, w, h):
    box_a, kp_a = palm_px(ours, w, h)
    box_b, kp_b = palm_px(peer, w, h)
    box = max(abs(a - b) for a, b in zip(box_a, box_b))
    kp = max(math.dist(a, b) for a, b in zip(kp_a, kp_b))
    return box, kp


def roi_size_px(roi, w, h):
    return math.sqrt(roi["width"] * w * roi["height"] * h)


def landmark_crop_diff(ours_hand, peer_hand, w, h):
    """Max landmark distance in crop pixels (224 across our ROI)."""
    scale = CROP / roi_size_px(ours_hand["roi"], w, h)
    worst = 0.0
    for a, b in zip(ours_hand["landmarks_norm"], peer_hand["landmarks_norm"]):
        d = math.hypot((a[0] - b[0]) * w, (a[1] - b[1]) * h) * scale
        worst = max(worst, d)
    return worst


def match_by_order_or_nearest(ours, peer, centre):
    """Pairs items of two lists (best first in both): nearest centre, greedily."""
    pairs = []
    used = set()
    for i, a in enumerate(ours):
        best, best_d = None, float("inf")
        for j, b in enumerate(peer):
            if j in used:
                continue
            d = math.dist(centre(a), centre(b))
            if d < best_d:
                best, best_d = j, d
        if best is not None:
            used.add(best)
            pairs.append((i, best))
    return pairs


def parity(args):
    ours, ours_summary = load_dir(args.ours)
    peer, peer_summary = load_dir(args.peer)
    if len(ours) != len(peer):
        sys.exit(f"mediapipe-compare: {len(ours)} images in {args.ours}, {len(peer)} in {args.peer}")
    max_hands = peer_summary.get("max_hands", 2)
    rows = []
    worst = {"palm_box_px": 0.0, "palm_keypoint_px": 0.0, "roi_px": 0.0, "roi_rotation_rad": 0.0,
             "landmark_crop_px": 0.0, "handedness": 0.0}
    failures = []
    compared = {"palms": 0, "hands": 0}
    for i, (o, p) in enumerate(zip(ours, peer)):
        w, h = o["width"], o["height"]
        name = os.path.basename(o["image"])
        if (w, h) != (p["width"], p["height"]):
            failures.append(f"{name}: size {w}x{h} vs peer {p['width']}x{p['height']}")
            continue
        o_palms = o["palms"][:max_hands]
        p_palms = p["palm_detections"]
        row = {"image": name, "palms": [len(o_palms), len(p_palms)],
               "hands": [len(o["hands"]), len(p["hands"])]}
        if len(o_palms) != len(p_palms):
            failures.append(f"{name}: {len(o_palms)} palms, peer {len(p_palms)}")
        centre = lambda q: (q["box"]["xmin"] * w + q["box"]["width"] * w / 2,
                            q["box"]["ymin"] * h + q["box"]["height"] * h / 2)
        for a, b in match_by_order_or_nearest(o_palms, p_palms, centre):
            box, kp = palm_diff(o_palms[a], p_palms[b], w, h)
            worst["palm_box_px"] = max(worst["palm_box_px"], box)
            worst["palm_keypoint_px"] = max(worst["palm_keypoint_px"], kp)
            compared["palms"] += 1
            row.setdefault("palm_box_px", []).append(round(box, 4))
            if box > TOL_PALM_PX or kp > TOL_PALM_PX:
                failures.append(f"{name}: palm {a} box {box:.3f} px, keypoints {kp:.3f} px")
        # ROIs from palms: ours are the hands' ROIs of the first max_hands palms.
        p_rois = p.get("palm_rois", [])
        hcentre = lambda q: (q["landmarks_norm"][0][0] * w, q["landmarks_norm"][0][1] * h)
        if len(o["hands"]) != len(p["hands"]):
            failures.append(f"{name}: {len(o['hands'])} hands reported, peer {len(p['hands'])} "
                            f"(presence {[round(x['presence'], 4) for x in o['hands']]})")
        for a, b in match_by_order_or_nearest(o["hands"], p["hands"], hcentre):
            oh, ph = o["hands"][a], p["hands"][b]
            # The peer's ROI for this hand: the palm ROI nearest ours.
            if p_rois:
                roi = oh["roi"]
                near = min(p_rois, key=lambda r: math.hypot((r["x_center"] - roi["x_center"]) * w,
                                                            (r["y_center"] - roi["y_center"]) * h))
                d_roi = max(math.hypot((near["x_center"] - roi["x_center"]) * w,
                                       (near["y_center"] - roi["y_center"]) * h),
                            abs(roi_size_px(near, w, h) - roi_size_px(roi, w, h)))
                d_rot = abs(math.remainder(near["rotation"] - roi["rotation"], 2 * math.pi))
                worst["roi_px"] = max(worst["roi_px"], d_roi)
                worst["roi_rotation_rad"] = max(worst["roi_rotation_rad"], d_rot)
                row.setdefault("roi_px", []).append(round(d_roi, 4))
            lm = landmark_crop_diff(oh, ph, w, h)
            hd = abs(left_prob(oh["handedness"]) - left_prob(ph["handedness"]))
            worst["landmark_crop_px"] = max(worst["landmark_crop_px"], lm)
            worst["handedness"] = max(worst["handedness"], hd)
            compared["hands"] += 1
            row.setdefault("landmark_crop_px", []).append(round(lm, 4))
            row.setdefault("handedness_diff", []).append(round(hd, 6))
            row.setdefault("presence_ours", []).append(round(oh["presence"], 5))
            if lm > TOL_LANDMARK_CROP_PX:
                failures.append(f"{name}: hand {a} landmarks differ by {lm:.3f} crop px")
            if hd > TOL_SCORE:
                failures.append(f"{name}: hand {a} handedness differs by {hd:.2e}")
        rows.append(row)
    for r in rows:
        print(json.dumps(r))
    print(f"images {len(ours)}, palms compared {compared['palms']}, hands compared "
          f"{compared['hands']}")
    print("worst: " + ", ".join(f"{k} {v:.4g}" for k, v in worst.items()))
    print(f"tolerances: landmarks {TOL_LANDMARK_CROP_PX} crop px, handedness {TOL_SCORE}, "
          f"palm boxes {TOL_PALM_PX} px")
    if args.report:
        with open(args.report, "w") as f:
            json.dump({"rows": rows, "worst": worst, "compared": compared,
                       "failures": failures}, f, indent=1)
    if failures:
        print("FAIL:\n  " + "\n  ".join(failures))
        return 1
    print("PASS")
    return 0


def load_annotations(paths):
    """basename -> (keypoints [(x, y, v)], box size) from COCO-style files."""
    truth = {}
    for path in paths:
        with open(path) as f:
            coco = json.load(f)
        names = {im["id"]: im["file_name"] for im in coco["images"]}
        for ann in coco["annotations"]:
            k = ann["keypoints"]
            kps = [(k[3 * i], k[3 * i + 1], k[3 * i + 2]) for i in range(21)]
            x, y, w, h = ann["bbox"]
            truth[os.path.basename(names[ann["image_id"]])] = (kps, max(w, h), (x, y, w, h))
    return truth


def box_iou(a, b):
    ix = min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0])
    iy = min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1])
    inter = max(ix, 0) * max(iy, 0)
    union = a[2] * a[3] + b[2] * b[3] - inter
    return inter / union if union > 0 else 0.0


def score_hand(hands, truth):
    """PCK@0.2 and mean normalised error of the hand whose keypoint box overlaps the
    annotated box most (the same rule for both detectors); None when no hand."""
    kps, size, gt_box = truth
    best = None
    for hand in hands:
        pts = hand["landmarks_px"]
        xs, ys = [q[0] for q in pts], [q[1] for q in pts]
        iou = box_iou((min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)), gt_box)
        if best is None or iou > best[0]:
            best = (iou, pts)
    if best is None:
        return None
    errors = [math.dist(best[1][i][:2], kps[i][:2]) / size for i in range(21) if kps[i][2] > 0]
    pck = sum(e <= 0.2 for e in errors) / len(errors)
    return pck, sum(errors) / len(errors)


def bench(args):
    ours, ours_summary = load_dir(args.ours)
    peer, peer_summary = load_dir(args.peer)
    truth = load_annotations(args.annotations)
    rows, totals = [], {"ours": [], "peer": []}
    print(f"{'image':<16} {'ours PCK':>9} {'peer PCK':>9} {'ours err':>9} {'peer err':>9} "
          f"{'ours ms':>9} {'peer ms':>9}")
    for o, p in zip(ours, peer):
        name = os.path.basename(o["image"])
        if name not in truth:
            continue
        so, sp = score_hand(o["hands"], truth[name]), score_hand(p["hands"], truth[name])
        ms_o = o["time_ms"]["palm"] + o["time_ms"]["landmarks"]
        ms_p = p["time_ms"]
        fmt = lambda s, i: "no hand" if s is None else f"{s[i]:.3f}"
        print(f"{name:<16} {fmt(so, 0):>9} {fmt(sp, 0):>9} {fmt(so, 1):>9} {fmt(sp, 1):>9} "
              f"{ms_o:9.1f} {ms_p:9.1f}")
        for key, s in (("ours", so), ("peer", sp)):
            totals[key].append(s if s is not None else (0.0, float("nan")))
        rows.append({"image": name, "ours": so, "peer": sp, "ours_ms": ms_o, "peer_ms": ms_p})
    for key in ("ours", "peer"):
        pcks = [s[0] for s in totals[key]]
        errs = [s[1] for s in totals[key] if not math.isnan(s[1])]
        print(f"{key}: mean PCK@0.2 {sum(pcks) / max(len(pcks), 1):.4f} over {len(pcks)} images, "
              f"mean normalised error {sum(errs) / max(len(errs), 1):.4f} over {len(errs)} "
              f"images with a hand")
    mo = sum(r["ours_ms"] for r in rows) / max(len(rows), 1)
    mp = sum(r["peer_ms"] for r in rows) / max(len(rows), 1)
    print(f"time per image (palm + landmarks): ours {mo:.1f} ms "
          f"(palm {ours_summary['mean_palm_ms']:.1f}, landmarks "
          f"{ours_summary['mean_landmarks_ms']:.1f}), MediaPipe wasm in Chromium {mp:.1f} ms "
          f"(one send(), image upload included)")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("parity")
    p.add_argument("ours")
    p.add_argument("peer")
    p.add_argument("--report")
    b = sub.add_parser("bench")
    b.add_argument("ours")
    b.add_argument("peer")
    b.add_argument("annotations", nargs="+")
    args = parser.parse_args()
    return parity(args) if args.command == "parity" else bench(args)


if __name__ == "__main__":
    sys.exit(main())
