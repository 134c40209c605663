#!/usr/bin/env python3
"""The gains table of a pipelines/gains run (standard library only).

    gains_table.py RUN_DIR [-o RUN_DIR/gains.md] [--json RUN_DIR/gains.json] [--plot FILE.png]

For every drive RUN_DIR/NAME/base (Makefile.example outputs: metrics.json, without_directions.txt,
with_directions.txt, and odom.txt there or in RUN_DIR/NAME/common; the ground truth is the dataset's poses file named in
RUN_DIR/gains.spec) it reports, for the prior (lidar_odom N = 1), the global result without and
with direction priors: APE translation (m) and rotation (deg) RMSE, t_rel (%) and r_rel
(deg/100 m) from metrics.json, and the ratios APE(without)/APE(prior), APE(with)/APE(without).

Steps: the frame-to-frame error of an estimate at frame k is the translation norm of
(G_k^-1 G_k+1)^-1 (E_k^-1 E_k+1), G ground truth and E the estimate (KITTI camera poses). A step
of the prior is a frame whose error exceeds 5x the prior's median frame-to-frame error; it
survives in a global result when the result's error at that frame still exceeds that threshold.
The table lists the prior's worst step with the global results' errors at the same frame.

--plot FILE.png (needs matplotlib) draws the steps before and after: every step of the prior on
the simulated drives (the results' errors at it against the prior's, in thresholds), and the
frame-to-frame errors around the prior's worst step and around the step the results come
closest to keeping.
"""
import argparse
import json
import math
import os
import shlex
import sys

LABELS = (("prior", "prior"), ("without", "w.o. direction priors"),
          ("with", "w. direction priors"))
FILES = {"prior": "odom.txt", "without": "without_directions.txt",
         "with": "with_directions.txt"}
STEP_FACTOR = 5.0


def read_kitti(path):
    poses = []
    with open(path) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            if len(v) != 12:
                raise ValueError(f"{path}: expected 12 numbers per line")
            poses.append([v[0:4], v[4:8], v[8:12]])
    return poses


