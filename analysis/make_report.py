#!/usr/bin/python3
"""One report of every result present: results/REPORT.md.

Machine and provenance from every result file (through results.py); Figure 7 computed from the
`demmat bench` JSON with the paper's ratios beside; Figure 4 and the sweep, the peers, the validation
against them, accuracy, stability and feature costs from the tables their scripts wrote. A result that
is absent gets a line naming the script that makes it. Images are linked relative to the report.

Usage: /usr/bin/python3 analysis/make_report.py [--results results] [--out results/REPORT.md] [--paper PAPER.json]
"""
import argparse
import glob
import os
import re
import sys

from atomic_io import write_text
from plot_phases import markdown as phases_markdown, paper_ratios, phase_stats
from results import PAPER_JSON, load
import report_answers as answers
import result_sets


class Report:
    def __init__(self, root, out):
        self.root, self.folder, self.lines = root, os.path.dirname(os.path.abspath(out)), []

    def add(self, *lines):
        self.lines += list(lines)

    def path(self, rel):
        return os.path.join(self.root, rel)

    def image(self, rel, alt):
        """A relative link to results/<rel> when the file exists."""
        p = self.path(rel)
        if os.path.exists(p):
            self.add(f"![{alt}]({os.path.relpath(p, self.folder)})", "")

    def link(self, rel):
        return f"[{rel}]({os.path.relpath(self.path(rel), self.folder)})"

    def include(self, rel):
        """A Markdown file the analysis wrote, its headings put under the report's sections."""
        with open(self.path(rel)) as f:
            text = f.read().strip()
        self.add(re.sub(r"^(#+) ", lambda m: "##" + m.group(1) + " ", text, flags=re.M), "", f"(from {self.link(rel)})", "")

    def missing(self, what, script):
        self.add(f"Not present: {what}. Produce it with `{script}`.", "")


def newest(root, pattern):
    found = sorted(glob.glob(os.path.join(root, pattern)))
    return os.path.relpath(found[-1], root) if found else None


def report_cpu(root):
    """The report's CPU: the one Figure 7 ran on (the main job's machine), else the newest result's."""
    for folder in ("main", "fast", "peers_fast"):
        prov = result_sets.describe(root, folder)
        if prov and len(prov["cpus"]) == 1:
            return next(iter(prov["cpus"]))
    return None


def provenance(rep, described):
    """One line per result set: its question, commit, CPU, compiler and date, and whether it is current."""
    rep.add("## Result sets", "",
            "One row per folder of results/ (each also names its question and CPU in its set.json, and every result "
            "file carries its own provenance). *Current*: measured at or after the last change to the code it "
            "measured, on the report's CPU.", "",
            "| set | question | commit | CPU | compiler | date | status |", "|---|---|---|---|---|---|---|")
    for folder, question, _, prov, state in described:
        commits = ", ".join(sorted(c[:10] for c in prov["commits"]))
        dates = sorted(prov["dates"])
        span = dates[0] if dates[0] == dates[-1] else f"{dates[0]} to {dates[-1]}"
        state = "current" if state == "current" else f"**{state}**"
        rep.add(f"| {rep.link(folder)} | {question} | {commits} | {'; '.join(sorted(prov['cpus']))} | "
                f"{', '.join(sorted(prov['compilers']))} | {span} | {state} |")
    rep.add("")


def figure7(rep, paper):
    rep.add("## Figure 7: per-phase CPU time per variant, against the paper", "")
    files = sorted(glob.glob(rep.path("main/bench_compression_*.json")))
    if not files:
        rep.missing("the per-phase benchmark of every variant (results/main/bench_compression_N.json)", "scripts/run_main.sh")
        return
    for path in files:
        res = load(path)
        stats, order = phase_stats(res)
        rep.add(phases_markdown(stats, [name for name, _, _ in order], res) + paper_ratios(stats, paper), "")
        rep.image(f"figures/phases_compression_{res.meta['scene']['particles']}.png", "Per-phase CPU time per variant")


def sweep(rep):
    rep.add("## Figure 4: contact search with and without cells; the sweep", "")
    name = next((s for s in ("full", "short") if os.path.exists(rep.path(f"sweep_{s}/figure4.md"))), None)
    if name is None:
        rep.missing("the sweep of Figure 4, cell sizes, scaling and where the time goes", "scripts/run_figures.sh")
        return
    rep.include(f"sweep_{name}/figure4.md")
    rep.image(f"figures/figure4_{name}.png", "Figure 4")
    more = [rel for rel in (f"sweep_{name}/cellsize.md", f"sweep_{name}/scaling.md", f"sweep_{name}/where_the_time_goes.md",
                            "sweep_million/scaling.md", "sweep_million/where_the_time_goes.md", "fast/summary.md")
            if os.path.exists(rep.path(rel))]
    if more:
        rep.add("Also: " + ", ".join(rep.link(rel) for rel in more) + ".", "")
    for fig, alt in ((f"cellsize_{name}", "Cell-size sweep"), (f"scaling_{name}", "Scaling"), (f"where_{name}", "Where the time goes")):
        rep.image(f"figures/{fig}.png", alt)


