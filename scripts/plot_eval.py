#!/usr/bin/env python3
"""Plots of an evaluate run: reads the plot_data.json that `evaluate --plot-dir DIR` writes.

    python3 scripts/plot_eval.py DIR/plot_data.json DIR

Writes (per sequence S when several): trajectories[_S].png (top view, x-z plane of cam0: x right,
z forward), ape[_S].png (APE translation along the frame index), ape_box.png (APE per estimate),
kitti_per_length.png (t_rel and r_rel per segment length, pooled over sequences).
Needs numpy and matplotlib (Debian: python3-matplotlib).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def sequence_names(data):
    names = []
    for est in data["estimates"]:
        for seq in est["sequences"]:
            if seq["name"] not in names:
                names.append(seq["name"])
    return names


def suffix(name, names):
    return "" if len(names) == 1 else "_" + name


def estimated_span(data, name):
    """First and last frame that any estimate has in sequence `name` (None if not known)."""
    frames = [f for est in data["estimates"] for seq in est["sequences"] if seq["name"] == name
              for f in seq.get("est_frames", [])]
    return (min(frames), max(frames)) if frames else None


def plot_top_view(data, name, path):
    fig, ax = plt.subplots(figsize=(8, 8))
    gt_drawn = False
    # The ground truth only where the estimates are (an excerpt of a long sequence is not
    # squeezed into a corner of the whole drive).
    span = estimated_span(data, name)
    for est in data["estimates"]:
        for seq in est["sequences"]:
            if seq["name"] != name:
                continue
            if not gt_drawn:
                gt = np.asarray(seq["gt_xyz"])
                gt_frames = seq.get("gt_frames", [])
                if span and len(gt_frames) == len(gt):
                    keep = [span[0] <= f <= span[1] for f in gt_frames]
                    if any(keep):
                        gt = gt[np.asarray(keep)]
                ax.plot(gt[:, 0], gt[:, 2], "k-", lw=2.0, label="ground truth")
                ax.plot(gt[0, 0], gt[0, 2], "ko", ms=6)
                gt_drawn = True
            xyz = np.asarray(seq["est_xyz"])
            if len(xyz):
                ax.plot(xyz[:, 0], xyz[:, 2], "-", lw=1.2, label=est["label"])
    plot_loops(data, name, ax)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("Top view, sequence %s (aligned estimates)" % name)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


LOOP_STYLE = {"LiDAR": ("tab:red", "x"), "visual": ("tab:blue", "+"),
              "proximity": ("tab:olive", "^"), "both": ("tab:purple", "o")}


def plot_loops(data, name, ax):
    """Accepted loops (evaluate --loops): query and match joined on the ground truth."""
    loops = data.get("loops", [])
    if not loops:
        return
    seq = next(s for e in data["estimates"] for s in e["sequences"] if s["name"] == name)
    where = {f: p for f, p in zip(seq.get("gt_frames", []), seq["gt_xyz"])}
    span = estimated_span(data, name)
    if span:  # Only the loops within the frames drawn.
        where = {f: p for f, p in where.items() if span[0] <= f <= span[1]}
    drawn = set()
    for query, match, detector in loops:
        if query not in where or match not in where:
            continue
        colour, marker = LOOP_STYLE.get(detector, ("tab:gray", "."))
        q, m = where[query], where[match]
        ax.plot([q[0], m[0]], [q[2], m[2]], "-", color=colour, lw=0.8, alpha=0.7)
        label = None if detector in drawn else "loops (%s)" % detector
        ax.plot(q[0], q[2], marker, color=colour, ms=5, label=label)
        drawn.add(detector)


def plot_ape_along(data, name, path):
    fig, ax = plt.subplots(figsize=(10, 4))
    for est in data["estimates"]:
        for seq in est["sequences"]:
            if seq["name"] == name:
                ax.plot(seq["ape_frames"], seq["ape_translation_m"], "-", lw=1.0,
                        label=est["label"])
    ax.set_xlabel("frame")
    ax.set_ylabel("APE translation (m)")
    ax.set_title("Absolute position error along sequence %s" % name)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_ape_box(data, path):
    labels, values = [], []
    for est in data["estimates"]:
        v = [x for seq in est["sequences"] for x in seq["ape_translation_m"]]
        labels.append(est["label"])
        values.append(v)
    fig, ax = plt.subplots(figsize=(max(4, 1.6 * len(labels) + 2), 5))
    ax.boxplot(values, showfliers=True)
    ax.set_xticks(range(1, len(labels) + 1))
    ax.set_xticklabels(labels, rotation=20)
    ax.set_ylabel("APE translation (m)")
    ax.set_title("APE per estimate (all matched frames)")
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_kitti(data, path):
    fig, (ax_t, ax_r) = plt.subplots(1, 2, figsize=(11, 4.5))
    drawn = 0
    for est in data["estimates"]:
        rows = [r for r in est["kitti_per_length"] if r[1] > 0]  # [length, count, t, r]
        if not rows:
            continue
        rows = np.asarray(rows, float)
        ax_t.plot(rows[:, 0], rows[:, 2], "s-", label=est["label"])
        ax_r.plot(rows[:, 0], rows[:, 3], "s-", label=est["label"])
        drawn += 1
    ax_t.set_xlabel("segment length (m)")
    ax_t.set_ylabel("translation error t_rel (%)")
    ax_r.set_xlabel("segment length (m)")
    ax_r.set_ylabel("rotation error r_rel (deg/100 m)")
    for ax in (ax_t, ax_r):
        ax.grid(True, alpha=0.3)
        if drawn:
            ax.legend(loc="best")
        else:
            ax.text(0.5, 0.5, "no KITTI segment\n(path shorter than the shortest length)",
                    ha="center", va="center", transform=ax.transAxes)
    fig.suptitle("KITTI segment errors per length")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_eval.py PLOT_DATA_JSON OUTPUT_DIR")
    with open(sys.argv[1]) as fh:
        data = json.load(fh)
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    names = sequence_names(data)
    written = []
    for name in names:
        for fn, stem in ((plot_top_view, "trajectories"), (plot_ape_along, "ape")):
            path = os.path.join(out, stem + suffix(name, names) + ".png")
            fn(data, name, path)
            written.append(path)
    for fn, stem in ((plot_ape_box, "ape_box"), (plot_kitti, "kitti_per_length")):
        path = os.path.join(out, stem + ".png")
        fn(data, path)
        written.append(path)
    print("plot_eval: wrote " + ", ".join(os.path.basename(p) for p in written))


if __name__ == "__main__":
    main()
