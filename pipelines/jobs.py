#!/usr/bin/env python3
"""Sequences x configurations for batch runs of Makefile.example (standard library only).

    jobs.py list SPEC [-o JOBS.txt] [--phase common|config|reweight]
    jobs.py makefile JOBS.txt [-o batch.mk]
    jobs.py task JOBS.txt INDEX [--run DIR] [--dry-run]

A spec names the sequences and the configurations (docs/ablations.md):

    sequence NAME DATASET [VAR=value ...]   one sequence; its own variables (GT, PRIOR, ODOM_N)
    set VAR=value ...                       the base configuration
    vary VAR=v1,v2,...                      one configuration per value, the rest at base
    grid VAR=v1,v2 VAR2=w1,w2 ...           every combination

Words are split as by the shell (quotes, # comments); $NAME / ${NAME} expand from the
environment. Relative paths are relative to the repository root, where the tasks run.

The job list has one task per line, `PHASE SEQUENCE CONFIG VAR=value ...` (shell quoting):
`common` (per sequence: the prior and the vanishing points), `config` (the chain from
direction_cluster to evaluate in the configuration's folder) and `reweight` (global_opt +
evaluate, and Makefile.example's re-association passes after the first, reusing the pass-1
artifacts of the configuration named by UPSTREAM=). A task runs
`make -f Makefile.example` in RUN/SEQUENCE/CONFIG; the phases must run in this order.
"""
import argparse
import itertools
import json
import os
import re
import shlex
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PHASES = ("common", "config", "reweight")
# Makefile.example variables, in the order they are written to a job line.
SEQUENCE_VARS = ("DATASET", "GT", "PRIOR", "ODOM_N")  # fixed per sequence (common phase)
# change direction_cluster / visual_assoc / local_map
UPSTREAM_VARS = ("N", "V_INTERVAL", "VISUAL_OPTS", "LOCAL_OPTS")
# global_opt + evaluate (and the re-association passes p > 1, which live in the task's own folder)
REWEIGHT_VARS = ("ALPHA", "BETA", "GAMMA", "GLOBAL_OPTS", "ALIGN", "PASSES", "LOOPS")
OTHER_VARS = ("THREADS", "BIN")
KNOWN_VARS = SEQUENCE_VARS + UPSTREAM_VARS + REWEIGHT_VARS + OTHER_VARS


class SpecError(Exception):
    pass


class Spec:
    """Parsed spec: sequences [(name, vars)], base vars, tables [(vars, [config diffs])]."""

    def __init__(self):
        self.sequences = []
        self.base = {}
        self.tables = []

    def configs(self):
        """Every configuration once, in spec order: [(name, diff)], 'base' first."""
        seen, out = {}, []

        def add(diff):
            name = config_name(diff)
            if seen.setdefault(name, diff) != diff:
                raise SpecError(f"configurations {seen[name]} and {diff} have the same folder "
                                f"name '{name}'")
            if len(seen) > len(out):
                out.append((name, diff))

        for diff in [{}] + [d for _, diffs in self.tables for d in diffs]:
            add(diff)
        # A reweight configuration needs its upstream configuration (same N, V_interval).
        for _, diff in list(out):
            add(upstream_diff(diff))
        return out


def parse_assignment(token, where):
    if "=" not in token:
        raise SpecError(f"{where}: expected VAR=value, got '{token}'")
    var, value = token.split("=", 1)
    if var not in KNOWN_VARS:
        raise SpecError(f"{where}: unknown variable '{var}' (known: {' '.join(KNOWN_VARS)})")
    return var, value


def expand(word, where):
    """$NAME and ${NAME} from the environment (e.g. the dataset root); unset is an error."""
    def value(m):
        name = m.group(1) or m.group(2)
        if name not in os.environ:
            raise SpecError(f"{where}: environment variable {name} is not set")
        return os.environ[name]
    return re.sub(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}|\$([A-Za-z_][A-Za-z0-9_]*)", value, word)