def section(rep, title, tables, figures, what, script):
    """A section from the Markdown tables a script wrote, or the line saying how to make them."""
    rep.add(f"## {title}", "")
    present = [t for t in tables if t and os.path.exists(rep.path(t))]
    if not present:
        rep.missing(what, script)
        return
    for t in present:
        rep.include(t)
    for fig, alt in figures:
        if fig:
            rep.image(fig, alt)


def experiments(rep):
    """The table of experiments tried on the variants, regenerated from its records."""
    if not glob.glob(rep.path("experiments/*.json")):
        return
    import experiments_table
    folder = rep.path("experiments")
    write_text(os.path.join(folder, "README.md"), experiments_table.render(experiments_table.load(folder)))


def validation(rep):
    """Chung & Ooi's tests: judged values passed per test and law (errors.csv), the full table linked."""
    rep.add("## Validation: Chung & Ooi (2011) tests 1–8", "")
    rel = "validation/errors.csv"
    if not os.path.exists(rep.path(rel)):
        rep.missing("the Chung & Ooi validation", "scripts/run_validation.sh")
        return
    import pandas as pd  # only here: the other sections need no pandas
    df = pd.read_csv(rep.path(rel))
    # pass/fail: judged against a reference of the same law; agrees/differs: the paper's law (no tangential
    # spring) beside the compliant laws' reference, expected to differ (docs/validation.md); info: not judged.
    df = df[df["pass"] != "info"]
    laws = sorted(df.law.unique(), key=lambda l: (l != "paper", l))
    rep.add("Per test and law, over every variant, material and integrator that ran: judged values that pass / judged; "
            "after a semicolon, the paper's law beside the tangentially compliant reference, which it is expected "
            "not to follow (it has no tangential spring): agrees / compared. The worst case of each quantity, its "
            f"reference and tolerance: {rep.link('validation/table.md')}; the method: docs/validation.md.", "",
            "| test | " + " | ".join(laws) + " |", "|---|" + "---:|" * len(laws))
    for test, t in df.groupby("test"):
        cells = []
        for law in laws:
            x = t[t.law == law]
            judged = x[~x["pass"].isin(["agrees"]) & ~x["pass"].str.startswith("differs")]
            compared = x[x["pass"].eq("agrees") | x["pass"].str.startswith("differs")]
            cell = f"{int((judged['pass'] == 'pass').sum())} / {len(judged)}" if len(judged) else ""
            if len(compared):
                cell += f"; {int((compared['pass'] == 'agrees').sum())} / {len(compared)}"
            cells.append(cell)
        rep.add(f"| {test} | " + " | ".join(cells) + " |")
    rep.add("")
    for k in range(1, 9):
        rep.image(f"validation/test{k}.png", f"Chung & Ooi test {k}")


