#!/usr/bin/env python3
"""How slowly biased the vertical vanishing points of a drive are (global_opt --vertical-bias).

Usage: scripts/vp_slow_bias.py [--half-window FRAMES] [--max-deg DEG] VPS.csv POSES.txt

VPS.csv is vp_detect's --csv output, POSES.txt the drive's ground truth (KITTI pose file, one
3 x 4 cam0-to-world line per frame, the frames of the VPs). Per frame the VP nearest the world's
up (within --max-deg, 10, of minus the first camera's y axis) is taken into the world with the
true rotation; the errors are its angles from their mean direction on two tangent axes. The
statistic is global_opt's (direction::MeasureSlowError): per axis, the white spread (RMS of
consecutive differences / sqrt 2) and the low-frequency error, the RMS of the centred moving
mean over +-FRAMES frames (default 10) less the share white noise leaves in such a mean; the
slow bias is the same along the direction it is largest in (largest eigenvalue of the 2 x 2
covariance). The slow bias is what global_opt's --vertical-bias stands for: how far the VPs
wander from the truth from stretch to stretch of the drive.

Prints one line: the drive's VP count, both axes' white and low-frequency errors, the slow
bias (deg) and its ratio to the larger white spread (global_opt's --vertical-bias-per-white).
"""
import csv
import math
import sys

from sim_fidelity import read_poses


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def vertical_vps(path, rotations, max_deg):
    """frame -> world direction of the frame's VP nearest up (oriented like up)."""
    up = [-rotations[0][i][1] for i in range(3)]
    best = {}
    with open(path) as f:
        reader = csv.DictReader(f)
        missing = {"frame", "dx", "dy", "dz"} - set(reader.fieldnames or [])
        if missing:
            raise ValueError(f"{path}: not a vp_detect CSV (no column {', '.join(sorted(missing))})")
        for row in reader:
            frame = int(row["frame"])
            if frame < 0 or frame >= len(rotations):
                raise ValueError(f"{path}: frame {frame} has no pose ({len(rotations)} poses)")
            ray = unit([float(row["dx"]), float(row["dy"]), float(row["dz"])])
            r = rotations[frame]
            w = [dot(r[i], ray) for i in range(3)]
            if dot(w, up) < 0:
                w = [-x for x in w]
            if math.degrees(math.acos(min(1.0, dot(w, up)))) > max_deg:
                continue
            if frame not in best or dot(w, up) > dot(best[frame], up):
                best[frame] = w
    return best


def slow_error(frames, errors, half_window):
    """(white per axis, low frequency per axis, slow) as direction::MeasureSlowError."""
    n = len(errors)
    if n < 3:
        return [0.0, 0.0], [0.0, 0.0], 0.0
    mean = [sum(e[a] for e in errors) / n for a in range(2)]
    x = [[e[a] - mean[a] for a in range(2)] for e in errors]
    w = [[0.0, 0.0], [0.0, 0.0]]  # white covariance
    for i in range(1, n):
        d = [x[i][a] - x[i - 1][a] for a in range(2)]
        for a in range(2):
            for b in range(2):
                w[a][b] += d[a] * d[b] / (2.0 * (n - 1))
    c = [[0.0, 0.0], [0.0, 0.0]]  # slow covariance
    lo = hi = 0
    for i in range(n):
        while frames[lo] < frames[i] - half_window:
            lo += 1
        while hi < n and frames[hi] <= frames[i] + half_window:
            hi += 1
        count = hi - lo
        m = [sum(x[k][a] for k in range(lo, hi)) / count for a in range(2)]
        for a in range(2):
            for b in range(2):
                c[a][b] += (m[a] * m[b] - w[a][b] * (1.0 / count - 1.0 / n)) / n
    # Largest eigenvalue of the symmetric 2 x 2 matrix c.
    half_trace = 0.5 * (c[0][0] + c[1][1])
    largest = half_trace + math.sqrt(max(0.0, (0.5 * (c[0][0] - c[1][1])) ** 2 + c[0][1] ** 2))
    white = [math.sqrt(w[a][a]) for a in range(2)]
    low = [math.sqrt(max(0.0, c[a][a])) for a in range(2)]
    return white, low, math.sqrt(max(0.0, largest))


def main(argv):
    half_window, max_deg, files = 10, 10.0, []
    i = 0
    while i < len(argv):
        if argv[i] in ("-h", "--help"):
            print(__doc__)
            return 0
        if argv[i] in ("--half-window", "--max-deg"):
            if i + 1 >= len(argv):
                raise ValueError(f"{argv[i]} needs a value")
            if argv[i] == "--half-window":
                half_window = int(argv[i + 1])
                if half_window < 0:
                    raise ValueError("--half-window must be >= 0")
            else:
                max_deg = float(argv[i + 1])
            i += 2
            continue
        files.append(argv[i])
        i += 1
    if len(files) != 2:
        raise ValueError("expected VPS.csv and POSES.txt (see --help)")
    rotations = [rotation for rotation, _ in read_poses(files[1], min_poses=1)]
    best = vertical_vps(files[0], rotations, max_deg)
    if len(best) < 3:
        raise ValueError(f"{files[0]}: {len(best)} frames with a vertical VP, at least 3 needed")
    frames = sorted(best)
    mean = unit([sum(best[f][i] for f in frames) for i in range(3)])
    helper = [1.0, 0.0, 0.0] if abs(mean[0]) < 0.9 else [0.0, 0.0, 1.0]
    b1 = unit(cross(mean, helper))
    b2 = cross(mean, b1)
    errors = [(math.degrees(dot(best[f], b1)), math.degrees(dot(best[f], b2))) for f in frames]
    white, low, slow = slow_error(frames, errors, half_window)
    print(
        f"{len(frames)} vertical VPs: white {white[0]:.3f} / {white[1]:.3f} deg, low-frequency "
        f"(+-{half_window} frames) {low[0]:.3f} / {low[1]:.3f} deg; slow bias {slow:.3f} deg "
        f"({slow / max(white) if max(white) > 0 else 0.0:.2f} of the larger white spread)"
    )
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except (OSError, ValueError) as e:
        print(f"vp_slow_bias: error: {e}", file=sys.stderr)
        sys.exit(1)