def parse_spec(text, path="spec"):
    spec = Spec()
    for number, line in enumerate(text.splitlines(), 1):
        where = f"{path}:{number}"
        try:
            words = [expand(w, where) for w in shlex.split(line, comments=True)]
        except ValueError as e:
            raise SpecError(f"{where}: {e}")
        if not words:
            continue
        key, args = words[0], words[1:]
        if key == "sequence":
            if len(args) < 2 or not re.fullmatch(r"[A-Za-z0-9_.+-]+", args[0]):
                raise SpecError(f"{where}: expected 'sequence NAME DATASET [VAR=value ...]'")
            if args[0] in [n for n, _ in spec.sequences]:
                raise SpecError(f"{where}: sequence '{args[0]}' given twice")
            seq_vars = {"DATASET": args[1]}
            seq_vars.update(parse_assignment(a, where) for a in args[2:])
            spec.sequences.append((args[0], seq_vars))
        elif key == "set":
            spec.base.update(parse_assignment(a, where) for a in args)
        elif key in ("vary", "grid"):
            if not args or (key == "vary" and len(args) != 1):
                raise SpecError(f"{where}: expected '{key} VAR=v1,v2,...'" +
                                (" (one variable; use grid for several)" if key == "vary" else ""))
            axes = [parse_assignment(a, where) for a in args]
            for var, _ in axes:
                if var in SEQUENCE_VARS or var in OTHER_VARS:
                    raise SpecError(f"{where}: {var} cannot vary within a sequence; "
                                    "write one sequence line per value instead")
            values = [[(var, v) for v in text_values.split(",")] for var, text_values in axes]
            spec.tables.append(([var for var, _ in axes],
                                [dict(combo) for combo in itertools.product(*values)]))
        else:
            raise SpecError(f"{where}: unknown keyword '{key}' (sequence, set, vary, grid)")
    if not spec.sequences:
        raise SpecError(f"{path}: no 'sequence' line")
    for i, (variables, diffs) in enumerate(spec.tables):
        spec.tables[i] = (variables, [relative_to_base(d, spec.base) for d in diffs])
    return spec


def relative_to_base(diff, base):
    """Drops assignments equal to the base, so that e.g. V_INTERVAL=0 is the base config.
    An empty value is the Makefile's default (for BETA and GAMMA: the residual-count rule)."""
    return {k: v for k, v in diff.items() if base.get(k, "") != v}


def upstream_diff(diff):
    return {k: v for k, v in diff.items() if k not in REWEIGHT_VARS}


def config_name(diff):
    if not diff:
        return "base"
    parts = []
    for var, value in ordered(diff):  # a fixed order: one folder per configuration
        value = re.sub(r"[^A-Za-z0-9.+]+", "-", value).strip("-") or "default"
        parts.append(f"{var.lower()}-{value}")
    return "_".join(parts)


def phase_of(diff):
    return "reweight" if upstream_diff(diff) != diff else "config"


def ordered(variables):
    return [(k, variables[k]) for k in KNOWN_VARS + ("UPSTREAM", "VPS", "OUT") if k in variables]


def job_lines(spec, phase=None):
    """One line per task: common tasks, then config tasks, then reweight tasks."""
    rows = []
    for seq, seq_vars in spec.sequences:
        base = dict(spec.base, **seq_vars)
        rows.append(("common", seq, "common",
                     {k: v for k, v in base.items() if k in SEQUENCE_VARS + OTHER_VARS}))
        for name, diff in spec.configs():
            variables = dict(base, **diff)
            if phase_of(diff) == "reweight":
                variables["UPSTREAM"] = config_name(upstream_diff(diff))
            rows.append((phase_of(diff), seq, name, variables))
    rows.sort(key=lambda r: PHASES.index(r[0]))  # stable: spec order within a phase
    return [" ".join([p, s, c] + [shlex.quote(f"{k}={v}") for k, v in ordered(variables)])
            for p, s, c, variables in rows if phase in (None, p)]