def inverse(T):
    R = [[T[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(R[i][j] * T[j][3] for j in range(3)) for i in range(3)]
    return [R[i] + [t[i]] for i in range(3)]


def compose(A, B):
    out = []
    for i in range(3):
        row = [sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)]
        row.append(sum(A[i][k] * B[k][3] for k in range(3)) + A[i][3])
        out.append(row)
    return out


def frame_errors(gt, est):
    """Translation error of each relative motion k -> k+1."""
    n = min(len(gt), len(est))
    errors = []
    for k in range(n - 1):
        dg = compose(inverse(gt[k]), gt[k + 1])
        de = compose(inverse(est[k]), est[k + 1])
        e = compose(inverse(dg), de)
        errors.append(math.sqrt(sum(e[i][3] ** 2 for i in range(3))))
    return errors


def median(values):
    s = sorted(values)
    if not s:
        return float("nan")
    m = len(s) // 2
    return s[m] if len(s) % 2 else 0.5 * (s[m - 1] + s[m])


def figure(estimate, *path):
    v = estimate
    for p in path:
        v = v.get(p) if isinstance(v, dict) else None
    return v


def path_length(poses):
    """Length (m) of the path through the positions of KITTI poses."""
    positions = [[T[i][3] for i in range(3)] for T in poses]
    return sum(math.dist(a, b) for a, b in zip(positions, positions[1:]))


def estimate_figures(e):
    """APE translation / rotation RMSE, t_rel and r_rel of one estimate of metrics.json."""
    return {
        "ape_m": figure(e, "ape", "translation_m", "rmse"),
        "ape_deg": figure(e, "ape", "rotation_deg", "rmse"),
        "t_rel": figure(e, "kitti", "t_rel_percent"),
        "r_rel": figure(e, "kitti", "r_rel_deg_per_100m"),
    }


def read_spec(run):
    drives = []
    with open(os.path.join(run, "gains.spec")) as f:
        for line in f:
            words = shlex.split(line, comments=True)
            if len(words) >= 3 and words[0] == "sequence":
                drives.append((words[1], words[2]))
    return drives


def drive_row(run, name, dataset):
    folder = os.path.join(run, name, "base")
    metrics_path = os.path.join(folder, "metrics.json")
    if not os.path.exists(metrics_path):
        return {"name": name, "missing": True}
    with open(metrics_path) as f:
        metrics = json.load(f)
    by_label = {e["label"]: e for e in metrics["estimates"]}
    row = {"name": name, "alignment": metrics["options"]["alignment"]}
    gt_path = os.path.join(dataset, "..", "..", "poses", os.path.basename(dataset) + ".txt")
    gt = read_kitti(gt_path)
    prior_path = os.path.join(folder, FILES["prior"])
    if not os.path.exists(prior_path):  # batch runs share it per sequence
        prior_path = os.path.join(run, name, "common", FILES["prior"])
    # The ground truth of a dataset excerpt (KITTI 04 frames 0-50) covers the whole sequence.
    gt = gt[:len(read_kitti(prior_path))]
    row["frames"] = len(gt)
    row["length_m"] = path_length(gt)
    errors = {}
    for key, label in LABELS:
        e = by_label.get(label)
        if e is None:
            row[key] = None
            continue
        row[key] = estimate_figures(e)
        path = prior_path if key == "prior" else os.path.join(folder, FILES[key])
        errors[key] = frame_errors(gt, read_kitti(path))
    prior = errors.get("prior", [])
    threshold = STEP_FACTOR * median(prior)
    steps = [k for k, e in enumerate(prior) if e > threshold]
    row["step_threshold_m"] = threshold
    row["prior_steps"] = len(steps)
    row["steps"] = [{"frame": k, **{key: errors[key][k] for key in errors}} for k in steps]
    row["_errors"] = errors  # for --plot; not written to the JSON
    for key in ("without", "with"):
        if key in errors:
            row[key]["surviving_steps"] = sum(1 for k in steps if errors[key][k] > threshold)
    if prior:
        worst = max(range(len(prior)), key=lambda k: prior[k])
        row["worst_step"] = {"frame": worst, "prior_m": prior[worst]}
        for key in ("without", "with"):
            if key in errors:
                row["worst_step"][key + "_m"] = errors[key][worst]
    return row


def fmt(v, digits=3):
    return "-" if v is None else f"{v:.{digits}f}"


def write_markdown(rows, path):
    lines = [
        "| drive | frames | km | APE t prior / w.o. / w. (m) | APE r prior / w.o. / w. (deg) "
        "| t_rel prior / w.o. / w. (%) | r_rel prior / w.o. / w. (deg/100 m) "
        "| w.o./prior | w./w.o. | steps of the prior (surviving w.o. / w.) "
        "| worst step: frame, prior / w.o. / w. (m) |",
        "|---|---:|---:|---|---|---|---|---:|---:|---|---|",
    ]
    for r in rows:
        if r.get("missing"):
            lines.append(f"| {r['name']} | missing |" + " |" * 9)
            continue
        p, wo, w = r["prior"], r["without"], r["with"]
        cell = lambda k, d=3: " / ".join(fmt(x[k], d) for x in (p, wo, w))  # noqa: E731
        ws = r.get("worst_step", {})
        name = r["name"] + (" (no alignment)" if r["alignment"] == "none" else "")
        lines.append(
            f"| {name} | {r['frames']} | {r['length_m'] / 1000:.2f} | {cell('ape_m')} "
            f"| {cell('ape_deg')} | {cell('t_rel', 2)} | {cell('r_rel', 3)} "
            f"| {fmt(r['ratio_without_prior'], 2)} | {fmt(r['ratio_with_without'], 2)} "
            f"| {r['prior_steps']} ({wo['surviving_steps']} / {w['surviving_steps']}) "
            f"| {ws.get('frame', '-')}: {fmt(ws.get('prior_m'))} / {fmt(ws.get('without_m'))} / "
            f"{fmt(ws.get('with_m'))} |")
    sims = [r for r in rows if not r.get("missing") and r["alignment"] != "none"]
    if sims:
        a = sum(r["ratio_without_prior"] for r in sims) / len(sims)
        b = sum(r["ratio_with_without"] for r in sims) / len(sims)
        worst = max(sims, key=lambda r: r["ratio_with_without"])
        lines += [
            "",
            f"Simulated drives ({len(sims)}): mean APE(w.o.)/APE(prior) = {a:.3f}, "
            f"mean APE(w.)/APE(w.o.) = {b:.3f}, largest APE(w.)/APE(w.o.) = "
            f"{worst['ratio_with_without']:.3f} ({worst['name']}); prior steps "
            f"{sum(r['prior_steps'] for r in sims)}, surviving w.o. "
            f"{sum(r['without']['surviving_steps'] for r in sims)}, w. "
            f"{sum(r['with']['surviving_steps'] for r in sims)}.",
        ]
    text = "\n".join(lines) + "\n"
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
    return text


def plot_steps(rows, path):
    """The steps before and after (see the module's docstring)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sims = [r for r in rows if not r.get("missing") and r["alignment"] != "none" and r["steps"]]
    if not sims:
        print("gains_table: no steps of the prior on the simulated drives: no plot", file=sys.stderr)
        return
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    ax = axes[0]
    for key, marker, color in (("without", "o", "tab:blue"), ("with", "s", "tab:red")):
        xs = [s["prior"] / r["step_threshold_m"] for r in sims for s in r["steps"]]
        ys = [s[key] / r["step_threshold_m"] for r in sims for s in r["steps"]]
        ax.scatter(xs, ys, s=14, marker=marker, facecolors="none", edgecolors=color,
                   label=f"{dict(LABELS)[key]} ({len(xs)} steps)")
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="threshold (5x the prior's median)")
    ax.set_xscale("log")
    ax.set_xlabel("prior's frame-to-frame error at the step / threshold")
    ax.set_ylabel("result's error at that frame / threshold")
    ax.set_title("every step of the prior (%d simulated drives have steps)" % len(sims), fontsize=9)
    ax.legend(fontsize=8)

    def around(ax, r, step, title):
        k = step["frame"]
        lo, hi = max(0, k - 15), min(len(r["_errors"]["prior"]), k + 16)
        frames = list(range(lo, hi))
        for key, label in LABELS:
            if key in r["_errors"]:
                ax.plot(frames, [1e3 * r["_errors"][key][f] for f in frames], marker=".",
                        label=label)
        ax.axhline(1e3 * r["step_threshold_m"], color="k", lw=0.8, ls="--", label="threshold")
        ax.axvline(k, color="0.6", lw=0.8)
        ax.set_yscale("log")
        ax.set_xlabel("frame")
        ax.set_ylabel("frame-to-frame translation error (mm)")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8)

    worst_prior = max(((r, s) for r in sims for s in r["steps"]),
                      key=lambda rs: rs[1]["prior"] / rs[0]["step_threshold_m"])
    worst_result = max(((r, s) for r in sims for s in r["steps"]),
                       key=lambda rs: max(rs[1]["without"], rs[1]["with"]) /
                       rs[0]["step_threshold_m"])
    for ax, (r, s), what in ((axes[1], worst_prior, "the prior's worst step"),
                             (axes[2], worst_result, "the step the results keep most of")):
        around(ax, r, s, "%s: %s frame %d\n(prior %.1f, w.o. %.1f, w. %.1f mm)" % (
            what, r["name"], s["frame"], 1e3 * s["prior"], 1e3 * s["without"], 1e3 * s["with"]))
    fig.tight_layout()
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=90)
    os.replace(tmp, path)
    print(f"gains_table: wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run")
    parser.add_argument("-o", "--output")
    parser.add_argument("--json")
    parser.add_argument("--plot", help="the steps before and after (PNG; needs matplotlib)")
    args = parser.parse_args()
    rows = []
    for name, dataset in read_spec(args.run):
        row = drive_row(args.run, name, dataset)
        if not row.get("missing"):
            row["ratio_without_prior"] = row["without"]["ape_m"] / row["prior"]["ape_m"]
            row["ratio_with_without"] = row["with"]["ape_m"] / row["without"]["ape_m"]
        rows.append(row)
    text = write_markdown(rows, args.output or os.path.join(args.run, "gains.md"))
    if args.plot:
        plot_steps(rows, args.plot)
    json_path = args.json or os.path.join(args.run, "gains.json")
    with open(json_path + ".tmp", "w") as f:
        json.dump([{k: v for k, v in r.items() if k != "_errors"} for r in rows], f, indent=1)
    os.replace(json_path + ".tmp", json_path)
    sys.stdout.write(text)
    return 0 if any(not r.get("missing") for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
