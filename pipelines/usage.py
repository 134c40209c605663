#!/usr/bin/env python3
"""Runs a command and writes its wall time, CPU time and peak memory as JSON (standard library).

    usage.py OUT.json -- COMMAND [ARGS...]

OUT.json: {"wall_s", "cpu_s" (user + system of the command and its children), "peak_mib"
(largest resident set of the command or a child), "exit_code"}. Written atomically, also when
the command fails; the exit code is the command's.
"""
import json
import os
import resource
import subprocess
import sys
import time


def main():
    if len(sys.argv) < 4 or sys.argv[2] != "--":
        sys.stderr.write("usage: usage.py OUT.json -- COMMAND [ARGS...]\n")
        return 2
    out, command = sys.argv[1], sys.argv[3:]
    start = time.monotonic()
    try:
        code = subprocess.call(command)
    except OSError as e:
        sys.stderr.write(f"usage.py: cannot run {command[0]}: {e.strerror}\n")
        return 127
    wall = time.monotonic() - start
    if code < 0:  # killed by signal -code: the shell's convention
        code = 128 - code
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    figures = {"wall_s": round(wall, 2), "cpu_s": round(children.ru_utime + children.ru_stime, 2),
               "peak_mib": round(children.ru_maxrss / 1024.0, 1), "exit_code": code}
    with open(out + ".tmp", "w") as f:
        json.dump(figures, f)
        f.write("\n")
    os.replace(out + ".tmp", out)
    return code


if __name__ == "__main__":
    sys.exit(main())
