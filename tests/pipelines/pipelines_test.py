#!/usr/bin/env python3
"""Batch pipelines without running a stage: job-list generation, the per-task make command, the
batch makefile, the Slurm submission (dry run), the collect step on committed metrics and the
gains table on a hand-made run, and Makefile.example's re-association passes (make -n).

    python3 tests/pipelines/pipelines_test.py      (from the repository root; CTest does this)
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "pipelines", "data")
SPEC = os.path.join(DATA, "small.spec")
JOBS_PY = os.path.join(ROOT, "pipelines", "jobs.py")
COLLECT_PY = os.path.join(ROOT, "pipelines", "collect.py")
GAINS_PY = os.path.join(ROOT, "pipelines", "gains_table.py")
LOOPS_PY = os.path.join(ROOT, "pipelines", "loops_table.py")
USAGE_PY = os.path.join(ROOT, "pipelines", "usage.py")
FIDELITY_PY = os.path.join(ROOT, "scripts", "sim_fidelity.py")
SLOW_BIAS_PY = os.path.join(ROOT, "scripts", "vp_slow_bias.py")
SENSOR_FIDELITY_PY = os.path.join(ROOT, "scripts", "sensor_fidelity.py")
TOPVIEW_PY = os.path.join(ROOT, "scripts", "scene_topview.py")


def run(args, **kwargs):
    return subprocess.run(args, capture_output=True, text=True, cwd=ROOT, **kwargs)


def read(path):
    with open(path) as f:
        return f.read()


class JobList(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="jvl_pipelines_")

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def test_job_list_is_exact(self):
        out = run([sys.executable, JOBS_PY, "list", SPEC])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout, read(os.path.join(DATA, "expected_jobs.txt")))

    def test_phases_partition_the_job_list(self):
        expected = read(os.path.join(DATA, "expected_jobs.txt")).splitlines()
        parts = []
        for phase, count in (("common", 2), ("config", 8), ("reweight", 6)):
            out = run([sys.executable, JOBS_PY, "list", SPEC, "--phase", phase])
            lines = out.stdout.splitlines()
            self.assertEqual(len(lines), count, phase)
            self.assertTrue(all(l.startswith(phase + " ") for l in lines))
            parts += lines
        self.assertEqual(parts, expected)

    def write_jobs(self):
        jobs = os.path.join(self.tmp, "jobs.txt")
        shutil.copy(os.path.join(DATA, "expected_jobs.txt"), jobs)
        return jobs

    def task_command(self, index):
        out = run([sys.executable, JOBS_PY, "task", self.write_jobs(), str(index), "--dry-run"])
        self.assertEqual(out.returncode, 0, out.stderr)
        return out.stdout.strip().replace(self.tmp, "RUN").replace(ROOT, "ROOT")

    def test_task_commands(self):
        make = "make --no-print-directory -f ROOT/Makefile.example "
        d04 = "DATASET=../shared/data/kitti_odometry_04_f0-50/sequences/04"
        self.assertEqual(self.task_command(1), make + d04 + " ODOM_N=1 OUT=RUN/04/common common")
        # A config task reads the sequence's shared prior (lidar_odom) and vanishing points.
        self.assertEqual(self.task_command(4), make + d04 + " PRIOR=RUN/04/common/odom.h5 "
                         "ODOM_N=1 N=10 V_INTERVAL=5 ALIGN=none VPS=RUN/04/common/vps.h5 "
                         "OUT=RUN/04/v_interval-5 all")
        # An external prior is used as given; a reweight task reuses its upstream config.
        self.assertEqual(self.task_command(16), make + "DATASET=/data/sim/sequences/00 "
                         "PRIOR=/data/sim/prior.h5 N=10 V_INTERVAL=0 BETA=10 GAMMA=50 ALIGN=none "
                         "UPSTREAM=RUN/sim/base VPS=RUN/sim/common/vps.h5 "
                         "OUT=RUN/sim/beta-10_gamma-50 all")

    def test_task_refuses_to_run_before_its_inputs_exist(self):
        out = run([sys.executable, JOBS_PY, "task", self.write_jobs(), "11"])
        self.assertEqual(out.returncode, 2)
        self.assertIn("04/common/vps.h5 is missing", out.stderr)
        out = run([sys.executable, JOBS_PY, "task", self.write_jobs(), "17"])
        self.assertEqual(out.returncode, 2)
        self.assertIn("task 17 out of range 1..16", out.stderr)

    def test_batch_makefile_orders_the_tasks(self):
        out = run([sys.executable, JOBS_PY, "makefile", self.write_jobs()])
        self.assertEqual(out.returncode, 0, out.stderr)
        deps = {l.split(":")[0]: l.split(":")[1].split() for l in out.stdout.splitlines()
                if l[:1] == "t" and ":" in l}
        self.assertEqual(len(deps), 16)
        self.assertEqual(deps["t1"], [])
        self.assertEqual(deps["t4"], ["t1"])  # 04 v_interval-5 after 04 common
        self.assertEqual(deps["t8"], ["t2"])  # sim v_interval-5 after sim common
        self.assertEqual(deps["t16"], ["t2", "t7"])  # sim reweight after sim base

    def test_spec_errors_name_the_line(self):
        cases = [("sequence 04 /d\nvary V_INTERVALL=1,2\n", "bad.spec:2: unknown variable"),
                 ("sequence 04 /d\nvary DATASET=/a,/b\n", "bad.spec:2: DATASET cannot vary"),
                 ("set N=1\n", "bad.spec: no 'sequence' line"),
                 ("sequence 04 /d\nfoo N=1\n", "bad.spec:2: unknown keyword 'foo'"),
                 ("sequence 04 /d\nvary N=1 V_INTERVAL=2\n", "bad.spec:2: expected 'vary")]
        for text, message in cases:
            spec = os.path.join(self.tmp, "bad.spec")
            with open(spec, "w") as f:
                f.write(text)
            out = run([sys.executable, JOBS_PY, "list", spec])
            self.assertEqual(out.returncode, 2, text)
            self.assertIn(message, out.stderr, text)
            self.assertEqual(len(out.stderr.strip().splitlines()), 1, out.stderr)

    def test_slurm_submit_dry_run(self):
        out = run(["bash", os.path.join(ROOT, "pipelines", "slurm", "submit"), SPEC, self.tmp,
                   "--dry-run", "--partition=cpu"])
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertEqual(len(lines), 4)
        for line, phase, n in zip(lines, ("common", "config", "reweight"), (2, 8, 6)):
            self.assertIn(f"--job-name=jvl-{phase} --array=1-{n} ", line)
            self.assertIn("--partition=cpu", line)
            self.assertTrue(line.strip().endswith(f"task.sbatch {self.tmp}/jobs.{phase}.txt"))
        self.assertIn("--dependency=afterany:\\$JOB_common", lines[1])
        self.assertIn("--dependency=afterany:\\$JOB_reweight", lines[3])
        self.assertIn("collect.sbatch", lines[3])
        self.assertEqual(read(os.path.join(self.tmp, "jobs.txt")),
                         read(os.path.join(DATA, "expected_jobs.txt")))

    def test_local_batch_dry_run(self):
        out = run(["bash", os.path.join(ROOT, "pipelines", "batch"), SPEC, self.tmp, "--dry-run"])
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertEqual(len(lines), 16)
        self.assertTrue(all("-f " + os.path.join(ROOT, "Makefile.example") in l for l in lines))
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "batch.mk")))


class Collect(unittest.TestCase):
    """The committed metrics of tests/pipelines/data/run (one task, sim/beta-10, failed)."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="jvl_collect_")
        cls.out = run([sys.executable, COLLECT_PY, SPEC, os.path.join(DATA, "run"), "-o",
                       cls.tmp, "--no-plots"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp)

    def test_reports_the_missing_result(self):
        self.assertEqual(self.out.returncode, 0, self.out.stderr)
        self.assertIn("13/14 results", self.out.stdout)
        self.assertIn("run/sim/beta-10/metrics.json is missing", self.out.stderr)

    def test_outputs_match_the_expected_files(self):
        for name in ("ablations.md", "v_interval.csv", "n.csv", "beta_gamma.csv", "metrics.csv"):
            with self.subTest(name=name):
                self.assertEqual(read(os.path.join(self.tmp, name)),
                                 read(os.path.join(DATA, "expected", name)))

    def test_paper_format(self):
        table = read(os.path.join(self.tmp, "v_interval.csv")).splitlines()
        self.assertEqual(table[0], "V_INTERVAL,config,04,sim")
        # r_rel / APE; r_rel is undefined on the 04 excerpt (no 100 m segment).
        self.assertEqual(table[2], "5,v_interval-5,-/0.310,0.201/1.310")

    def test_other_cells_and_estimates(self):
        out = run([sys.executable, COLLECT_PY, SPEC, os.path.join(DATA, "run"), "-o", self.tmp
                   + "/x", "--no-plots", "--cell", "ape_deg/ape", "--estimate",
                   "w.o. direction priors"])
        self.assertEqual(out.returncode, 0, out.stderr)
        table = read(os.path.join(self.tmp, "x", "n.csv")).splitlines()
        self.assertEqual(table[1], "1,n-1,0.215/0.430,0.715/1.430")

    def test_bad_input(self):
        out = run([sys.executable, COLLECT_PY, SPEC, os.path.join(self.tmp, "nothing")])
        self.assertEqual(out.returncode, 2)
        self.assertIn("no such run folder", out.stderr)
        os.makedirs(os.path.join(self.tmp, "empty"), exist_ok=True)
        out = run([sys.executable, COLLECT_PY, SPEC, os.path.join(self.tmp, "empty"),
                   "--no-plots"])
        self.assertEqual(out.returncode, 1)
        self.assertIn("no metrics.json", out.stderr.splitlines()[-1])
        out = run([sys.executable, COLLECT_PY, SPEC, DATA, "--cell", "r_rel/apex"])
        self.assertEqual(out.returncode, 2)
        self.assertIn("unknown figure 'apex'", out.stderr)


def kitti_line(x, z):
    return f"1 0 0 {x} 0 1 0 0 0 0 1 {z}\n"


class MakefilePasses(unittest.TestCase):
    """Makefile.example's PASSES, from the commands `make -n` would run."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.bin = os.path.join(self.dir, "bin")
        os.makedirs(self.bin)
        for tool in ("lidar_odom", "vp_detect", "direction_cluster", "visual_assoc", "local_map",
                     "global_opt", "evaluate"):
            open(os.path.join(self.bin, tool), "w").close()
        self.out = os.path.join(self.dir, "out")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def commands(self, *variables):
        out = run(["make", "-n", "--no-print-directory", "-f", "Makefile.example",
                   "BIN=" + self.bin, "OUT=" + self.out, "DATASET=" + self.dir + "/seq"] +
                  list(variables))
        self.assertEqual(out.returncode, 0, out.stderr)
        # Join continuation lines: one command per entry.
        return [l for l in out.stdout.replace("\\\n", " ").splitlines() if l.strip()]

    def tool_runs(self, commands, tool):
        return [c for c in commands if c.startswith(os.path.join(self.bin, tool) + " ")]

    def test_single_pass_is_the_papers_chain(self):
        c = self.commands("PASSES=1")
        self.assertEqual(len(self.tool_runs(c, "visual_assoc")), 1)
        runs = self.tool_runs(c, "global_opt")
        self.assertEqual(len(runs), 2)
        self.assertTrue(any(f"--kitti-poses {self.out}/with_directions.txt" in r for r in runs))
        self.assertTrue(any(f"--kitti-poses {self.out}/without_directions.txt" in r for r in runs))
        evaluate = self.tool_runs(c, "evaluate")[0]
        self.assertIn(f"--est {self.out}/global.h5 ", evaluate)

    def test_default_second_pass_starts_from_the_first_result_without_directions(self):
        c = self.commands()
        visual = self.tool_runs(c, "visual_assoc")
        self.assertEqual(len(visual), 2)
        self.assertIn(f"--prior {self.out}/odom.h5 ", visual[0])
        self.assertIn(f"--prior {self.out}/global_nodir.h5 ", visual[1])
        self.assertIn(f"-o {self.out}/pass2/visual.h5", visual[1])
        cluster = self.tool_runs(c, "direction_cluster")
        self.assertIn(f"--prior {self.out}/global_nodir.h5 ", cluster[1])
        runs = self.tool_runs(c, "global_opt")
        # Pass 1 only without direction priors (the next pass's prior), pass 2 both.
        self.assertEqual(len(runs), 3)
        self.assertEqual(sum("--vps" in r for r in runs), 1)
        self.assertTrue(any(f"--kitti-poses {self.out}/pass1/without_directions.txt" in r
                            for r in runs))
        self.assertTrue(any(f"-o {self.out}/pass2/global.h5 " in r and
                            f"--kitti-poses {self.out}/with_directions.txt" in r for r in runs))
        evaluate = self.tool_runs(c, "evaluate")[0]
        self.assertIn(f"--est {self.out}/odom.h5 --label prior", evaluate)
        self.assertIn(f"--est {self.out}/pass2/global_nodir.h5 ", evaluate)
        self.assertIn(f"--est {self.out}/pass2/global.h5 ", evaluate)

    def test_passes_chain_their_priors(self):
        c = self.commands("PASSES=3")
        visual = self.tool_runs(c, "visual_assoc")
        self.assertEqual(len(visual), 3)
        self.assertIn(f"--prior {self.out}/pass2/global_nodir.h5 ", visual[2])

    def test_gamma_does_not_change_the_runs_without_direction_priors(self):
        c = self.commands("GAMMA=7")
        runs = self.tool_runs(c, "global_opt")
        self.assertTrue(all(("--gamma 7" in r) == ("--vps" in r) for r in runs))

    def test_bad_passes(self):
        out = run(["make", "-n", "-f", "Makefile.example", "BIN=" + self.bin, "OUT=" + self.out,
                   "PASSES=0"])
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("PASSES must be 1..9", out.stderr)


class GainsTable(unittest.TestCase):
    """pipelines/gains_table.py on a hand-made run: ratios, steps of the prior, survival."""

    def setUp(self):
        self.run_dir = tempfile.mkdtemp()
        data = os.path.join(self.run_dir, "data", "d1")
        os.makedirs(os.path.join(data, "sequences", "00"))
        os.makedirs(os.path.join(data, "poses"))
        base = os.path.join(self.run_dir, "d1", "base")
        common = os.path.join(self.run_dir, "d1", "common")
        os.makedirs(base)
        os.makedirs(common)
        n = 21
        gt = [(0.0, 1.0 * i) for i in range(n)]
        # The prior drifts 1 mm per frame sideways and jumps 0.2 m between frames 10 and 11; the
        # result without keeps half the jump, the one with removes it.
        prior = [(0.001 * i + (0.2 if i > 10 else 0.0), 1.0 * i) for i in range(n)]
        without = [(0.1 if i > 10 else 0.0, 1.0 * i) for i in range(n)]
        with_ = [(0.0, 1.0 * i) for i in range(n)]
        for path, poses in ((os.path.join(data, "poses", "00.txt"), gt),
                            (os.path.join(common, "odom.txt"), prior),
                            (os.path.join(base, "without_directions.txt"), without),
                            (os.path.join(base, "with_directions.txt"), with_)):
            with open(path, "w") as f:
                f.writelines(kitti_line(x, z) for x, z in poses)

        def estimate(label, ape):
            return {"label": label,
                    "ape": {"translation_m": {"rmse": ape}, "rotation_deg": {"rmse": ape / 10}},
                    "kitti": {"t_rel_percent": None, "r_rel_deg_per_100m": None}}
        metrics = {"options": {"alignment": "se3"},
                   "estimates": [estimate("prior", 1.0), estimate("w.o. direction priors", 0.3),
                                 estimate("w. direction priors", 0.15)]}
        with open(os.path.join(base, "metrics.json"), "w") as f:
            json.dump(metrics, f)
        with open(os.path.join(self.run_dir, "gains.spec"), "w") as f:
            f.write(f"sequence d1 {data}/sequences/00 ODOM_N=1 ALIGN=se3\n")
            f.write(f"sequence missing {data}/sequences/00\n")

    def tearDown(self):
        shutil.rmtree(self.run_dir)

    def test_ratios_steps_and_survival(self):
        out = run([sys.executable, GAINS_PY, self.run_dir])
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = json.loads(read(os.path.join(self.run_dir, "gains.json")))
        d1 = rows[0]
        self.assertAlmostEqual(d1["ratio_without_prior"], 0.3)
        self.assertAlmostEqual(d1["ratio_with_without"], 0.5)
        self.assertEqual(d1["prior_steps"], 1)  # only the jump exceeds 5x the 1 mm median
        self.assertEqual(d1["without"]["surviving_steps"], 1)
        self.assertEqual(d1["with"]["surviving_steps"], 0)
        self.assertEqual(d1["worst_step"]["frame"], 10)
        self.assertAlmostEqual(d1["worst_step"]["prior_m"], 0.201, places=6)
        self.assertAlmostEqual(d1["worst_step"]["without_m"], 0.1, places=6)
        self.assertTrue(rows[1]["missing"])
        self.assertIn("| d1 | 21 | 0.02 |", read(os.path.join(self.run_dir, "gains.md")))


class LoopsTable(unittest.TestCase):
    """pipelines/loops_table.py on a hand-made run: APE ratios with / without loops, precision
    and recall per detector, time per keyframe, a missing detector run."""

    def setUp(self):
        self.run_dir = tempfile.mkdtemp()
        poses = os.path.join(self.run_dir, "data", "d1", "poses")
        os.makedirs(poses)
        with open(os.path.join(poses, "00.txt"), "w") as f:
            f.writelines(kitti_line(0.0, 2.0 * i) for i in range(11))  # 20 m

        def metrics(folder, without, with_):
            os.makedirs(folder)
            def estimate(label, ape):
                return {"label": label, "ape": {"translation_m": {"rmse": ape},
                                                "rotation_deg": {"rmse": ape / 10}},
                        "kitti": {"t_rel_percent": ape / 100}}
            with open(os.path.join(folder, "metrics.json"), "w") as f:
                json.dump({"options": {"alignment": "se3"},
                           "estimates": [estimate("prior", 1.0),
                                         estimate("w.o. direction priors", without),
                                         estimate("w. direction priors", with_)]}, f)
        metrics(os.path.join(self.run_dir, "d1", "base"), 0.4, 0.2)
        metrics(os.path.join(self.run_dir, "d1", "loops-1"), 0.1, 0.08)
        gt = os.path.join(self.run_dir, "d1", "gt")
        os.makedirs(gt)

        def report(name, entries, time_s):
            with open(os.path.join(gt, name + ".json"), "w") as f:
                json.dump({"keyframes": 50, "candidates": 30, "accepted": entries[-1][1],
                           "detectors": [
                               {"detector": label, "accepted": a, "right": r,
                                "revisits_same": 20, "found_same": fs, "revisits_opposite": 10,
                                "found_opposite": fo, "stretches_same": 1, "closed_same": 1,
                                "stretches_opposite": 1, "closed_opposite": 1 if fo else 0}
                               for label, a, r, fs, fo in entries]}, f)
            with open(os.path.join(gt, name + ".time"), "w") as f:
                f.write(f"{time_s}\n")
        report("visual", [("visual", 18, 18, 18, 0)], 1.5)
        report("lidar", [("LiDAR", 12, 11, 10, 1)], 1.0)
        report("all", [("visual", 18, 18, 18, 0), ("LiDAR (after visual)", 1, 1, 1, 0),
                       ("combined", 27, 27, 19, 8)], 2.0)  # proximity.json: missing

    def tearDown(self):
        shutil.rmtree(self.run_dir)

    def test_ratios_precision_recall_and_time(self):
        out = run([sys.executable, LOOPS_PY, self.run_dir, "d1"])
        self.assertEqual(out.returncode, 0, out.stderr)
        d1 = json.loads(read(os.path.join(self.run_dir, "loops.json")))[0]
        self.assertAlmostEqual(d1["ratio_without"], 0.25)
        self.assertAlmostEqual(d1["ratio_with"], 0.4)
        self.assertAlmostEqual(d1["length_m"], 20.0)
        self.assertEqual(d1["detectors"]["all"]["detector"], "combined")
        self.assertIsNone(d1["detectors"]["proximity"])
        md = read(os.path.join(self.run_dir, "loops.md"))
        self.assertIn("| d1 | 11 | 0.02 | 1.000 / 0.100 |", md)
        self.assertIn("| d1 | LiDAR | 50 | 30 | 12 / 11 (92 %) | 10 of 20 (50 %) | 1 of 10 (10 %)", md)
        self.assertIn("| d1 | combined | 50 | 30 | 27 / 27 (100 %) | 19 of 20 (95 %) "
                      "| 8 of 10 (80 %) | 1 of 1 / 1 of 1 | 2.0 (40) |", md)
        self.assertIn("| d1 | proximity | missing |", md)
        self.assertIn("0.25-0.40 (mean 0.32); wrong accepted loops (all runs of the second "
                      "table) 1.", md)

    def test_detect_only_run_has_the_detector_table_with_usage(self):
        # pipelines/loops --detect-only: no chain, so no APE table; the drive's frames and length
        # go into the detector table, with the CPU time and peak memory of usage.json.
        shutil.rmtree(os.path.join(self.run_dir, "d1", "base"))
        shutil.rmtree(os.path.join(self.run_dir, "d1", "loops-1"))
        with open(os.path.join(self.run_dir, "d1", "gt", "all.usage.json"), "w") as f:
            json.dump({"wall_s": 2.5, "cpu_s": 4.25, "peak_mib": 812.4, "exit_code": 0}, f)
        out = run([sys.executable, LOOPS_PY, self.run_dir, "d1"])
        self.assertEqual(out.returncode, 0, out.stderr)
        md = read(os.path.join(self.run_dir, "loops.md"))
        self.assertNotIn("APE prior", md)
        self.assertTrue(md.startswith("| drive | frames | km | detector |"), md)
        self.assertIn("| d1 | 11 | 0.02 | combined | 50 | 30 | 27 / 27 (100 %) | 19 of 20 (95 %) "
                      "| 8 of 10 (80 %) | 1 of 1 / 1 of 1 | 2.5 (50) | 4.2, 812 |", md)
        self.assertIn("| d1 | 11 | 0.02 | visual | 50 | 30 | 18 / 18 (100 %)", md)
        self.assertIn("| 1.5 (30) | - |", md)
        self.assertIn("Drives (1): wrong accepted loops (all runs of the table) 1.", md)
        d1 = json.loads(read(os.path.join(self.run_dir, "loops.json")))[0]
        self.assertIsNone(d1["no_loops"])
        self.assertNotIn("ratio_without", d1)
        self.assertEqual(d1["detectors"]["all"]["peak_mib"], 812.4)


# A stand-in for every tool pipelines/loops --detect-only runs: writes each output it is given
# (-o, --csv, --plot, --kitti-poses); sim_sequence also writes a ground truth of 11 poses 2 m
# apart, loop_detect a --report with two right loops; visual_assoc fails on a drive named "bad".
STUB_TOOL = r"""#!/usr/bin/env python3
import json, os, sys
tool, args = os.path.basename(sys.argv[0]), sys.argv[1:]
if tool == "visual_assoc" and any("/bad/" in a for a in args):
    sys.exit(tool + ": failing on purpose")
def value(flag):
    return args[args.index(flag) + 1] if flag in args else None
if tool == "sim_sequence":
    poses = os.path.join(value("-o"), "poses")
    os.makedirs(poses, exist_ok=True)
    os.makedirs(os.path.join(value("-o"), "sequences", "00"), exist_ok=True)
    with open(os.path.join(poses, "00.txt"), "w") as f:
        f.writelines(f"1 0 0 0 0 1 0 0 0 0 1 {2.0 * i}\n" for i in range(11))
    with open(os.path.join(value("-o"), "..", "sim_calls"), "a") as f:
        f.write(" ".join(args) + "\n")
    sys.exit(0)
for flag in ("-o", "--csv", "--plot", "--kitti-poses"):
    if value(flag):
        with open(value(flag), "w") as f:
            f.write(tool + "\n")
if tool == "loop_detect":
    dets = value("--detectors").split(",")
    entry = {"accepted": 2, "right": 2, "revisits_same": 0, "found_same": 0,
             "revisits_opposite": 0, "found_opposite": 0, "stretches_same": 0, "closed_same": 0,
             "stretches_opposite": 0, "closed_opposite": 0}
    entries = [dict(entry, detector=d) for d in dets]
    if len(dets) > 1:
        entries.append(dict(entry, detector="combined"))
    with open(value("--report"), "w") as f:
        json.dump({"keyframes": 3, "candidates": 2, "accepted": 2, "detectors": entries}, f)
"""


class LoopsDetectOnly(unittest.TestCase):
    """pipelines/loops --detect-only with stand-in tools: the drive list, the prior and visual
    map through Makefile.example, the ground-truth runs with their usage, the table; a rerun
    simulates nothing again; a failing drive fails the run and leaves the others' rows."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.bin = os.path.join(self.dir, "bin")
        os.makedirs(self.bin)
        for tool in ("sim_sequence", "lidar_odom", "vp_detect", "direction_cluster",
                     "visual_assoc", "loop_detect"):
            path = os.path.join(self.bin, tool)
            with open(path, "w") as f:
                f.write(STUB_TOOL)
            os.chmod(path, 0o755)
        self.drives = os.path.join(self.dir, "t.drives")
        with open(self.drives, "w") as f:
            f.write("# test drives\nd1   --scenario urban --seed 1\n\nd2 --seed 2 --laps 2\n")
        self.run_dir = os.path.join(self.dir, "run")
        self.env = dict(os.environ, JVL_BIN=self.bin, DRIVES=self.drives, THREADS="1")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def loops(self):
        return run([os.path.join(ROOT, "pipelines", "loops"), self.run_dir, "--detect-only",
                    "-j", "2"], env=self.env)

    def test_detect_only_run(self):
        out = self.loops()
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        for name in ("d1", "d2"):
            for f in ("common/odom.h5", "common/vps.h5", "base/directions.h5", "base/visual.h5"):
                self.assertTrue(os.path.exists(os.path.join(self.run_dir, name, f)), f)
            for det in ("visual", "lidar", "proximity", "all"):
                usage = json.loads(read(os.path.join(self.run_dir, name, "gt",
                                                     det + ".usage.json")))
                self.assertEqual(usage["exit_code"], 0)
        md = read(os.path.join(self.run_dir, "loops.md"))
        self.assertNotIn("APE prior", md)
        self.assertIn("| d2 | 11 | 0.02 | combined | 3 | 2 | 2 / 2 (100 %) |", md)
        self.assertIn("Drives (2): wrong accepted loops (all runs of the table) 0.", md)
        calls = read(os.path.join(self.run_dir, "data", "sim_calls")).splitlines()
        self.assertEqual(len(calls), 2)
        self.assertIn("--seed 2 --laps 2", calls[1])
        # A rerun finds the drives simulated and every artifact up to date.
        out = self.loops()
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        self.assertNotIn("simulating", out.stdout)
        self.assertEqual(len(read(os.path.join(self.run_dir, "data", "sim_calls")).splitlines()), 2)

    def test_a_failing_drive_fails_the_run(self):
        with open(self.drives, "a") as f:
            f.write("bad --seed 3\n")
        out = self.loops()
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("bad", out.stderr)
        md = read(os.path.join(self.run_dir, "loops.md"))
        self.assertIn("| d1 | 11 | 0.02 | combined |", md)
        self.assertIn("| bad | 11 | 0.02 | visual | missing |", md)


class Usage(unittest.TestCase):
    """pipelines/usage.py: a command's wall and CPU time and peak memory, and its exit code."""

    def test_figures_and_exit_code(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "u.json")
            # 64 MiB held while the process spins for a CPU second.
            code = ("import time\nx = bytearray(64 << 20)\nt = time.process_time()\n"
                    "while time.process_time() - t < 0.3: pass\nraise SystemExit(3)")
            res = run([sys.executable, USAGE_PY, out, "--", sys.executable, "-c", code])
            self.assertEqual(res.returncode, 3, res.stderr)
            figures = json.loads(read(out))
            self.assertEqual(figures["exit_code"], 3)
            self.assertGreaterEqual(figures["cpu_s"], 0.3)
            self.assertGreaterEqual(figures["wall_s"], 0.3)
            self.assertGreater(figures["peak_mib"], 64)
            res = run([sys.executable, USAGE_PY, out, "--", os.path.join(d, "missing")])
            self.assertEqual(res.returncode, 127)
            self.assertIn("cannot run", res.stderr)
            res = run([sys.executable, USAGE_PY, out])
            self.assertEqual(res.returncode, 2)


class SimFidelity(unittest.TestCase):
    """scripts/sim_fidelity.py on hand-made drives: a yaw rate that steps and one that ramps."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir)

    def drive(self, name, yaw_rates_deg):
        # 1 m per frame along the camera's z axis, turning about its y axis (down).
        path = os.path.join(self.dir, name)
        x = z = heading = 0.0
        with open(path, "w") as f:
            for rate in [0.0] + yaw_rates_deg:
                heading += math.radians(rate)
                c, s = math.cos(heading), math.sin(heading)
                x += s
                z += c
                f.write(f"{c} 0 {s} {x} 0 1 0 0 {-s} 0 {c} {z}\n")
        return path

    def test_step_and_ramp(self):
        step = self.drive("step.txt", [0.0] * 200 + [2.0] * 200)
        ramp = self.drive("ramp.txt", [0.0] * 200 + [0.25 * k for k in range(1, 9)] + [2.0] * 192)
        md = os.path.join(self.dir, "table.md")
        out = run([sys.executable, FIDELITY_PY, "--markdown", md, "step=" + step, "ramp=" + ramp])
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
                for line in out.stdout.splitlines()[2:]}
        self.assertEqual(rows["step"][0], "401")
        self.assertEqual(rows["step"][1], "10.0 / 10.0")      # speed median / max
        self.assertEqual(rows["step"][2], "2.000 / 2.000")    # yaw per frame p99 / max
        self.assertEqual(rows["step"][3], "0.000 / 2.000")    # yaw change: one step of 2 deg
        self.assertEqual(rows["ramp"][3], "0.250 / 0.250")    # ramped in 0.25 deg per frame
        self.assertEqual(rows["ramp"][4], "0.0000 / 0.000 / 0.000")  # no roll
        self.assertEqual(rows["step"][6], "0.000 / 0.000")  # straight: along its chords
        self.assertEqual(read(md), out.stdout)

    def test_weave_is_the_heading_off_the_chord(self):
        # The heading weaves by +-1 deg with a 70 m period (1 m per frame): the optical axis
        # leaves the chord to the position 20 m ahead by up to about 1.5 deg.
        heading = [math.sin(2 * math.pi * k / 70) for k in range(401)]
        weave = self.drive("weave.txt", [heading[k + 1] - heading[k] for k in range(400)])
        straight = self.drive("straight.txt", [0.0] * 400)
        out = run([sys.executable, FIDELITY_PY, "weave=" + weave, "straight=" + straight])
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
                for line in out.stdout.splitlines()[2:]}
        median, p90 = (float(x) for x in rows["weave"][6].split(" / "))
        self.assertGreater(median, 0.4)
        self.assertLess(p90, 1.6)
        self.assertEqual(rows["straight"][6], "0.000 / 0.000")

    def test_bad_input(self):
        bad = os.path.join(self.dir, "bad.txt")
        with open(bad, "w") as f:
            f.write("1 0 0\n")
        out = run([sys.executable, FIDELITY_PY, "bad=" + bad])
        self.assertEqual(out.returncode, 1)
        self.assertIn("expected 12 numbers", out.stderr)
        out = run([sys.executable, FIDELITY_PY, "missing=" + os.path.join(self.dir, "none.txt")])
        self.assertEqual(out.returncode, 1)
        out = run([sys.executable, FIDELITY_PY])
        self.assertEqual(out.returncode, 2)


class VpSlowBias(unittest.TestCase):
    """scripts/vp_slow_bias.py on hand-made vertical VPs: white noise, and a slow wander on one
    axis on top of it."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()
        # Identity poses: the camera's up is -y.
        self.poses = os.path.join(self.dir, "poses.txt")
        with open(self.poses, "w") as f:
            for _ in range(600):
                f.write("1 0 0 0 0 1 0 0 0 0 1 0\n")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def vps(self, name, slow_deg):
        import random
        rng = random.Random(7)
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write("frame,vp_index,u,v,dx,dy,dz,inliers,residual_deg,score,is_forward\n")
            for k in range(600):
                ex = math.radians(rng.gauss(0.0, 0.2) + slow_deg * math.sin(2 * math.pi * k / 300))
                ez = math.radians(rng.gauss(0.0, 0.2))
                f.write(f"{k},0,0,0,0,0.02,1,50,0.5,100,1\n")  # a forward VP: not vertical
                f.write(f"{k},1,0,0,{ex},{-1.0},{ez},50,0.5,100,0\n")
        return path

    def slow_bias(self, vps):
        out = run([sys.executable, SLOW_BIAS_PY, vps, self.poses])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertTrue(out.stdout.startswith("600 vertical VPs"), out.stdout)
        return float(out.stdout.split("slow bias ")[1].split()[0])

    def test_white_noise_and_a_slow_wander(self):
        self.assertLess(self.slow_bias(self.vps("white.csv", 0.0)), 0.03)
        # A sine of amplitude 0.3 deg has an RMS of 0.212 deg.
        self.assertAlmostEqual(self.slow_bias(self.vps("slow.csv", 0.3)), 0.212, delta=0.03)

    def test_bad_input(self):
        out = run([sys.executable, SLOW_BIAS_PY, self.poses, self.poses])
        self.assertEqual(out.returncode, 1)
        self.assertIn("not a vp_detect CSV", out.stderr)
        short = os.path.join(self.dir, "short.txt")
        with open(short, "w") as f:
            f.write("1 0 0 0 0 1 0 0 0 0 1 0\n")
        out = run([sys.executable, SLOW_BIAS_PY, self.vps("v.csv", 0.0), short])
        self.assertEqual(out.returncode, 1)
        self.assertIn("has no pose", out.stderr)
        out = run([sys.executable, SLOW_BIAS_PY, self.poses])
        self.assertEqual(out.returncode, 1)


class SensorFidelity(unittest.TestCase):
    """scripts/sensor_fidelity.py on hand-made sensor_stats artifacts: the band around the
    reference, the absolute floor for fractions, missing statistics and bad input."""

    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir)

    def stats(self, name, scan, image=None):
        path = os.path.join(self.dir, name)
        part = lambda d: {k: {"median": v, "p10": v, "p90": v, "frames": [v]} for k, v in d.items()}
        with open(path, "w") as f:
            json.dump({"schema": "sensor_stats", "schema_version": 1, "provenance": {},
                       "frames": [0], "scan": part(scan),
                       "image": part(image) if image is not None else None}, f)
        return path

    def test_band_and_fraction_floor(self):
        real = self.stats("real.json", {"points": 1000, "ground": 0.5, "range_80_up": 0.001,
                                        "scattered": 0.4}, {"fast_corners": 4000})
        sim = self.stats("sim.json", {"points": 1250, "ground": 0.7, "range_80_up": 0.02,
                                      "scattered": None}, {"fast_corners": 700})
        md = os.path.join(self.dir, "t.md")
        out = run([sys.executable, SENSOR_FIDELITY_PY, "--markdown", md, "real=" + real,
                   "sim=" + sim])
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
                for line in out.stdout.splitlines()[2:]}
        self.assertEqual(rows["scan points"], ["1000", "1250"])         # +25 %: inside +-30 %
        self.assertEqual(rows["scan ground"], ["0.500", "0.700 !"])     # +40 % and 0.2 away
        self.assertEqual(rows["scan range_80_up"], ["0.001", "0.020"])  # 20x, but 0.019 away
        self.assertEqual(rows["scan scattered"], ["0.400", "-"])        # not measured
        self.assertEqual(rows["image fast_corners"], ["4000", "700.0 !"])
        self.assertEqual(rows["outside the band"], ["(reference)", "2"])
        self.assertEqual(read(md), out.stdout)
        out = run([sys.executable, SENSOR_FIDELITY_PY, "--band", "0.5", "real=" + real,
                   "sim=" + sim])
        self.assertIn("| scan ground | 0.500 | 0.700 |", out.stdout)

    def test_stages_by_mean_and_tail(self):
        def doc(name, found, error):
            path = os.path.join(self.dir, name)
            stat = lambda mean, median, p90: {"mean": mean, "median": median, "p10": median,
                                              "p90": p90, "frames": [median]}
            with open(path, "w") as f:
                json.dump({"schema": "sensor_stats", "schema_version": 1, "provenance": {},
                           "frames": [0], "scan": None, "image": None, "stage_frames": [0],
                           "stages": {"vp_forward_found": stat(found, 1.0, 1.0),
                                      "vp_forward_error_deg": stat(0.0, *error)}}, f)
            return path
        real = doc("real.json", 1.0, (0.14, 0.24))
        sim = doc("sim.json", 0.6, (0.16, 0.70))
        out = run([sys.executable, SENSOR_FIDELITY_PY, "real=" + real, "sim=" + sim])
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = {line.split("|")[1].strip(): [c.strip() for c in line.split("|")[2:-1]]
                for line in out.stdout.splitlines()[2:]}
        # The rate by its mean (its median is 1 on both), the error by median and p90.
        self.assertEqual(rows["stages vp_forward_found_mean"], ["1.000", "0.600 !"])
        self.assertEqual(rows["stages vp_forward_error_deg"], ["0.140", "0.160"])
        self.assertEqual(rows["stages vp_forward_error_deg_p90"], ["0.240", "0.700 !"])
        self.assertNotIn("stages vp_forward_found", rows)

    def test_bad_input(self):
        real = self.stats("real.json", {"points": 1000})
        other = os.path.join(self.dir, "other.json")
        with open(other, "w") as f:
            json.dump({"schema": "metrics"}, f)
        out = run([sys.executable, SENSOR_FIDELITY_PY, "real=" + real, "x=" + other])
        self.assertEqual(out.returncode, 2)
        self.assertIn("not a sensor_stats artifact", out.stderr)
        out = run([sys.executable, SENSOR_FIDELITY_PY, "real=" + real, "x=" + other + ".none"])
        self.assertEqual(out.returncode, 2)
        out = run([sys.executable, SENSOR_FIDELITY_PY, "real=" + real])
        self.assertEqual(out.returncode, 2)
        out = run([sys.executable, SENSOR_FIDELITY_PY, real, real])
        self.assertEqual(out.returncode, 2)
        self.assertIn("expected NAME=STATS.json", out.stderr)


