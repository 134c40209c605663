#!/usr/bin/env python3
"""Accuracy of vp_detect on a sim_sequence output against its ground-truth vanishing points.

Usage: scripts/vp_accuracy_sim.py SEQUENCE_DIR VPS_CSV [--margin M]

Frames counted: those on straight route pieces lined with buildings (scene.json), at least
M metres (default 10) away from both ends of the piece. For each such frame the detected VP
closest in angle to the ground-truth road direction is compared with the road direction and
with the building axis along the road (the two differ by the road's slope on hilly terrain).
Prints the detection rate and the median / p90 angular errors.
"""
import csv
import json
import math
import os
import sys


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def angle_deg(a, b):
    d = abs(sum(x * y for x, y in zip(unit(a), unit(b))))
    return math.degrees(math.acos(min(1.0, d)))


def percentile(values, p):
    s = sorted(values)
    if not s:
        return float("nan")
    k = (len(s) - 1) * p
    f = math.floor(k)
    c = min(f + 1, len(s) - 1)
    return s[f] + (s[c] - s[f]) * (k - f)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    margin = 10.0
    if "--margin" in sys.argv:
        margin = float(sys.argv[sys.argv.index("--margin") + 1])
    seq_dir, vps_csv = args[0], args[1]
    scene = json.load(open(os.path.join(seq_dir, "sim", "scene.json")))
    pieces = [p for p in scene["route"]["pieces"] if p["type"] == "straight" and not p["open"]]
    poses_path = os.path.join(seq_dir, "..", "..", "poses",
                              os.path.basename(os.path.normpath(seq_dir)) + ".txt")
    centres = []
    for line in open(poses_path):
        v = [float(x) for x in line.split()]
        centres.append((v[3], v[7], v[11]))
    s = [0.0]
    for i in range(1, len(centres)):
        s.append(s[-1] + math.dist(centres[i], centres[i - 1]))
    gt = {}
    for row in csv.DictReader(open(os.path.join(seq_dir, "sim", "gt_vps.csv"))):
        gt.setdefault(int(row["frame"]), {})[row["kind"]] = [float(row[k]) for k in ("dx", "dy", "dz")]
    det = {}
    for row in csv.DictReader(open(vps_csv)):
        det.setdefault(int(row["frame"]), []).append([float(row[k]) for k in ("dx", "dy", "dz")])
    frames = [f for f in range(len(centres))
              if any(p["s0"] + margin <= s[f] <= p["s0"] + p["length"] - margin for p in pieces)
              and "road" in gt.get(f, {})]
    found, err_road, err_along = 0, [], []
    for f in frames:
        road = gt[f]["road"]
        cands = det.get(f, [])
        if not cands:
            continue
        best = min(cands, key=lambda d: angle_deg(d, road))
        if angle_deg(best, road) > 5.0:
            continue
        found += 1
        err_road.append(angle_deg(best, road))
        along = gt[f].get("building_along", road)
        err_along.append(angle_deg(best, along))
    print(f"frames on straight segments with buildings: {len(frames)}")
    print(f"road-direction VP found (within 5 deg): {found} ({100.0 * found / max(1, len(frames)):.1f} %)")
    print(f"error vs road tangent:       median {percentile(err_road, 0.5):.3f} deg, p90 {percentile(err_road, 0.9):.3f} deg")
    print(f"error vs building axis along: median {percentile(err_along, 0.5):.3f} deg, p90 {percentile(err_along, 0.9):.3f} deg")
    print(f"error vs nearer of the two:  median {percentile([min(a, b) for a, b in zip(err_road, err_along)], 0.5):.3f} deg, "
          f"p90 {percentile([min(a, b) for a, b in zip(err_road, err_along)], 0.9):.3f} deg")


if __name__ == "__main__":
    main()
