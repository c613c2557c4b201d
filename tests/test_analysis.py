#!/usr/bin/python3
"""The analysis loader (analysis/results.py) on a sample of each benchmark schema, and the report.

The samples in tests/data/analysis/ are trimmed copies of real results: bench_sample.json of
`demmat bench --json` (arrays and fast, two repetitions), gbench_sample.json of demmat_bench's Google
Benchmark JSON (fast on the settled bed of 8000 at 1 and 2 threads, two STREAM kernels),
mpi_bench_sample.json of `mpirun -np 2 demmat_mpi bench --json` (the loose bed of 2000, two repetitions).
Run by ctest (analysis.results) with /usr/bin/python3.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ANALYSIS = os.path.join(HERE, os.pardir, "analysis")
DATA = os.path.join(HERE, "data", "analysis")
sys.path.insert(0, ANALYSIS)

import results  # noqa: E402
import test_peers_bench  # noqa: E402  (the peers' samples, for the report's section)

TIDY = ["variant", "threads", "N", "phase", "repetition", "seconds", "sample"]


class Loader(unittest.TestCase):
    def test_demmat_bench(self):
        r = results.load(os.path.join(DATA, "bench_sample.json"))
        self.assertEqual(r.kind, "bench")
        # demmat bench also records the thread count asked for beside the one a variant ran on
        self.assertEqual([c for c in r.table.columns if c != "threads_asked"], TIDY)
        self.assertIn("threads_asked", r.table.columns)
        self.assertIs(r.provenance["dirty"], False)
        self.assertEqual(len(r.table), 16)  # 2 variants × 2 repetitions × 4 phases
        row = r.table[(r.table.variant == "arrays") & (r.table.repetition == 0) & (r.table.phase == "predict")]
        self.assertEqual(row.seconds.tolist(), [1.5135653999999999e-05])
        self.assertEqual(set(r.table.N), {2000})
        self.assertEqual(set(r.table[r.table.variant == "fast"].threads), {2})

        w = results.wide(r.table)
        self.assertEqual(len(w), 4)  # one row per sample
        a0 = w[(w.variant == "arrays") & (w.repetition == 0)].iloc[0]
        self.assertAlmostEqual(a0.total_s, a0.predict_s + a0.search_s + a0.forces_s + a0.correct_s, delta=0)

    def test_demmat_mpi_bench(self):
        r = results.load(os.path.join(DATA, "mpi_bench_sample.json"))
        self.assertEqual(r.kind, "mpi")
        self.assertEqual(r.meta["processes"], 2)
        self.assertEqual(len(r.table), 2 * len(results.MPI_PHASES))  # one row per (rank, phase) of the median repetition
        self.assertEqual(sorted(set(r.table["rank"])), [0, 1])
        per_rank = r.table[r.table.phase == "predict"]
        self.assertEqual(per_rank.particles.sum(), 2000)  # every particle owned once
        self.assertTrue((per_rank.ghosts > 0).all())
        self.assertTrue((per_rank.messages_per_step >= 1).all())  # one refresh to the neighbour per step, at least

    @staticmethod
    def fast_asked_for_1_and_2_threads_ran_on_1():
        """The bench sample as if fast, asked for 1 and 2 threads on a small bed, ran on 1 both times."""
        import json
        raw = json.load(open(os.path.join(DATA, "bench_sample.json")))
        extra = [dict(x, threads=1, threads_asked=1) for x in raw["samples"] if x["variant"] == "fast"]
        for x in raw["samples"]:
            if x["variant"] == "fast":
                x["threads"], x["threads_asked"] = 1, 2
        raw["samples"] += extra
        fast = next(s for s in raw["summary"] if s["variant"] == "fast")
        raw["summary"].append(dict(fast, threads=1, threads_asked=1))
        fast.update(threads=1, threads_asked=2)
        return raw

    def test_two_configurations_on_the_same_threads_stay_two_samples(self):
        # fast asked for 1 and 2 threads on a small bed runs on 1 both times: still two samples each
        import json, tempfile
        raw = self.fast_asked_for_1_and_2_threads_ran_on_1()
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            json.dump(raw, f)
        r = results.load(f.name)
        os.unlink(f.name)
        fast = r.table[r.table.variant == "fast"]
        self.assertEqual(set(fast.threads), {1})
        self.assertEqual(fast["sample"].nunique(), 4)  # 2 configurations × 2 repetitions
        self.assertEqual(len(results.wide(r.table)), 6)

    def test_subnormal_table_pairs_the_builds_within_each_repetition(self):
        # the bench sample as the loose grid and the bed, without the rule; with it, the loose grid at
        # half the time in repetition 0 and a quarter in repetition 1, the bed unchanged
        import json
        raw = json.load(open(os.path.join(DATA, "bench_sample.json")))
        work = tempfile.mkdtemp()
        try:
            for r, factor in ((0, 0.5), (1, 0.25)):
                for stage in ("loose", "bed"):
                    after = json.loads(json.dumps(raw))
                    if stage == "loose":
                        for x in after["samples"]:
                            x["seconds_per_step"] *= factor
                    json.dump(raw, open(os.path.join(work, f"bench_{stage}_before_r{r}.json"), "w"))
                    json.dump(after, open(os.path.join(work, f"bench_{stage}_after_r{r}.json"), "w"))
            out = os.path.join(work, "subnormal.md")
            subprocess.run([sys.executable, os.path.join(ANALYSIS, "subnormal_table.py"), work, "-o", out], check=True,
                           stdout=subprocess.DEVNULL)
            row = next(l for l in open(out) if l.startswith("| arrays |")).split("|")
            self.assertEqual(row[4].strip(), "0.375 (0.250–0.500)")  # loose: paired, median of 0.5 and 0.25
            self.assertEqual(row[7].strip(), "1.000 (1.000–1.000)")  # bed
            self.assertAlmostEqual(float(row[8]) / float(row[9]), 1 / 0.375, delta=0.05)  # loose/bed without over with (printed to 2 places)
        finally:
            shutil.rmtree(work)

    @staticmethod
    def summarise_fast(raw):
        """summarise_fast.py's summary of one bench JSON, as the settled bed of 2000."""
        import json
        work = tempfile.mkdtemp()
        try:
            with open(os.path.join(work, "bench_settled_2000.json"), "w") as f:
                json.dump(raw, f)
            out = os.path.join(work, "summary.md")
            subprocess.run([sys.executable, os.path.join(ANALYSIS, "summarise_fast.py"), work, "-o", out], check=True)
            return open(out).read()
        finally:
            shutil.rmtree(work)

    def test_summarise_fast_keys_rows_by_the_threads_asked(self):
        # fast asked for 1 and 2 threads on a small bed runs on 1 both times: two rows, the second saying so
        text = self.summarise_fast(self.fast_asked_for_1_and_2_threads_ran_on_1())
        rows = [line for line in text.splitlines() if line.startswith("| settled | 2000 | fast |")]
        self.assertEqual([r.split("|")[4].strip() for r in rows], ["1", "2 (ran on 1)"])

    def test_summarise_fast_pairs_fast_with_fast_unordered_within_each_repetition(self):
        # the sample's arrays samples as fast_unordered's on fast's threads: the paired cost is, per
        # repetition, fast's total over the other's, and the table gives their median, min and max
        import json
        raw = json.load(open(os.path.join(DATA, "bench_sample.json")))
        for x in raw["samples"] + raw["summary"]:
            if x["variant"] == "arrays":
                x["variant"], x["threads"] = "fast_unordered", 2
        totals = {}
        for x in raw["samples"]:
            key = (x["variant"], x["repetition"])
            totals[key] = totals.get(key, 0.0) + x["seconds_per_step"]
        ratios = sorted(totals[("fast", r)] / totals[("fast_unordered", r)] for r in range(raw["repetitions"]))
        self.assertNotAlmostEqual(ratios[0], ratios[-1], places=3)  # two distinct repetitions, so min ≠ max
        text = self.summarise_fast(raw)
        self.assertIn("## What the canonical order costs", text)
        row = [line for line in text.splitlines() if line.startswith("| settled | 2000 | 2 |")]
        self.assertEqual(len(row), 1)
        paired = row[0].split("|")[5].strip()
        median = (ratios[0] + ratios[-1]) / 2  # two repetitions
        self.assertEqual(paired, f"{median:.3f} ({ratios[0]:.3f}–{ratios[-1]:.3f})")
        us = {x["variant"]: x["us_per_particle_step"] for x in raw["summary"]}
        self.assertEqual(row[0].split("|")[4].strip(), f"{us['fast'] / us['fast_unordered']:.3f}")

    def test_summarise_gpu_speed_up_over_cuda_and_the_verdicts(self):
        # the sample's arrays as cuda and its fast as fast at 2 threads under the paper's law, and its
        # fast as cuda under mindlin, each in its own file as device_check.sh writes them, the laws named
        # by runs.tsv: fast's row carries its median over cuda's of the same law, cuda under mindlin its
        # median over cuda's under the paper's law; each compare's last line is quoted under its law and
        # stage, a difference as well as an identity
        import json
        raw = json.load(open(os.path.join(DATA, "bench_sample.json")))
        work = tempfile.mkdtemp()
        try:
            us = {}
            runs = ["file\tlaw"]
            for v, name, law in (("arrays", "cuda", "paper"), ("fast", "fast", "paper"), ("fast", "cuda", "mindlin")):
                one = json.loads(json.dumps(raw))
                one["samples"] = [dict(x, variant=name) for x in one["samples"] if x["variant"] == v]
                one["summary"] = [dict(x, variant=name) for x in one["summary"] if x["variant"] == v]
                if name == "cuda":  # one thread, as the device runs
                    one["summary"] = [dict(x, threads=1, threads_asked=1) for x in one["summary"]]
                us[name, law] = one["summary"][0]["us_per_particle_step"]
                file = f"bench_settled_2000_{law}_{name}_{one['summary'][0]['threads']}.json"
                runs.append(f"{file}\t{law}")
                with open(os.path.join(work, file), "w") as f:
                    json.dump(one, f)
            with open(os.path.join(work, "compare_bed_2000_paper.txt"), "w") as f:
                f.write("identical: cuda, arrays, cuda over 1000 steps of 'dense_bed_2000' (2000 particles)\n")
            with open(os.path.join(work, "compare_bed_2000_mindlin_compression.txt"), "w") as f:
                f.write("step 1\nfirst difference: step 3, particle 7, position x\n")
            runs += ["compare_bed_2000_paper.txt\tpaper", "compare_bed_2000_mindlin_compression.txt\tmindlin"]
            with open(os.path.join(work, "runs.tsv"), "w") as f:
                f.write("\n".join(runs) + "\n")
            out = os.path.join(work, "summary.md")
            subprocess.run([sys.executable, os.path.join(ANALYSIS, "summarise_gpu.py"), work, "-o", out], check=True,
                           stdout=subprocess.DEVNULL)
            text = open(out).read()
        finally:
            shutil.rmtree(work)
        self.assertIn("| paper's law | identical: cuda, arrays, cuda over 1000 steps of 'dense_bed_2000' (2000 particles) | (not run) |", text)
        self.assertIn("| mindlin | (not run) | first difference: step 3, particle 7, position x |", text)
        rows = {(c[3].strip(), c[4].strip()): c for c in (line.split("|") for line in text.splitlines() if line.startswith("| settled | 2000 |"))}
        self.assertEqual(set(rows), {("paper's law", "cuda"), ("paper's law", "fast"), ("mindlin", "cuda")})
        self.assertEqual(rows["paper's law", "fast"][8].strip(), f"{us['fast', 'paper'] / us['cuda', 'paper']:.1f}×")
        self.assertEqual(rows["paper's law", "cuda"][8].strip(), "")
        self.assertEqual(rows["paper's law", "cuda"][6].strip(), f"{us['cuda', 'paper']:.4f}")
        self.assertEqual(rows["mindlin", "cuda"][9].strip(), f"{us['cuda', 'mindlin'] / us['cuda', 'paper']:.2f}×")
        self.assertEqual(rows["paper's law", "cuda"][9].strip(), "")

    def test_google_benchmark(self):
        r = results.load(os.path.join(DATA, "gbench_sample.json"))
        self.assertEqual(r.kind, "gbench")
        self.assertTrue(set(TIDY) <= set(r.table.columns))
        self.assertIs(r.provenance["dirty"], False)  # the context holds the string "false"
        self.assertEqual(r.provenance["commit"][:7], "8f31195")
        self.assertEqual(r.provenance["host_cpus"], 2)
        t = r.table
        row = t[(t.family == "phases") & (t.threads == 1) & (t.repetition == 0) & (t.phase == "forces")]
        self.assertEqual(row.seconds.tolist(), [0.0003912214142956283])
        self.assertEqual(row.N.tolist(), [8000])  # the label's particles, the label's threads (not Google Benchmark's)
        self.assertEqual(len(t[t.family == "phases"]), 6 * 4)  # 2 thread counts × 3 repetitions × 4 phases
        stream = t[t.family == "stream"]
        self.assertEqual(len(stream), 4)  # untimed: one row each, no phase
        self.assertTrue(stream.phase.isna().all())
        w = results.wide(t)
        self.assertEqual(len(w), 10)
        self.assertTrue(w[w.family == "stream"].total_s.isna().all())

    def test_unknown_schema(self):
        with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
            f.write('{"something": 1}')
            f.flush()
            with self.assertRaises(ValueError):
                results.load(f.name)


