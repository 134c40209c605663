#!/usr/bin/env python3
"""How a simulated drive moves compared with real KITTI drives (docs/sim.md "Vehicle motion").

Usage: scripts/sim_fidelity.py [--markdown FILE] NAME=POSES [NAME=POSES ...]

POSES is a KITTI pose file (3 x 4 cam0-to-world per line, 10 Hz): a real sequence's ground
truth (e.g. ../shared/data/kitti_odom_eval_reference/gt_poses/09.txt) or a sim_sequence output's
poses/00.txt. For each drive the statistics of its frame-to-frame motion, in the camera frame
(x right, y down, z forward), are printed as one row of a Markdown table:

  speed        translation per frame x 10 Hz (m/s): median and max
  yaw          rotation about the camera's y axis per frame (deg): p99 and max
  yaw change   change of that between consecutive frames (deg): p99 and max - how fast the
               vehicle steers into a turn
  roll, pitch  rotation about z and x per frame (deg): median (the jitter along straights),
               p99 and max
  heading off the chord
               where the path turns by at most 2 deg over the next 20 m: the angle about the
               camera's y axis between its optical axis and the chord to the position 20 m
               ahead, less the drive's median (the camera's mounting yaw): median and p90 of its
               size (deg). The lane keeping's weave; it also enters any comparison of a forward
               vanishing point (the road's lines) with the direction of travel.

The drives are read as given; nothing is aligned or resampled (KITTI's frames are 0.103 s apart,
the simulator's 0.1 s).
"""
import math
import os
import sys


def write_atomic(path, data):
    """Writes data (str or bytes) to path through a temporary file renamed over it."""
    tmp = path + ".tmp"
    with open(tmp, "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data)
    os.replace(tmp, path)


def read_poses(path, min_poses=3):
    """[(rotation rows, translation)] of a KITTI pose file; ValueError if malformed or shorter
    than min_poses."""
    poses = []
    with open(path) as f:
        for line_no, line in enumerate(f, 1):
            v = line.split()
            if not v:
                continue
            if len(v) != 12:
                raise ValueError(f"{path}:{line_no}: expected 12 numbers, found {len(v)}")
            x = [float(t) for t in v]
            poses.append(([x[0:3], x[4:7], x[8:11]], [x[3], x[7], x[11]]))
    if len(poses) < min_poses:
        raise ValueError(f"{path}: {len(poses)} poses, at least {min_poses} needed")
    return poses


def relative(a, b):
    """Rotation R_a^T R_b and translation R_a^T (t_b - t_a)."""
    (ra, ta), (rb, tb) = a, b
    r = [[sum(ra[k][i] * rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    d = [tb[k] - ta[k] for k in range(3)]
    t = [sum(ra[k][i] * d[k] for k in range(3)) for i in range(3)]
    return r, t


def rotation_vector(r):
    c = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2))
    angle = math.acos(c)
    v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    s = 2 * math.sin(angle)
    f = angle / s if s > 1e-12 else 0.5
    return [f * x for x in v]


def quantile(values, q):
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))]


def chord_headings(poses, lookahead_m=20.0, max_turn_deg=2.0):
    """Per frame with lookahead_m of path ahead over which the path turns by at most
    max_turn_deg: the yaw (deg, about the camera's y axis) of the chord to the position that far
    ahead, in the frame's camera."""
    path = [0.0]
    for k in range(1, len(poses)):
        path.append(path[-1] + math.dist(poses[k - 1][1], poses[k][1]))
    out, j = [], 0
    for k in range(len(poses)):
        j = max(j, k)
        while j < len(poses) and path[j] - path[k] < lookahead_m:
            j += 1
        if j == len(poses):
            break
        r, t = relative(poses[k], poses[j])
        turn = math.degrees(math.sqrt(sum(x * x for x in rotation_vector(r))))
        if turn <= max_turn_deg:
            out.append(math.degrees(math.atan2(t[0], t[2])))
    return out


def motion_stats(poses, rate_hz=10.0):
    steps = [relative(poses[k], poses[k + 1]) for k in range(len(poses) - 1)]
    rot = [[math.degrees(x) for x in rotation_vector(r)] for r, _ in steps]
    speed = [math.sqrt(sum(x * x for x in t)) * rate_hz for _, t in steps]
    yaw = [abs(r[1]) for r in rot]
    yaw_change = [abs(rot[k + 1][1] - rot[k][1]) for k in range(len(rot) - 1)]
    roll = [abs(r[2]) for r in rot]
    pitch = [abs(r[0]) for r in rot]
    chord = chord_headings(poses)
    mount = quantile(chord, 0.5) if chord else 0.0
    off = [abs(c - mount) for c in chord]
    return {
        "frames": len(poses),
        "chord_median": quantile(off, 0.5) if off else float("nan"),
        "chord_p90": quantile(off, 0.9) if off else float("nan"),
        "speed_median": quantile(speed, 0.5), "speed_max": max(speed),
        "yaw_p99": quantile(yaw, 0.99), "yaw_max": max(yaw),
        "yaw_change_p99": quantile(yaw_change, 0.99), "yaw_change_max": max(yaw_change),
        "roll_median": quantile(roll, 0.5), "roll_p99": quantile(roll, 0.99), "roll_max": max(roll),
        "pitch_median": quantile(pitch, 0.5), "pitch_p99": quantile(pitch, 0.99),
        "pitch_max": max(pitch),
    }


HEADER = ("| drive | frames | speed median / max (m/s) | yaw per frame p99 / max (deg) | "
          "yaw change p99 / max (deg) | roll per frame median / p99 / max (deg) | "
          "pitch per frame median / p99 / max (deg) | heading off the 20 m chord median / p90 "
          "(deg) |\n"
          "|---|---:|---|---|---|---|---|---|")


def row(name, s):
    return (f"| {name} | {s['frames']} | {s['speed_median']:.1f} / {s['speed_max']:.1f} | "
            f"{s['yaw_p99']:.3f} / {s['yaw_max']:.3f} | "
            f"{s['yaw_change_p99']:.3f} / {s['yaw_change_max']:.3f} | "
            f"{s['roll_median']:.4f} / {s['roll_p99']:.3f} / {s['roll_max']:.3f} | "
            f"{s['pitch_median']:.4f} / {s['pitch_p99']:.3f} / {s['pitch_max']:.3f} | "
            f"{s['chord_median']:.3f} / {s['chord_p90']:.3f} |")


def main(argv):
    markdown = None
    drives = []
    args = list(argv)
    while args:
        a = args.pop(0)
        if a in ("-h", "--help"):
            print(__doc__.strip())
            return 0
        if a == "--markdown":
            if not args:
                print("sim_fidelity: --markdown needs a file name", file=sys.stderr)
                return 2
            markdown = args.pop(0)
        elif "=" in a:
            name, path = a.split("=", 1)
            drives.append((name, path))
        else:
            print(f"sim_fidelity: expected NAME=POSES, got '{a}' (--help)", file=sys.stderr)
            return 2
    if not drives:
        print("sim_fidelity: no drives given (NAME=POSES ...; --help)", file=sys.stderr)
        return 2
    lines = [HEADER]
    for name, path in drives:
        try:
            lines.append(row(name, motion_stats(read_poses(path))))
        except (OSError, ValueError) as e:
            print(f"sim_fidelity: {e}", file=sys.stderr)
            return 1
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if markdown:
        write_atomic(markdown, text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
