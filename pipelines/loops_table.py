#!/usr/bin/env python3
"""The loops table of a pipelines/loops run (standard library only).

    loops_table.py RUN_DIR NAME... [-o RUN_DIR/loops.md] [--json RUN_DIR/loops.json]

For every drive NAME: the APE (translation m / rotation deg RMSE) and t_rel of the prior
(lidar_odom N = 1) and of the global results without and with direction priors, without loops
(RUN_DIR/NAME/base/metrics.json) and with loop_detect's loops (RUN_DIR/NAME/loops-1/), and the
ratio with / without loops; then each detector's loops against the ground truth
(RUN_DIR/NAME/gt/D.json, loop_detect --report; D = visual, lidar, proximity alone and all, the
three together): accepted, right (precision), the revisiting keyframes found in the same and
the opposite direction (recall), the revisit stretches closed, and the default run's time per
keyframe.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gains_table import LABELS, estimate_figures, fmt, path_length, read_kitti  # noqa: E402

CONFIGS = (("no_loops", "base"), ("loops", "loops-1"))
DETECTORS = (("visual", "visual"), ("lidar", "LiDAR"), ("proximity", "proximity"),
             ("all", "combined"))


def estimates(folder):
    path = os.path.join(folder, "metrics.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        metrics = json.load(f)
    by_label = {e["label"]: e for e in metrics["estimates"]}
    return {key: estimate_figures(by_label[label]) if label in by_label else None
            for key, label in LABELS}


def detector_report(gt_dir, det):
    path = os.path.join(gt_dir, det + ".json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        report = json.load(f)
    # Alone (visual, lidar, proximity) the report holds that detector; `all` ends with the
    # combined figures.
    entry = report["detectors"][-1]
    entry = dict(entry, keyframes=report["keyframes"], candidates=report["candidates"])
    usage_path = os.path.join(gt_dir, det + ".usage.json")
    time_path = os.path.join(gt_dir, det + ".time")
    if os.path.exists(usage_path):
        with open(usage_path) as f:
            usage = json.load(f)
        entry.update(time_s=usage["wall_s"], cpu_s=usage["cpu_s"], peak_mib=usage["peak_mib"])
    elif os.path.exists(time_path):
        with open(time_path) as f:
            entry["time_s"] = float(f.read())
    return entry


def drive_row(run, name):
    row = {"name": name}
    gt_path = os.path.join(run, "data", name, "poses", "00.txt")
    if os.path.exists(gt_path):
        gt = read_kitti(gt_path)
        row["frames"] = len(gt)
        row["length_m"] = path_length(gt)
    for key, config in CONFIGS:
        row[key] = estimates(os.path.join(run, name, config))
    row["detectors"] = {det: detector_report(os.path.join(run, name, "gt"), det)
                        for det, _ in DETECTORS}
    for which in ("without", "with"):
        a = (row["no_loops"] or {}).get(which) or {}
        b = (row["loops"] or {}).get(which) or {}
        if a.get("ape_m") and b.get("ape_m") is not None:
            row[f"ratio_{which}"] = b["ape_m"] / a["ape_m"]
    return row


def pct(a, b):
    return "-" if not b else f"{100.0 * a / b:.0f} %"


def write_markdown(rows, path):
    # The APE table holds the drives that went through the chain (not those of a
    # pipelines/loops --detect-only run).
    chain_rows = [r for r in rows if r.get("no_loops") or r.get("loops")]
    lines = [
        "| drive | frames | km | APE prior (m / deg) | no loops: w.o. / w. (m / deg) "
        "| loops: w.o. / w. (m / deg) | t_rel no loops -> loops, w.o. / w. (%) "
        "| loops / no loops, w.o. / w. |",
        "|---|---:|---:|---|---|---|---|---|",
    ] if chain_rows else []

    def ape(e):
        return "-" if not e else f"{fmt(e['ape_m'])} / {fmt(e['ape_deg'])}"

    for r in chain_rows:
        n, l = r.get("no_loops") or {}, r.get("loops") or {}
        km = f"{r['length_m'] / 1000:.2f}" if "length_m" in r else "-"
        t_rel = " / ".join(
            f"{fmt((n.get(w) or {}).get('t_rel'))} -> {fmt((l.get(w) or {}).get('t_rel'))}"
            for w in ("without", "with"))
        ratios = " / ".join(fmt(r.get(f"ratio_{w}"), 2) for w in ("without", "with"))
        lines.append(
            f"| {r['name']} | {r.get('frames', '-')} | {km} | {ape(n.get('prior'))} "
            f"| {ape(n.get('without'))}; {ape(n.get('with'))} "
            f"| {ape(l.get('without'))}; {ape(l.get('with'))} | {t_rel} | {ratios} |")
    lines += [
        "",
        "| drive | detector | keyframes | verified | accepted / right (precision) "
        "| recall same direction | recall opposite direction | stretches closed, same / opposite "
        "| time (s, ms per keyframe) | CPU (s), peak memory (MiB) |",
        "|---|---|---:|---:|---|---|---|---|---|---|",
    ] if chain_rows else [
        "| drive | frames | km | detector | keyframes | verified "
        "| accepted / right (precision) | recall same direction | recall opposite direction "
        "| stretches closed, same / opposite | time (s, ms per keyframe) "
        "| CPU (s), peak memory (MiB) |",
        "|---|---:|---:|---|---:|---:|---|---|---|---|---|---|",
    ]
    for r in rows:
        drive = r["name"]
        if not chain_rows:
            km = f"{r['length_m'] / 1000:.2f}" if "length_m" in r else "-"
            drive = f"{r['name']} | {r.get('frames', '-')} | {km}"
        for det, label in DETECTORS:
            d = r["detectors"].get(det)
            if d is None:
                lines.append(f"| {drive} | {label} | missing | | | | | | | |")
                continue
            time = "-"
            if "time_s" in d:
                time = f"{d['time_s']:.1f} ({1e3 * d['time_s'] / max(d['keyframes'], 1):.0f})"
            usage = "-"
            if "cpu_s" in d:
                usage = f"{d['cpu_s']:.1f}, {d['peak_mib']:.0f}"
            lines.append(
                f"| {drive} | {label} | {d['keyframes']} | {d['candidates']} "
                f"| {d['accepted']} / {d['right']} ({pct(d['right'], d['accepted'])}) "
                f"| {d['found_same']} of {d['revisits_same']} "
                f"({pct(d['found_same'], d['revisits_same'])}) "
                f"| {d['found_opposite']} of {d['revisits_opposite']} "
                f"({pct(d['found_opposite'], d['revisits_opposite'])}) "
                f"| {d['closed_same']} of {d['stretches_same']} / {d['closed_opposite']} of "
                f"{d['stretches_opposite']} | {time} | {usage} |")
    ratios = [r[f"ratio_{w}"] for r in rows for w in ("without", "with") if f"ratio_{w}" in r]
    wrong = sum(d["accepted"] - d["right"] for r in rows for d in r["detectors"].values() if d)
    ape = (f" APE with loops / without loops {min(ratios):.2f}-{max(ratios):.2f} (mean "
           f"{sum(ratios) / len(ratios):.2f});") if ratios else ""
    summary = (f"\nDrives ({len(rows)}):{ape} wrong accepted loops (all runs of the "
               f"{'second ' if chain_rows else ''}table) {wrong}.\n")
    text = "\n".join(lines).lstrip("\n") + "\n" + summary
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)
    print(text, end="")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run")
    parser.add_argument("names", nargs="+")
    parser.add_argument("-o", "--output")
    parser.add_argument("--json")
    args = parser.parse_args()
    rows = [drive_row(args.run, name) for name in args.names]
    write_markdown(rows, args.output or os.path.join(args.run, "loops.md"))
    json_path = args.json or os.path.join(args.run, "loops.json")
    with open(json_path + ".tmp", "w") as f:
        json.dump(rows, f, indent=1)
        f.write("\n")
    os.replace(json_path + ".tmp", json_path)


if __name__ == "__main__":
    main()
