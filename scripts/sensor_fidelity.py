#!/usr/bin/env python3
"""Real against simulated sensor data, side by side (docs/sim.md "Fidelity table").

Usage: scripts/sensor_fidelity.py [--markdown FILE] [--band 0.3] [--fraction-floor 0.03]
                                  REAL=STATS.json NAME=STATS.json [NAME=STATS.json ...]

Each STATS.json is a sensor_stats artifact (build/bin/sensor_stats -d SEQUENCE -o STATS.json;
with --odometry ODOM.h5 --vps VPS.h5 --visual VISUAL.h5 it also holds what the stages see).
The first drive is the reference. For every statistic the table has the median over the frames
of each drive; a simulated value outside the band around the reference is marked with "!":
outside +-band (relative, default 30 %) and, for fractions (statistics in [0, 1] whose name does
not end in _m, e.g. ground, scattered, range_5_10), also more than fraction-floor (absolute)
away - a relative band means little for fractions of a few percent. The last line counts the
marked cells per drive. Exit status 0 unless the input is bad (the table is a measurement, not
a test).
"""
import json
import math
import sys

from sim_fidelity import write_atomic

SECTIONS = ("scan", "image", "stages")
# Statistics whose value is a count or a length: compared by the relative band only.
NOT_FRACTIONS = {
    "points", "rings", "ring_points_median", "ring_points_p10", "range_median_m", "shape_voxels",
    "intensity_median", "intensity_p90", "mean", "contrast", "local_contrast", "gradient_mean",
    "gradient_p90", "fast_corners", "orb_keypoints", "far_ahead", "far_behind", "far_ahead_p10",
    "far_behind_p10", "odom_rpe_m_mean", "odom_rpe_percent", "odom_drift_percent",
    "odom_direction_yaw_deg", "odom_direction_pitch_deg", "vp_forward_error_deg",
    "vp_forward_error_deg_p90", "visual_points", "visual_reprojection_px",
}
# Statistics whose 10 % quantile over the frames is compared too: the frames where the scanner
# sees no world ahead or behind are a tail, not the median.
WITH_P10 = {"far_ahead", "far_behind"}
# Statistics whose 90 % quantile is compared too (the tail of an error).
WITH_P90 = {"vp_forward_error_deg"}
# Statistics compared by their mean: a rate (0 or 1 per frame), or an error whose outliers matter.
BY_MEAN = {"vp_forward_found", "odom_rpe_m"}


def load(path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: {e}")
    if doc.get("schema") != "sensor_stats":
        raise ValueError(f"{path}: not a sensor_stats artifact (schema {doc.get('schema')!r})")
    out = {}
    for section in SECTIONS:
        part = doc.get(section)
        if part is None:
            continue
        for name, v in part.items():
            if name in BY_MEAN:
                out[(section, name + "_mean")] = v.get("mean")
            else:
                out[(section, name)] = v.get("median")
            if name in WITH_P10:
                out[(section, name + "_p10")] = v.get("p10")
            if name in WITH_P90:
                out[(section, name + "_p90")] = v.get("p90")
    if not out:
        raise ValueError(f"{path}: no statistics")
    return out, len(doc.get("frames", []))


def outside(value, reference, name, band, floor):
    if value is None or reference is None:
        return False
    if abs(value - reference) <= band * abs(reference):
        return False
    if name not in NOT_FRACTIONS and abs(value - reference) <= floor:
        return False
    return True


def fmt(v):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if abs(v) >= 1000:
        return f"{v:.0f}"
    if abs(v) >= 10:
        return f"{v:.1f}"
    return f"{v:.3f}"


def table(drives, band, floor):
    names = [n for n, _, _ in drives]
    keys = []
    for _, stats, _ in drives:
        keys += [k for k in stats if k not in keys]
    lines = ["| statistic | " + " | ".join(f"{n} ({c} frames)" for n, _, c in drives) + " |",
             "|---|" + "---:|" * len(drives)]
    marked = [0] * len(drives)
    reference = drives[0][1]
    for key in keys:
        cells = []
        for i, (_, stats, _) in enumerate(drives):
            v = stats.get(key)
            cell = fmt(v)
            if i > 0 and outside(v, reference.get(key), key[1], band, floor):
                cell += " !"
                marked[i] += 1
            cells.append(cell)
        lines.append(f"| {key[0]} {key[1]} | " + " | ".join(cells) + " |")
    lines.append("| outside the band | " + " | ".join(
        ["(reference)"] + [str(m) for m in marked[1:]]) + " |")
    return "\n".join(lines) + "\n", dict(zip(names, marked))


def main(argv):
    markdown, band, floor, specs = None, 0.3, 0.03, []
    args = iter(argv)
    for a in args:
        if a == "--markdown":
            markdown = next(args, None)
        elif a == "--band":
            band = float(next(args, "nan"))
        elif a == "--fraction-floor":
            floor = float(next(args, "nan"))
        elif a in ("-h", "--help"):
            print(__doc__)
            return 0
        else:
            specs.append(a)
    if markdown is None and "--markdown" in argv:
        print("sensor_fidelity: --markdown needs a file", file=sys.stderr)
        return 2
    if not (band > 0) or not (floor >= 0):
        print("sensor_fidelity: --band must be > 0 and --fraction-floor >= 0", file=sys.stderr)
        return 2
    if len(specs) < 2:
        print("sensor_fidelity: need a reference and at least one more drive as NAME=STATS.json"
              " (see --help)", file=sys.stderr)
        return 2
    drives = []
    try:
        for spec in specs:
            name, sep, path = spec.partition("=")
            if not sep or not name or not path:
                raise ValueError(f"expected NAME=STATS.json, got {spec!r}")
            stats, count = load(path)
            drives.append((name, stats, count))
    except ValueError as e:
        print(f"sensor_fidelity: {e}", file=sys.stderr)
        return 2
    text, _ = table(drives, band, floor)
    sys.stdout.write(text)
    if markdown:
        write_atomic(markdown, text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
