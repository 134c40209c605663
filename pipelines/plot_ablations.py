#!/usr/bin/env python3
"""Plots of pipelines/collect.py's plot_data.json (matplotlib).

    plot_ablations.py plot_data.json OUT_DIR

ape_vs_VAR.png     APE RMSE against a numeric variable, per sequence: with direction priors
                   (solid) and without (dashed), as the paper's APE-vs-V_interval figure
ape_box_TABLE.png  per-frame APE distribution per configuration, one panel per sequence,
                   the base configuration without direction priors first
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def line_plot(table, sequences, path):
    rows = [r for r in table["rows"] if r["x"] is not None]
    if len(rows) < 2:
        return False
    rows.sort(key=lambda r: r["x"])
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for i, seq in enumerate(sequences):
        color = f"C{i % 10}"
        for key, style, name in (("ape", "-o", "with"), ("ape_without", "--x", "without")):
            pts = [(r["x"], r[key][seq]) for r in rows if r[key].get(seq) is not None]
            if pts:
                ax.plot(*zip(*pts), style, color=color, label=f"{seq} {name} direction priors")
    var = table["variables"][0]
    ax.set_xlabel(var)
    ax.set_ylabel("APE RMSE (m)")
    ax.set_title(f"APE vs {var}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def box_plot(table, sequences, path):
    panels = []
    for seq in sequences:
        boxes = [("w.o. dir. (base)", table["without_frames"].get(seq, []))]
        boxes += [(r["label"], r["ape_frames"].get(seq, [])) for r in table["rows"]]
        boxes = [(label, v) for label, v in boxes if v]
        if boxes:
            panels.append((seq, boxes))
    if not panels:
        return False
    cols = min(3, len(panels))
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.8 * cols, 3.6 * rows), squeeze=False)
    for ax, (seq, boxes) in zip(axes.flat, panels):
        ax.boxplot([v for _, v in boxes], showfliers=True, flierprops={"markersize": 2})
        ax.set_xticks(range(1, len(boxes) + 1))
        ax.set_xticklabels([label for label, _ in boxes], rotation=45, ha="right", fontsize=7)
        ax.set_title(f"{seq}: APE per frame", fontsize=9)
        if len(table["variables"]) == 1:
            ax.set_xlabel(table["variables"][0])
        ax.set_ylabel("APE (m)")
        ax.grid(alpha=0.3, axis="y")
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv):
    if len(argv) != 2:
        print("usage: plot_ablations.py plot_data.json OUT_DIR", file=sys.stderr)
        return 2
    with open(argv[0]) as f:
        data = json.load(f)
    os.makedirs(argv[1], exist_ok=True)
    written = []
    for table in data["tables"]:
        if len(table["variables"]) == 1:
            path = os.path.join(argv[1], f"ape_vs_{table['name']}.png")
            if line_plot(table, data["sequences"], path):
                written.append(path)
        path = os.path.join(argv[1], f"ape_box_{table['name']}.png")
        if box_plot(table, data["sequences"], path):
            written.append(path)
    for path in written:
        print(f"plot_ablations.py: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