def build(root, out, paper):
    rep = Report(root, out)
    cpu = report_cpu(root)
    described = result_sets.sets(root, cpu)
    cpu_of = {d: "; ".join(sorted(p["cpus"])) for d, _, _, p, _ in described}
    rep.add("# demmat: the results", "",
            f"Generated by analysis/make_report.py from the files under results/. This machine: {cpu or 'unknown'} "
            "(Figure 7's). The machines were shared: compare figures only within one result set; "
            "[Result sets](#result-sets) says which sets are current.", "")

    def stats_of(path):
        res = load(path)
        stats, order = phase_stats(res)
        return res, stats, [name for name, _, _ in order]

    answers.figure7(rep, stats_of)
    answers.lammps(rep, lambda folder: cpu_of.get(folder, "?"))
    answers.memory(rep)
    answers.accuracy(rep)
    answers.validation(rep)
    answers.mpi(rep)
    answers.cuda(rep)
    rep.add("")
    provenance(rep, described)
    result_sets.write_set_files(root, described)
    experiments(rep)
    figure7(rep, paper)
    sweep(rep)
    physics = newest(root, "peers/physics_*.md")
    n = physics and re.search(r"physics_(\d+)\.md", physics).group(1)
    features = newest(root, "features/features_*.md")
    nf = features and re.search(r"features_(\d+)\.md", features).group(1)
    section(rep, "Beside LAMMPS and LIGGGHTS: time per step", ["peers/bench_peers.md"],
            [("figures/peers_us_per_particle_step.png", "µs per particle-step against N")],
            "the benchmark beside LAMMPS and LIGGGHTS", "scripts/run_peers.sh")
    section(rep, "Validation: the physics beside LAMMPS and LIGGGHTS", [physics, "peers/single_contacts.md"],
            [(n and f"figures/peers_physics_{n}.png", "Physics cross-check")],
            "the ensemble cross-check of the physics against LAMMPS and LIGGGHTS", "scripts/run_peers.sh")
    for folder, law, keys in (("peers_mindlin", "tangential mindlin", "tangential=mindlin ..."),
                              ("peers_mindlin_sds", "tangential mindlin, rolling sds", "tangential=mindlin ... rolling=sds ...")):
        section(rep, f"Beside LAMMPS with contact memory ({law}): time per step", [f"{folder}/bench_peers.md"],
                [(f"{folder}/peers_us_per_particle_step.png", f"µs per particle-step against N, {law}")],
                "the benchmark beside LAMMPS with a law of physics.md §9", f"scripts/run_peers.sh --contact \"{keys}\" --out results/{folder}")
        physics_law = newest(root, f"{folder}/physics_*.md")
        section(rep, f"The physics beside LAMMPS with contact memory ({law})", [physics_law, f"{folder}/single_contacts.md"],
                [(physics_law and physics_law.replace("physics_", "peers_physics_").replace(".md", ".png"), f"Physics cross-check, {law}")],
                "the ensemble cross-check with a law of physics.md §9", f"scripts/run_peers.sh --contact \"{keys}\" --out results/{folder}")
    # fast beside LAMMPS on each CPU that has a run: both LAMMPS builds named with their flags, fast's targets.
    for folder in sorted(os.path.basename(f) for f in glob.glob(os.path.join(root, "peers_fast*"))):
        section(rep, f"fast beside LAMMPS built for the CPU and Debian's binary ({folder})", [f"{folder}/bench_peers.md"],
                [(f"{folder}/peers_us_per_particle_step.png", f"µs per particle-step against N ({folder})")],
                "fast's targets beside LAMMPS", f"scripts/run_peers.sh --bench-only --variants fast,fast_unordered --out results/{folder}")
    section(rep, "What contact memory costs each style", ["memory_cost/table.md"], [("memory_cost/memory_cost.png", "memory cost")],
            "the cost of contact memory per style", "scripts/run_memory_cost.sh")
    validation(rep)
    section(rep, "Distributed memory: the mpi variant", ["mpi/bench_mpi.md", "mpi/halo_mpi.md", "mpi/imbalance_mpi.md"], [],
            "the mpi benchmark, halo traffic and imbalance", "scripts/run_mpi_bench.sh")
    if os.path.exists(rep.path("mpi/scaling.md")):
        rep.add(f"The scaling model from these measurements: {rep.link('mpi/scaling.md')}.", "")
    section(rep, "The GPU style: the cuda variant", ["gpu/summary.md"], [],
            "the cuda variant's check on a GPU (bit for bit against arrays, µs per particle-step beside fast)",
            "scripts/device_check.sh --pack here, then scripts/device_check.sh on a GPU machine, then analysis/summarise_gpu.py results/gpu")
    section(rep, "Accuracy: error against time step and CPU time", ["accuracy/recommendation.md"],
            [("figures/accuracy_work_precision.png", "work–precision"), ("figures/accuracy_error_vs_dt.png", "error against Δt")],
            "the speed–accuracy study", "scripts/run_accuracy.sh")
    section(rep, "Stability: the largest stable time step", ["stability/stability_default.md", "stability/stability_long.md"],
            [("figures/stability_map.png", "stability map"), ("figures/stability_map_long.png", "stability map, long run")],
            "the stability map", "scripts/run_stability.sh")
    section(rep, "What each model feature costs", [features], [(nf and f"figures/features_{nf}.png", "feature costs")],
            "the feature costs", "scripts/run_features.sh")
    write_text(out, "\n".join(rep.lines).rstrip() + "\n")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results", help="the results folder (default: results)")
    ap.add_argument("--out", help="the report (default: REPORT.md in the results folder)")
    ap.add_argument("--paper", default=PAPER_JSON, help="the paper's figures (default: data/paper.json in the repository)")
    a = ap.parse_args(argv)
    if not os.path.isdir(a.results):
        sys.exit(f"make_report.py: no results folder {a.results}")
    out = a.out or os.path.join(a.results, "REPORT.md")
    build(a.results, out, a.paper)
    print(out)


if __name__ == "__main__":
    main(sys.argv[1:])
