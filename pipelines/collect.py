#!/usr/bin/env python3
"""Merges the metrics of a batch run into ablation tables and plots (standard library only).

    collect.py SPEC RUN_DIR [-o DIR] [--estimate LABEL] [--cell r_rel/ape] [--no-plots]

Reads RUN_DIR/SEQUENCE/CONFIG/metrics.json (evaluate --json, schema "metrics" v1) of every
sequence x configuration of SPEC (pipelines/jobs.py) and writes to DIR (default RUN_DIR/tables):

    ablations.md      one table per `vary` / `grid` line: rows = configurations,
                      columns = sequences, cells "r_rel/APE" as in the paper
    TABLE.csv         the same table as CSV (TABLE = the varied variables, e.g. v_interval.csv)
    metrics.csv       every sequence x configuration x estimate with all figures
    plot_data.json    what the plots are drawn from; plots by pipelines/plot_ablations.py:
    ape_vs_VAR.png    APE RMSE against a numeric variable (with / without direction priors)
    ape_box_TABLE.png per-frame APE distribution per configuration (from evaluate's plot data)

Nothing is executed but the plotting script. Missing results give "missing" cells and a
warning; the exit code is non-zero only when no result at all was found.
"""
import argparse
import csv
import io
import json
import os
import subprocess
import sys
import textwrap

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import jobs  # noqa: E402

WITH, WITHOUT, PRIOR = "w. direction priors", "w.o. direction priors", "prior"
# Figures taken from each estimate of a metrics report: name -> (path in the JSON, needs KITTI
# segments). r_rel and t_rel are undefined (not 0) when the path is shorter than 100 m.
FIGURES = {
    "ape": (("ape", "translation_m", "rmse"), False),
    "ape_deg": (("ape", "rotation_deg", "rmse"), False),
    "rpe": (("rpe", "translation_m", "mean"), False),
    "rpe_percent": (("rpe", "translation_percent", "mean"), False),
    "rpe_deg": (("rpe", "rotation_deg", "mean"), False),
    "t_rel": (("kitti", "t_rel_percent"), True),
    "r_rel": (("kitti", "r_rel_deg_per_100m"), True),
}
CSV_NAMES = {"ape": "ape_rmse_m", "ape_deg": "ape_rmse_deg", "rpe": "rpe_mean_m",
             "rpe_percent": "rpe_mean_percent", "rpe_deg": "rpe_mean_deg",
             "t_rel": "t_rel_percent", "r_rel": "r_rel_deg_per_100m"}
UNITS = {"ape": "APE RMSE (m)", "ape_deg": "APE RMSE (deg)", "rpe": "RPE mean (m)",
         "rpe_percent": "RPE mean (%)", "rpe_deg": "RPE mean (deg)", "t_rel": "t_rel (%)",
         "r_rel": "r_rel (deg/100 m)"}


def warn(message):
    print(f"collect.py: {message}", file=sys.stderr)


def dig(node, path):
    for key in path:
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node if isinstance(node, (int, float)) else None


def read_metrics(path):
    """{label: {figure: value or None, 'frames': n, 'segments': n}}, or None if unreadable."""
    try:
        with open(path) as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        warn(f"{path}: {getattr(e, 'strerror', None) or e}")
        return None
    if report.get("schema") != "metrics":
        warn(f"{path}: not a metrics report (schema '{report.get('schema')}')")
        return None
    out = {}
    for est in report.get("estimates", []):
        segments = dig(est, ("kitti", "segments")) or 0
        figures = {name: (None if needs_segments and segments == 0 else dig(est, path))
                   for name, (path, needs_segments) in FIGURES.items()}
        figures.update(frames=est.get("frames_matched"), segments=segments)
        out[est.get("label")] = figures
    return out


def read_ape_frames(path):
    """{label: per-frame translation APE} from evaluate's plots/plot_data.json."""
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError):
        return {}
    out = {}
    for est in data.get("estimates", []):
        values = [v for s in est.get("sequences", []) for v in s.get("ape_translation_m", [])]
        out[est.get("label")] = values
    return out


def value_text(var, value):
    if value == "":
        return "rule" if var == "BETA" else "default"
    return value


def row_label(variables, full):
    if len(variables) == 1:
        return value_text(variables[0], full.get(variables[0], ""))
    return ", ".join(f"{v}={value_text(v, full.get(v, ''))}" for v in variables)


def table_names(spec):
    names, out = {}, []
    for variables, _ in spec.tables:
        name = "_".join(v.lower() for v in variables)
        names[name] = names.get(name, 0) + 1
        out.append(name if names[name] == 1 else f"{name}-{names[name]}")
    return out