def parse_job_line(line, where):
    words = shlex.split(line)
    if len(words) < 3 or words[0] not in PHASES:
        raise SpecError(f"{where}: expected 'PHASE SEQUENCE CONFIG VAR=value ...'")
    variables = {}
    for token in words[3:]:
        if "=" not in token:
            raise SpecError(f"{where}: expected VAR=value, got '{token}'")
        var, value = token.split("=", 1)
        variables[var] = value
    return words[0], words[1], words[2], variables


def read_jobs(path):
    try:
        with open(path) as f:
            lines = [l for l in f.read().splitlines() if l.strip() and not l.startswith("#")]
    except OSError as e:
        raise SpecError(f"{path}: cannot read the job list ({e.strerror})")
    return [parse_job_line(l, f"{path}:{i}") for i, l in enumerate(lines, 1)]


def make_command(run, phase, seq, config, variables):
    """The make invocation of one task; paths are resolved against the run folder."""
    seq_dir = os.path.join(run, seq)
    variables = dict(variables, OUT=os.path.join(seq_dir, config))
    if phase != "common":
        variables["VPS"] = os.path.join(seq_dir, "common", "vps.h5")
        if variables.get("PRIOR", "lidar") == "lidar":
            variables["PRIOR"] = os.path.join(seq_dir, "common", "odom.h5")
    if phase == "reweight":
        variables["UPSTREAM"] = os.path.join(seq_dir, variables["UPSTREAM"])
    target = "common" if phase == "common" else "all"
    return ([os.environ.get("MAKE", "make"), "--no-print-directory", "-f",
             os.path.join(ROOT, "Makefile.example")] +
            [f"{k}={v}" for k, v in ordered(variables)] + [target])


def missing_inputs(run, phase, seq, variables):
    """Artifacts an earlier phase must have written (a task never builds shared ones)."""
    seq_dir = os.path.join(run, seq)
    need = []
    if phase != "common":
        need.append(os.path.join(seq_dir, "common", "vps.h5"))
        if variables.get("PRIOR", "lidar") == "lidar":
            need.append(os.path.join(seq_dir, "common", "odom.h5"))
    if phase == "reweight":
        need += [os.path.join(seq_dir, variables["UPSTREAM"], f)
                 for f in ("directions.h5", "visual.h5", "local.h5")]
    return [p for p in need if not os.path.isfile(p)]


def make_dry_run():
    """True under `make -n` of a generated batch makefile: print, do not run."""
    flags = os.environ.get("MAKEFLAGS", "").split()
    return bool(flags) and not flags[0].startswith("-") and "n" in flags[0]


def run_task(jobs_path, index, run, dry_run):
    jobs = read_jobs(jobs_path)
    if not 1 <= index <= len(jobs):
        raise SpecError(f"{jobs_path}: task {index} out of range 1..{len(jobs)}")
    phase, seq, config, variables = jobs[index - 1]
    cmd = make_command(run, phase, seq, config, variables)
    if dry_run or make_dry_run():
        print(shlex.join(cmd))
        return 0
    missing = missing_inputs(run, phase, seq, variables)
    if missing:
        raise SpecError(f"task {index} ({phase} {seq} {config}): {missing[0]} is missing; "
                        "run the earlier phases first")
    print(f"task {index}: {phase} {seq} {config}", file=sys.stderr, flush=True)
    out = os.path.join(run, seq, config)
    product = os.path.join(out, "vps.h5" if phase == "common" else "metrics.json")
    before = mtime(product)
    start = time.time()
    # close_fds=False keeps the make jobserver of a calling `make -j` open for the child.
    code = subprocess.run(cmd, cwd=ROOT, close_fds=False).returncode
    record = {"task": index, "phase": phase, "sequence": seq, "config": config,
              "exit_code": code, "wall_time_s": round(time.time() - start, 3),
              "command": shlex.join(cmd)}
    # task.json keeps the time of the run that made the outputs, not of a later no-op rerun.
    os.makedirs(out, exist_ok=True)
    record_path = os.path.join(out, "task.json")
    if code != 0 or mtime(product) != before or not os.path.isfile(record_path):
        with open(record_path, "w") as f:
            json.dump(record, f, indent=1)
            f.write("\n")
    return code