class PeerContacts(unittest.TestCase):
    """peer_contacts.py: the four-grain scene keeps the stage's law and walls and sets each contact up as
    meant; the comparison reports the largest difference per grain, in v and in R·ω."""

    def setUp(self):
        import peer_contacts
        self.pc = peer_contacts
        self.work = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, self.work)

    def test_scene_sets_up_one_contact_per_grain_and_keeps_the_law(self):
        import tomllib
        # The committed compression scene, with a law of memory; its particles come from a state file.
        with open(os.path.join(HERE, os.pardir, "scenes", "dense_bed_2000_compression.toml")) as f:
            text = f.read().replace("[particles]", '[contact]\ntangential = "mindlin"\n\n[particles]', 1)
        with open(os.path.join(self.work, "stage.toml"), "w") as f:
            f.write(text)
        out = os.path.join(self.work, "c.toml")
        self.pc.cmd_scene(type("A", (), {"stage": os.path.join(self.work, "stage.toml"), "o": out}))
        with open(out, "rb") as f:
            s = tomllib.load(f)
        self.assertEqual(s["time"]["gravity"], [0, 0, 0])
        self.assertEqual(s["contact"]["tangential"], "mindlin")
        self.assertEqual(len(s["wall"]), 6)
        g = s["particles"]["particle"]
        self.assertEqual(len(g), 4)
        lo, hi = s["domain"]["min"], s["domain"]["max"]
        pos = [p["position"] for p in g]
        rad = [p["radius"] for p in g]
        for x, r in zip(pos, rad):
            for c in range(3):
                self.assertTrue(lo[c] + r <= x[c] <= hi[c] - r, f"a grain outside the domain: {x}")
        d = [b - a for a, b in zip(pos[0], pos[1])]
        gap = sum(c * c for c in d) ** 0.5 - rad[0] - rad[1]
        closing = -sum((vb - va) * c for va, vb, c in zip(g[0]["velocity"], g[1]["velocity"], d))
        self.assertGreater(gap, 0.0)
        self.assertGreater(closing, 0.0, "the pair must approach")
        self.assertAlmostEqual(hi[0] - pos[2][0] - rad[2], 0.0075)
        self.assertAlmostEqual(pos[3][2] - lo[2] - rad[3], 0.001)
        self.assertLess(g[3]["velocity"][2], 0.0, "the grain must fall onto z_min")

    def dump(self, name, frames):
        with open(os.path.join(self.work, name), "w") as f:
            for step, rows in frames:
                f.write(f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{len(rows)}\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
                        "ITEM: ATOMS id radius x y z vx vy vz omegax omegay omegaz\n")
                for r in rows:
                    f.write(" ".join(repr(float(v)) for v in r) + "\n")

    def test_compare_reports_the_largest_difference_per_grain(self):
        base = [[i + 1, 0.004, 0, 0, 0, 0.1, 0, 0, 0, 0, 1.0] for i in range(4)]
        moved = [list(r) for r in base]
        moved[2][6] += 3e-4       # grain 3: Δv_y
        moved[1][9] += 2.0        # grain 2: Δω_y, R·Δω = 8e-3
        self.dump("lammps.dump", [(0, base), (500, base)])
        self.dump("suite.dump", [(0, base), (500, moved)])
        self.dump("suite_as_lammps.dump", [(0, base), (500, base)])
        with open(os.path.join(self.work, "versions.json"), "w") as f:
            f.write('{"lammps": "test"}')
        out = os.path.join(self.work, "out")
        self.pc.cmd_compare(type("A", (), {"work": self.work, "versions": os.path.join(self.work, "versions.json"),
                                           "build": [], "out": out}))
        import pandas as pd
        df = pd.read_csv(os.path.join(out, "single_contacts.csv")).set_index(["code", "grain"])
        self.assertAlmostEqual(df.loc[("suite", 3), "max_dv"], 3e-4, delta=1e-9)
        self.assertAlmostEqual(df.loc[("suite", 2), "max_r_domega"], 8e-3, delta=1e-9)
        self.assertEqual(df.loc[("suite", 1), "max_dv"], 0.0)
        self.assertEqual(float(df.xs("suite_as_lammps").max().max_dv), 0.0)
        self.assertIn("suite_as_lammps", set(df.index.get_level_values(0)))