def fmt(x, digits):
    return "-" if x is None else f"{x:.{digits}f}"


def cell(figures, cell_spec, digits):
    if figures is None:
        return "missing"
    return "/".join(fmt(figures.get(name), digits) for name in cell_spec)


def csv_text(rows):
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()


def number(x):
    return "" if x is None else repr(x)


class Collection:
    def __init__(self, spec, run, estimate, with_frames):
        self.spec, self.run, self.estimate = spec, run, estimate
        self.sequences = [name for name, _ in spec.sequences]
        self.metrics, self.frames = {}, {}
        for seq in self.sequences:
            for config, _ in spec.configs():
                folder = os.path.join(run, seq, config)
                path = os.path.join(folder, "metrics.json")
                self.metrics[seq, config] = read_metrics(path) if os.path.isfile(path) else None
                if self.metrics[seq, config] is None and not os.path.isfile(path):
                    warn(f"{path} is missing")
                if with_frames:
                    self.frames[seq, config] = read_ape_frames(
                        os.path.join(folder, "plots", "plot_data.json"))

    def figures(self, seq, config, label):
        report = self.metrics.get((seq, config))
        if report is None:
            return None
        if label not in report:
            warn(f"{os.path.join(self.run, seq, config, 'metrics.json')}: no estimate '{label}'")
            return None
        return report[label]

    def found(self):
        return sum(1 for v in self.metrics.values() if v is not None)


def table_rows(spec, variables, diffs):
    """[(label, config name, full variables)] of one table, in spec order, without repeats."""
    rows, seen = [], set()
    for diff in diffs:
        name = jobs.config_name(diff)
        if name not in seen:
            seen.add(name)
            full = dict(spec.base, **diff)
            rows.append((row_label(variables, full), name, full))
    return rows