def mtime(path):
    try:
        return os.stat(path).st_mtime_ns
    except OSError:
        return None


def batch_makefile(jobs_path, run):
    """A makefile with one phony target per task and the dependencies between them."""
    jobs = read_jobs(jobs_path)
    index = {(p, s, c): i for i, (p, s, c, _) in enumerate(jobs, 1)}
    me = os.path.abspath(__file__)
    lines = [f"# Generated by pipelines/jobs.py from {os.path.basename(jobs_path)}; "
             "run: make -f THIS -j2 -k",
             f"TASK := {shlex.quote(sys.executable)} {shlex.quote(me)} task "
             f"{shlex.quote(os.path.abspath(jobs_path))} --run {shlex.quote(run)}",
             f"LOGS := {shlex.quote(os.path.join(run, 'logs'))}",
             ".PHONY: all " + " ".join(f"t{i}" for i in range(1, len(jobs) + 1)),
             "all: " + " ".join(f"t{i}" for i in range(1, len(jobs) + 1)), ""]
    for i, (phase, seq, config, variables) in enumerate(jobs, 1):
        deps = []
        if phase != "common":
            deps.append(index.get(("common", seq, "common")))
        if phase == "reweight":
            deps.append(index.get(("config", seq, variables.get("UPSTREAM"))))
        lines.append(f"t{i}: " + " ".join(f"t{d}" for d in deps if d))
        lines.append(f"\t+@mkdir -p $(LOGS) && echo '[{i}/{len(jobs)}] {phase} {seq} {config}' && "
                     f"$(TASK) {i} > $(LOGS)/{i}.log 2>&1 || "
                     f"{{ tail -n 20 $(LOGS)/{i}.log; echo 'task {i} failed: $(LOGS)/{i}.log'; "
                     "exit 1; }")
    return "\n".join(lines) + "\n"


def write(text, path):
    if path in (None, "-"):
        sys.stdout.write(text)
    else:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        with open(path, "w") as f:
            f.write(text)


def read_spec(path):
    try:
        with open(path) as f:
            return parse_spec(f.read(), path)
    except OSError as e:
        raise SpecError(f"{path}: cannot read the spec ({e.strerror})")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("list", help="the job list of a spec")
    p.add_argument("spec")
    p.add_argument("-o", "--output")
    p.add_argument("--phase", choices=PHASES)
    p = sub.add_parser("makefile", help="a makefile running a job list with make -j")
    p.add_argument("jobs")
    p.add_argument("-o", "--output")
    p.add_argument("--run", help="run folder (default: the job list's folder)")
    p = sub.add_parser("task", help="run one line of a job list (1-based)")
    p.add_argument("jobs")
    p.add_argument("index", type=int)
    p.add_argument("--run", help="run folder (default: the job list's folder)")
    p.add_argument("--dry-run", action="store_true", help="print the make command only")
    args = parser.parse_args(argv)
    try:
        if args.command == "list":
            lines = job_lines(read_spec(args.spec), args.phase)
            write("".join(l + "\n" for l in lines), args.output)
            return 0
        run = os.path.abspath(args.run or os.path.dirname(os.path.abspath(args.jobs)))
        if args.command == "makefile":
            write(batch_makefile(args.jobs, run), args.output)
            return 0
        return run_task(args.jobs, args.index, run, args.dry_run)
    except SpecError as e:
        print(f"jobs.py: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
