#!/usr/bin/env python3
"""Golden data for tests/eval: constructed trajectories and the metrics expected for them.

The expected numbers are computed here with numpy, independently of the C++ code, from the
definitions in docs/evaluate.md (KITTI devkit segment metric, Umeyama 1991, kitti-odom-eval's
"7dof" procedure for sim3 + origin-first). Regenerate (deterministic) with:

    python3 tests/eval/make_golden.py tests/eval/data

With a frame count it writes only the two trajectories of that length (no expected numbers),
e.g. the 4541-pose input of the benchmark in docs/evaluate.md:

    python3 tests/eval/make_golden.py /tmp/long 4541
"""
import json
import os
import sys

import numpy as np

LENGTHS = [100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0]


def rot(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def make_pose(r, t):
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = t
    return m


def make_trajectories(n=800, seed=3):
    """A planar-ish drive at ~1.2 m/frame with turns; the estimate drifts in yaw and scale."""
    rng = np.random.default_rng(seed)
    gt, est = [np.eye(4)], [np.eye(4)]
    for f in range(1, n):
        yaw = 0.02 * np.sin(f / 60.0) + rng.normal(0, 0.002)
        step = make_pose(rot([0, 1, 0], yaw) @ rot([1, 0, 0], rng.normal(0, 0.001)),
                         [rng.normal(0, 0.02), rng.normal(0, 0.01), 1.2 + rng.normal(0, 0.05)])
        noise = make_pose(rot(rng.normal(size=3), 0.0005 + abs(rng.normal(0, 0.0005))),
                          rng.normal(0, 0.01, 3) + [0, 0, 0.015])
        gt.append(gt[-1] @ step)
        est.append(est[-1] @ step @ noise)
    offset = make_pose(rot([0.2, 1, 0.1], 0.8), [4.0, -1.0, 7.0])
    scale = 0.6  # A monocular estimate in its own units.
    est_out = {}
    for f in range(2, n):  # Starts late (frame 2) and misses frame 517.
        if f == 517:
            continue
        m = est[f].copy()
        m[:3, 3] *= scale
        est_out[f] = offset @ m
    return {f: gt[f] for f in range(n)}, est_out


def write_kitti(path, poses, indexed, fmt):
    with open(path, "w") as fh:
        for f in sorted(poses):
            vals = [fmt % v for v in poses[f][:3, :].reshape(-1)]
            fh.write((("%d " % f) if indexed else "") + " ".join(vals) + "\n")


def read_kitti(path):
    poses = {}
    for k, line in enumerate(open(path)):
        v = [float(x) for x in line.split()]
        m = np.eye(4)
        m[:3, :] = np.array(v[-12:]).reshape(3, 4)
        poses[int(v[0]) if len(v) == 13 else k] = m
    return poses


def angle(m):
    return np.arccos(np.clip(0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0), -1.0, 1.0))


def stats(x):
    x = np.asarray(x, float)
    if x.size == 0:
        return dict(rmse=0.0, mean=0.0, median=0.0, std=0.0, min=0.0, max=0.0, count=0)
    return dict(rmse=float(np.sqrt(np.mean(x ** 2))), mean=float(np.mean(x)),
                median=float(np.median(x)), std=float(np.std(x)), min=float(np.min(x)),
                max=float(np.max(x)), count=int(x.size))