class SceneTopview(unittest.TestCase):
    """scripts/scene_topview.py on a hand-made scene: a 100 m straight with a building."""

    def test_png_and_bad_input(self):
        d = tempfile.mkdtemp()
        try:
            scene = os.path.join(d, "scene.json")
            with open(scene, "w") as f:
                json.dump({"route": {"pieces": [
                    {"start": [0, 0], "start_heading_rad": 0, "curvature": 0, "length": 100}]},
                    "buildings": [{"center": [50, 15, 0], "yaw_rad": 0, "length": 20,
                                   "depth": 10}],
                    "plants": [{"center": [20, -10, 4], "radius": 2}],
                    "poles": [{"base": [30, 8, 0]}]}, f)
            png = os.path.join(d, "top.png")
            out = run([sys.executable, TOPVIEW_PY, scene, png, "2"])
            self.assertEqual(out.returncode, 0, out.stderr)
            with open(png, "rb") as f:
                data = f.read()
            self.assertTrue(data.startswith(b"\x89PNG\r\n\x1a\n"))
            width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
            self.assertEqual((width, height), (360, 160))  # (100 + 80) m x (0 + 80) m at 2 px/m
            out = run([sys.executable, TOPVIEW_PY, os.path.join(d, "none.json"), png])
            self.assertEqual(out.returncode, 1)
            out = run([sys.executable, TOPVIEW_PY, scene])
            self.assertEqual(out.returncode, 2)
        finally:
            shutil.rmtree(d)


if __name__ == "__main__":
    unittest.main(verbosity=2)