def markdown(c, cell_spec, digits, spec_name):
    what = "/".join(UNITS[n] for n in cell_spec)
    base_vars = " ".join(f"{k}={v}" for k, v in jobs.ordered(c.spec.base)) or "(Makefile defaults)"
    intro = (f"Spec `{spec_name}`, base configuration `{base_vars}`. Each cell is {what} of "
             f"\"{c.estimate}\", sequences in columns. The last two rows are the base "
             "configuration's estimates without direction priors and the prior. \"-\": "
             "undefined (r_rel and t_rel need segments of at least 100 m); \"missing\": no "
             "result.")
    lines = ["# Ablations", "", textwrap.fill(intro, 100, break_on_hyphens=False), ""]
    for name, (variables, diffs) in zip(table_names(c.spec), c.spec.tables):
        header = " x ".join(variables)
        lines += [f"## {header}", "", f"| {header} | " + " | ".join(c.sequences) + " |",
                  "|---|" + "---:|" * len(c.sequences)]
        for label, config, _ in table_rows(c.spec, variables, diffs):
            cells = [cell(c.figures(s, config, c.estimate), cell_spec, digits)
                     for s in c.sequences]
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
        for ref in (WITHOUT, PRIOR):
            cells = [cell(c.figures(s, "base", ref), cell_spec, digits) for s in c.sequences]
            lines.append(f"| {ref} (base) | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines + run_times(c))


def run_times(c):
    """Wall time of every task (its task.json, written by jobs.py task), if there are any."""
    rows, total, found = [], 0.0, False
    for config in ["common"] + [name for name, _ in c.spec.configs()]:
        cells = []
        for seq in c.sequences:
            try:
                with open(os.path.join(c.run, seq, config, "task.json")) as f:
                    seconds = float(json.load(f)["wall_time_s"])
                cells.append(f"{seconds:.0f}")
                total += seconds
                found = True
            except (OSError, ValueError, KeyError, TypeError):
                cells.append("-")
        rows.append(f"| {config} | " + " | ".join(cells) + " |")
    if not found:
        return []
    return ["## Run time (s per task)", "",
            f"Total {total:.0f} s of task wall time (tasks may overlap under make -j).", "",
            "| task | " + " | ".join(c.sequences) + " |",
            "|---|" + "---:|" * len(c.sequences)] + rows + [""]


def table_csv(c, variables, diffs, cell_spec, digits):
    rows = [[" x ".join(variables), "config"] + c.sequences]
    for label, config, _ in table_rows(c.spec, variables, diffs):
        rows.append([label, config] + [cell(c.figures(s, config, c.estimate), cell_spec, digits)
                                       for s in c.sequences])
    for ref in (WITHOUT, PRIOR):
        rows.append([f"{ref} (base)", "base"] +
                    [cell(c.figures(s, "base", ref), cell_spec, digits) for s in c.sequences])
    return csv_text(rows)


def metrics_csv(c):
    varied = [v for v in jobs.KNOWN_VARS if any(v in d for _, d in c.spec.configs())]
    rows = [["sequence", "config"] + varied + ["estimate", "frames"] +
            [CSV_NAMES[n] for n in FIGURES] + ["segments"]]
    for seq in c.sequences:
        for config, diff in c.spec.configs():
            report = c.metrics.get((seq, config)) or {}
            full = dict(c.spec.base, **diff)
            for label, figures in report.items():
                rows.append([seq, config] + [full.get(v, "") for v in varied] +
                            [label, figures["frames"]] +
                            [number(figures[n]) for n in FIGURES] + [figures["segments"]])
    return csv_text(rows)


def plot_data(c):
    tables = []
    for name, (variables, diffs) in zip(table_names(c.spec), c.spec.tables):
        rows = []
        for label, config, full in table_rows(c.spec, variables, diffs):
            x = None
            if len(variables) == 1:
                try:
                    x = float(full.get(variables[0], ""))
                except ValueError:
                    pass
            rows.append({"label": label, "config": config, "x": x,
                         "ape": {s: (c.figures(s, config, c.estimate) or {}).get("ape")
                                 for s in c.sequences},
                         "ape_without": {s: (c.figures(s, config, WITHOUT) or {}).get("ape")
                                         for s in c.sequences},
                         "ape_frames": {s: c.frames.get((s, config), {}).get(c.estimate, [])
                                        for s in c.sequences}})
        reference = {s: c.frames.get((s, "base"), {}).get(WITHOUT, []) for s in c.sequences}
        tables.append({"name": name, "variables": variables, "rows": rows,
                       "without_frames": reference})
    return {"estimate": c.estimate, "sequences": c.sequences, "tables": tables}


def run_plots(data_path, out_dir, python):
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plot_ablations.py")
    for candidate in [p for p in (python, sys.executable, "python3", "/usr/bin/python3") if p]:
        try:
            probe = subprocess.run([candidate, "-c", "import matplotlib"],
                                   capture_output=True)
        except OSError:
            continue
        if probe.returncode == 0:
            done = subprocess.run([candidate, script, data_path, out_dir])
            if done.returncode != 0:
                warn(f"plotting failed ({candidate} {script}); tables are written")
            return
    warn("plots skipped: no python3 with matplotlib (Debian: python3-matplotlib)")


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("spec")
    parser.add_argument("run")
    parser.add_argument("-o", "--output", help="output folder (default RUN/tables)")
    parser.add_argument("--estimate", default=WITH, help=f"estimate label (default '{WITH}')")
    parser.add_argument("--cell", default="r_rel/ape",
                        help="figures of a cell, '/'-separated, from: " + ", ".join(FIGURES))
    parser.add_argument("--digits", type=int, default=3, help="decimals in the tables (3)")
    parser.add_argument("--no-plots", action="store_true")
    parser.add_argument("--python", help="interpreter with matplotlib for the plots")
    args = parser.parse_args(argv)
    cell_spec = args.cell.split("/")
    for name in cell_spec:
        if name not in FIGURES:
            print(f"collect.py: --cell: unknown figure '{name}' (known: {', '.join(FIGURES)})",
                  file=sys.stderr)
            return 2
    try:
        spec = jobs.read_spec(args.spec)
        spec.configs()
    except jobs.SpecError as e:
        print(f"collect.py: {e}", file=sys.stderr)
        return 2
    if not os.path.isdir(args.run):
        print(f"collect.py: {args.run}: no such run folder", file=sys.stderr)
        return 2
    c = Collection(spec, args.run, args.estimate, not args.no_plots)
    if c.found() == 0:
        print(f"collect.py: {args.run}: no metrics.json of any sequence x configuration",
              file=sys.stderr)
        return 1
    out = args.output or os.path.join(args.run, "tables")
    os.makedirs(out, exist_ok=True)
    write(os.path.join(out, "ablations.md"),
          markdown(c, cell_spec, args.digits, os.path.basename(args.spec)))
    for name, (variables, diffs) in zip(table_names(spec), spec.tables):
        write(os.path.join(out, f"{name}.csv"),
              table_csv(c, variables, diffs, cell_spec, args.digits))
    write(os.path.join(out, "metrics.csv"), metrics_csv(c))
    print(f"collect.py: {c.found()}/{len(c.metrics)} results -> {out}/ablations.md")
    if not args.no_plots:
        data_path = os.path.join(out, "plot_data.json")
        write(data_path, json.dumps(plot_data(c), indent=1) + "\n")
        run_plots(data_path, out, args.python)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