def umeyama(x, y, with_scale):
    """Least-squares y ~ c R x + t (Umeyama 1991, eqs. 34-43); x, y are 3 x n."""
    n = x.shape[1]
    mx, my = x.mean(axis=1), y.mean(axis=1)
    xc, yc = x - mx[:, None], y - my[:, None]
    var_x = np.sum(xc ** 2) / n
    u, d, vt = np.linalg.svd(yc @ xc.T / n)
    s = np.ones(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        s[2] = -1
    r = u @ np.diag(s) @ vt
    c = float(d @ s / var_x) if with_scale else 1.0
    return r, my - c * r @ mx, c


def evaluate(gt, est, align, origin_first, rpe_delta, rpe_unit):
    frames = sorted(gt)
    matched = [f for f in sorted(est) if f in gt]
    gt, est = dict(gt), dict(est)
    if align == "origin" or origin_first:
        g0, e0 = np.linalg.inv(gt[matched[0]]), np.linalg.inv(est[matched[0]])
        gt = {f: g0 @ m for f, m in gt.items()}
        est = {f: e0 @ m for f, m in est.items()}
    r, t, c = np.eye(3), np.zeros(3), 1.0
    if align in ("se3", "sim3"):
        x = np.array([est[f][:3, 3] for f in matched]).T
        y = np.array([gt[f][:3, 3] for f in matched]).T
        r, t, c = umeyama(x, y, align == "sim3")
    a = make_pose(r, t)
    aligned = {}
    for f in matched:
        m = est[f].copy()
        m[:3, 3] *= c
        aligned[f] = a @ m
    # Path distance along the ground truth (devkit trajectoryDistances).
    dist = [0.0]
    for f0, f1 in zip(frames[:-1], frames[1:]):
        dist.append(dist[-1] + np.linalg.norm(gt[f0][:3, 3] - gt[f1][:3, 3]))
    ape_t = [np.linalg.norm(gt[f][:3, 3] - aligned[f][:3, 3]) for f in matched]
    ape_r = [np.degrees(angle(np.linalg.inv(gt[f]) @ aligned[f])) for f in matched]
    rpe_t, rpe_p, rpe_r = [], [], []
    for i, f in enumerate(frames):
        if f not in aligned:
            continue
        if rpe_unit == "frames":
            j = frames.index(f + int(rpe_delta)) if f + int(rpe_delta) in gt else None
        else:
            later = [k for k in range(i, len(frames)) if dist[k] > dist[i] + rpe_delta]
            j = later[0] if later else None
        if j is None or frames[j] not in aligned:
            continue
        g_rel = np.linalg.inv(gt[f]) @ gt[frames[j]]
        e_rel = np.linalg.inv(aligned[f]) @ aligned[frames[j]]
        err = np.linalg.inv(g_rel) @ e_rel
        rpe_t.append(np.linalg.norm(err[:3, 3]))
        rpe_r.append(np.degrees(angle(err)))
        if dist[j] - dist[i] > 0:
            rpe_p.append(rpe_t[-1] / (dist[j] - dist[i]) * 100.0)
    segs = []
    for first in range(0, len(frames), 10):
        for length in LENGTHS:
            last = next((k for k in range(first, len(frames)) if dist[k] > dist[first] + length),
                        None)
            if last is None or frames[first] not in aligned or frames[last] not in aligned:
                continue
            dg = np.linalg.inv(gt[frames[first]]) @ gt[frames[last]]
            de = np.linalg.inv(aligned[frames[first]]) @ aligned[frames[last]]
            err = np.linalg.inv(de) @ dg
            segs.append((length, np.linalg.norm(err[:3, 3]) / length, angle(err) / length))
    per_length = []
    for length in LENGTHS:
        sel = [s for s in segs if s[0] == length]
        per_length.append(dict(
            length_m=length, segments=len(sel),
            t_rel_percent=float(np.mean([s[1] for s in sel]) * 100) if sel else 0.0,
            r_rel_deg_per_100m=float(np.mean([s[2] for s in sel]) / np.pi * 180 * 100)
            if sel else 0.0))
    return dict(
        frames_matched=len(matched), scale=c,
        ape=dict(translation_m=stats(ape_t), rotation_deg=stats(ape_r)),
        rpe=dict(translation_m=stats(rpe_t), translation_percent=stats(rpe_p),
                 rotation_deg=stats(rpe_r)),
        kitti=dict(t_rel_percent=float(np.mean([s[1] for s in segs]) * 100),
                   r_rel_deg_per_100m=float(np.mean([s[2] for s in segs]) / np.pi * 180 * 100),
                   segments=len(segs), per_length=per_length))


CASES = [
    # name, align, origin_first, rpe_delta, rpe_unit
    ("kitti_odom_eval_7dof", "sim3", True, 1, "frames"),
    ("none", "none", False, 1, "frames"),
    ("origin_rpe_5_frames", "origin", False, 5, "frames"),
    ("se3_rpe_50_m", "se3", False, 50.0, "m"),
    ("sim3_rpe_100_m", "sim3", False, 100.0, "m"),
]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/eval/data"
    os.makedirs(out, exist_ok=True)
    if len(sys.argv) > 2:
        gt, est = make_trajectories(n=int(sys.argv[2]))
        write_kitti(out + "/gt.txt", gt, indexed=False, fmt="%.9e")
        write_kitti(out + "/est.txt", est, indexed=True, fmt="%.7e")
        return
    gt, est = make_trajectories()
    # Limited precision like real KITTI files, so rotation blocks are orthonormal only to ~1e-7.
    write_kitti(out + "/gt.txt", gt, indexed=False, fmt="%.9e")
    write_kitti(out + "/est.txt", est, indexed=True, fmt="%.7e")
    gt, est = read_kitti(out + "/gt.txt"), read_kitti(out + "/est.txt")
    expected = {"generator": "tests/eval/make_golden.py", "cases": []}
    for name, align, origin_first, delta, unit in CASES:
        r = evaluate(gt, est, align, origin_first, delta, unit)
        r.update(name=name, align=align, origin_first=origin_first, rpe_delta=delta, rpe_unit=unit)
        expected["cases"].append(r)
    with open(out + "/expected.json", "w") as fh:
        json.dump(expected, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