class OneN(unittest.TestCase):
    def test_no_curve_against_n_from_one_n(self):
        """The sample has one N: scaling and where-the-time-goes are tables, and a stale figure goes."""
        root = tempfile.mkdtemp()
        try:
            figs = os.path.join(root, "figures")
            os.makedirs(figs)
            open(os.path.join(figs, "scaling_one.png"), "w").close()  # left by other data
            done = subprocess.run([sys.executable, os.path.join(ANALYSIS, "plot_figures.py"), os.path.join(DATA, "gbench_sample.json"),
                                   "--out", root, "--figures", figs, "--suffix", "one"], capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual(os.listdir(figs), [])
            self.assertIn("| settled | fast | 2 | 8000 |", open(os.path.join(root, "scaling.md")).read())
            self.assertIn("| 8000 | 1 | forces |", open(os.path.join(root, "where_the_time_goes.md")).read())
        finally:
            shutil.rmtree(root)


class Report(unittest.TestCase):
    def test_sections_present_and_missing(self):
        root = tempfile.mkdtemp()
        try:
            os.makedirs(os.path.join(root, "main"))
            os.makedirs(os.path.join(root, "sweep_short"))
            shutil.copy(os.path.join(DATA, "bench_sample.json"), os.path.join(root, "main", "bench_compression_2000.json"))
            shutil.copy(os.path.join(DATA, "gbench_sample.json"), os.path.join(root, "sweep_short", "bench.json"))
            out = os.path.join(root, "REPORT.md")
            done = subprocess.run([sys.executable, os.path.join(ANALYSIS, "make_report.py"), "--results", root, "--out", out],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual(done.stdout.strip(), out)
            text = open(out).read()
            self.assertIn("## Result sets", text)
            self.assertIn("| [main](main) | Figure 7", text)
            self.assertIn("| [sweep_short](sweep_short) |", text)
            with open(os.path.join(root, "main", "set.json")) as f:
                self.assertEqual(json.load(f)["question"], "Figure 7: each style phase by phase")
            self.assertIn("| arrays | 15.0 (1.00×) | 656.7 (1.00×)", text)  # Figure 7 from the bench sample: µs per step, medians of 2
            for script in ("scripts/run_figures.sh", "scripts/run_peers.sh", "scripts/run_accuracy.sh",
                           "scripts/run_stability.sh", "scripts/run_features.sh", "scripts/run_memory_cost.sh",
                           "scripts/run_validation.sh", "scripts/run_mpi_bench.sh"):
                self.assertIn(f"Produce it with `{script}`", text)
            self.assertNotIn("`scripts/run_main.sh`", text)  # Figure 7 is present
            self.assertFalse([f for f in os.listdir(root) if f.endswith(".tmp") or f.startswith("tmp")])
        finally:
            shutil.rmtree(root)


    def test_fast_beside_both_lammps_builds_is_a_section_naming_their_flags(self):
        import pandas as pd
        import plot_peers
        root = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, root)
        rows = [{"code": code, "variant": code if code != "suite" else "fast", "threads": 1, "particles": 1000, "stage": "bed",
                 "repetition": 0, "steps": 1000, "phase": "total", "seconds_per_step": t}
                for code, t in (("suite", 4e-5), ("lammps_native", 1e-4), ("lammps", 1.2e-4))]
        out = os.path.join(root, "peers_fast_xeon")
        plot_peers.write_bench(pd.DataFrame(rows), {"cpu": "test CPU"}, test_peers_bench.PeersBench.NATIVE, out,
                               os.path.join(out, "peers_us_per_particle_step.png"))
        report = os.path.join(root, "REPORT.md")
        done = subprocess.run([sys.executable, os.path.join(ANALYSIS, "make_report.py"), "--results", root, "--out", report],
                              capture_output=True, text=True, timeout=120)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(report) as f:
            text = f.read().split("## fast beside LAMMPS (peers_fast_xeon)")[1]
        self.assertIn("| LAMMPS -O3 -march=native | 1.00 |", text)
        self.assertIn("| LAMMPS Debian (-g -O2, baseline x86-64) | 1.20 |", text)
        self.assertIn("peers_fast_xeon/peers_us_per_particle_step.png", text)

    def test_validation_summary_counts_each_verdict(self):
        """Chung & Ooi's summary: passes over judged values, and the paper's law's expected differences apart."""
        root = tempfile.mkdtemp()
        try:
            os.makedirs(os.path.join(root, "validation"))
            rows = ["test,law,variant,quantity,pass"]
            rows += [f"4,mindlin,arrays,spin,{v}" for v in ("pass", "pass", "FAIL", "info")]
            rows += [f"4,paper,arrays,spin,{v}" for v in ("pass", "agrees", "differs (no tangential spring)", "differs (no tangential spring)")]
            with open(os.path.join(root, "validation", "errors.csv"), "w") as f:
                f.write("\n".join(rows) + "\n")
            out = os.path.join(root, "REPORT.md")
            done = subprocess.run([sys.executable, os.path.join(ANALYSIS, "make_report.py"), "--results", root, "--out", out],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr)
            text = open(out).read()
            self.assertIn("| test | paper | mindlin |", text)
            self.assertIn("| 4 | 1 / 1; 1 / 3 | 2 / 3 |", text)  # the FAIL counts against mindlin; info is not judged
            self.assertNotIn("Produce it with `scripts/run_validation.sh`", text)
        finally:
            shutil.rmtree(root)


    def test_the_answers_come_first_in_order_then_the_result_sets(self):
        """On the repository's own results: every answer within the first 60 lines, in order, then provenance."""
        import report_answers
        with tempfile.TemporaryDirectory() as d:
            root = os.path.join(d, "results")
            shutil.copytree(os.path.join(HERE, os.pardir, "results"), root)
            out = os.path.join(root, "REPORT.md")
            done = subprocess.run([sys.executable, os.path.join(ANALYSIS, "make_report.py"), "--results", root, "--out", out],
                                  capture_output=True, text=True, timeout=300)
            self.assertEqual(done.returncode, 0, done.stderr)
            with open(out, encoding="utf-8") as f:
                lines = f.read().splitlines()
        screen = "\n".join(lines[:60])
        where = [screen.find(f"**{a}**") for a in report_answers.ANSWERS]
        self.assertNotIn(-1, where, [a for a, w in zip(report_answers.ANSWERS, where) if w < 0])
        self.assertEqual(where, sorted(where))
        self.assertNotIn("not present", screen)  # every answer's result set is committed
        self.assertLess(max(where), screen.find("## Result sets") if "## Result sets" in screen else len(screen))
        self.assertIn("## Result sets", "\n".join(lines))
        self.assertFalse([l for l in lines[:60] if l.startswith("## ") and l != "## Result sets"])
        tests = [l for l in lines[:60] if re.match(r"- test \d: ", l)]
        self.assertEqual(len(tests), 8)  # validation: one line per test

    def test_a_set_measured_before_a_change_of_code_is_marked(self):
        """The set's commit against the last commit that changed its code (a comment alone is no change)."""
        import result_sets
        with tempfile.TemporaryDirectory() as repo:
            def git(*args):
                return subprocess.run(["git", "-C", repo, "-c", "user.name=t", "-c", "user.email=t@t", *args],
                                      capture_output=True, text=True, check=True).stdout.strip()

            def commit(text, message):
                os.makedirs(os.path.join(repo, "common"), exist_ok=True)
                with open(os.path.join(repo, "common", "law.cpp"), "w") as f:
                    f.write(text)
                git("add", "-A")
                git("commit", "-qm", message)
                return git("rev-parse", "HEAD")

            git("init", "-q")
            measured = commit("int f() { return 1; }\n", "code")
            prov = {"commits": {measured}, "cpus": {"cpu A"}, "dirty": False}
            commit("// why f returns 1\nint f() { return 1; }\n", "a comment")
            self.assertEqual(result_sets.status("", "main", prov, "cpu A", repo), "current")
            self.assertEqual(result_sets.status("", "main", prov, "cpu B", repo), "another CPU")
            changed = commit("// why f returns 1\nint f() { return 2; }\n", "code changed")
            self.assertEqual(result_sets.status("", "main", prov, "cpu A", repo),
                             f"older than the code it measured (changed at {changed[:10]})")
            self.assertEqual(result_sets.status("", "main", {**prov, "commits": {changed}}, "cpu A", repo), "current")


class Experiments(unittest.TestCase):
    """results/experiments/README.md is the table of the records beside it, and a record is checked."""
    FOLDER = os.path.join(HERE, os.pardir, "results", "experiments")

    def test_the_committed_table_is_generated_from_the_records(self):
        import experiments_table
        records = experiments_table.load(self.FOLDER)
        self.assertGreater(len(records), 30)
        with open(os.path.join(self.FOLDER, "README.md"), encoding="utf-8") as f:
            self.assertEqual(f.read(), experiments_table.render(records))
        self.assertEqual(subprocess.run([sys.executable, os.path.join(ANALYSIS, "experiments_table.py"), "--check",
                                         "--folder", self.FOLDER]).returncode, 0)

    def test_a_changed_record_changes_the_table_and_a_bad_one_is_refused(self):
        import experiments_table
        with tempfile.TemporaryDirectory() as d:
            for name in os.listdir(self.FOLDER):
                shutil.copy(os.path.join(self.FOLDER, name), d)
            path = os.path.join(d, "law-on-16-lanes.json")
            with open(path) as f:
                rec = json.load(f)
            rec["readings"][0]["ratio"] = 9.875
            with open(path, "w") as f:
                json.dump(rec, f)
            self.assertIn("forces 9.875 (1.744–2.707)", experiments_table.render(experiments_table.load(d)))
            check = [sys.executable, os.path.join(ANALYSIS, "experiments_table.py"), "--check", "--folder", d]
            self.assertEqual(subprocess.run(check, stderr=subprocess.DEVNULL).returncode, 1)
            del rec["cpu"]
            with open(path, "w") as f:
                json.dump(rec, f)
            with self.assertRaisesRegex(ValueError, "missing cpu"):
                experiments_table.load(d)


class Docs(unittest.TestCase):
    """The pages a reader reads: no figure left in a commit message, every relative link resolves, pages short."""
    ROOT = os.path.normpath(os.path.join(HERE, os.pardir))
    # Phrases that send a reader to a commit message (git's history) for a figure.
    TO_A_MESSAGE = re.compile(r"commit'?s?'? messages?|messages? of the commits?|readings are in the", re.I)

    def pages(self):
        docs = os.path.join(self.ROOT, "docs")
        found = [os.path.join(self.ROOT, "README.md")]
        for folder, _, names in os.walk(docs):
            found += [os.path.join(folder, n) for n in sorted(names) if n.endswith(".md")]
        return found

    def test_no_page_points_to_a_commit_message(self):
        # the pattern catches the sentences the pages used to hold, so that the check can fail
        for old in ("the readings are in the message of the commit that made the change",
                    "the commit's message has the paired readings", "in the messages of the commits that added"):
            self.assertRegex(old, self.TO_A_MESSAGE)
        for page in self.pages():
            with open(page, encoding="utf-8") as f:
                for n, line in enumerate(f, 1):
                    self.assertIsNone(self.TO_A_MESSAGE.search(line), f"{os.path.relpath(page, self.ROOT)}:{n}: {line.strip()}")

    def test_no_file_cites_an_issue_number(self):
        """A reader of the repository cannot see the issues: comments and pages say why, not which issue."""
        if not os.path.isdir(os.path.join(self.ROOT, ".git")) and not os.path.isfile(os.path.join(self.ROOT, ".git")):
            self.skipTest("not a git checkout")
        pattern = "issue" + " [0-9]"  # split, so that this file does not match itself
        found = subprocess.run(["git", "-C", self.ROOT, "grep", "-n", "-I", pattern], capture_output=True, text=True)
        self.assertEqual(found.returncode, 1, found.stdout[:2000])  # 1: nothing found

    @staticmethod
    def anchors(page):
        """The anchors GitHub makes of a page's headings: lower case, punctuation dropped, spaces as hyphens."""
        with open(page, encoding="utf-8") as f:
            heads = [m.group(1).strip().lower() for m in re.finditer(r"^#+ (.*)$", f.read(), flags=re.M)]
        return {re.sub(r"[^\w\- ]", "", h).replace(" ", "-") for h in heads}

    def test_every_relative_link_resolves(self):
        link = re.compile(r"\]\(([^)#\s]*)(?:#([^)\s]*))?\)")
        for page in self.pages():
            with open(page, encoding="utf-8") as f:
                text = f.read()
            for target, anchor in link.findall(text):
                if re.match(r"[a-z]+:", target):
                    continue  # a URL
                path = os.path.normpath(os.path.join(os.path.dirname(page), target)) if target else page
                name = f"{os.path.relpath(page, self.ROOT)} links {target}#{anchor}"
                self.assertTrue(os.path.exists(path), f"{name}, which does not exist")
                if anchor and path.endswith(".md"):
                    self.assertIn(anchor, self.anchors(path), f"{name}: no such heading")

    def test_pages_are_short(self):
        for page in self.pages():
            with open(page, encoding="utf-8") as f:
                lines = sum(1 for _ in f)
            limit = 150 if os.sep + "variants" + os.sep in page else 400
            self.assertLessEqual(lines, limit, os.path.relpath(page, self.ROOT))


class ValidationReference(unittest.TestCase):
    """The Chung & Ooi references (analysis/validation_reference.py) against what they must reproduce."""

    def row(self, **kw):
        r = dict(test=1, law="paper", radius1=0.01, radius2=0.01, density=2800, young=4.8e10, poisson=0.2, mu=0.0,
                 restitution=1.0, value=0.0)
        r.update(kw)
        return r

    def test_integration_of_the_elastic_law_is_hertz(self):
        import validation_reference as vr
        c = vr.Case(self.row())
        r = vr.integrate(c, 2000)
        h, f, tc = vr.hertz(c.mstar, c.rstar, c.estar, c.vn)
        self.assertAlmostEqual(r["contact_time"] / tc, 1.0, delta=1e-6)
        self.assertAlmostEqual(r["peak_force"] / f, 1.0, delta=1e-6)
        self.assertAlmostEqual(r["normal_restitution"], 1.0, delta=1e-6)

    def test_damping_solved_for_e_rebounds_at_e(self):
        import validation_reference as vr
        for law in ("paper", "restitution"):
            c = vr.Case(self.row(test=3, law=law, radius2=0.0, radius1=0.0025, density=4000, young=3.8e11, poisson=0.23,
                                 restitution=0.5, value=0.5))
            self.assertAlmostEqual(vr.integrate(c, 2000)["normal_restitution"], 0.5, delta=1e-3)

    def test_gross_slip_at_a_grazing_angle(self):
        import validation_reference as vr
        for law in ("paper", "mindlin"):
            c = vr.Case(self.row(test=4, law=law, radius2=0.0, radius1=0.0025, density=4000, young=3.8e11, poisson=0.23,
                                 mu=0.092, restitution=0.98, value=60.0))
            gross, _, is_gross = vr.limits(c)
            self.assertTrue(is_gross)
            r = vr.integrate(c, 2000)
            self.assertAlmostEqual(r["spin"] / gross["spin"], 1.0, delta=1e-2)
            self.assertAlmostEqual(r["tangential_velocity"] / gross["tangential_velocity"], 1.0, delta=1e-2)


if __name__ == "__main__":
    unittest.main()
