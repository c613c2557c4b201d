"""The mpi variant's benchmark tables (scripts/run_mpi_bench.sh, docs/scaling.md), from the work files of one
run: mpi at R = 1 and 2 (demmat_mpi bench), fast on 1 and 2 threads (demmat bench), LAMMPS on 2 processes,
each a median of µs per particle-step over the interleaved repetitions; and the halo traffic of mpi per
step per rank (demmat_mpi run on the dense bed's lattice).
Writes, in --out:
  bench_mpi.json   medians, every sample, the provenance of the suite's runs, the peers' versions
  bench_mpi.csv    one row per (N, configuration): median, min, max µs per particle-step
  bench_mpi.md     the comparison and its targets (listed in docs/scaling.md), each said to be met or not
  halo_mpi.csv     one row per (N, R): particles, ghosts, messages and bytes per step per rank (mean, max)
  halo_mpi.md      the same as a table
  imbalance_mpi.csv, .md  particles per rank (max/mean at the end, the most a rank held/mean) of the static
                   bricks on the bed and the compression stage, cut by count and evenly, at R = 2 and 4
Usage: mpi_bench.py --work DIR --versions FILE --out DIR
"""
import argparse
import glob
import json
import os
import re
import sys

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402
from atomic_io import write_text  # noqa: E402

CONFIGS = ["mpi R=1", "mpi R=2", "fast 1 thread", "fast 2 threads", "lammps np=2"]


def samples(work):
    """One row per (N, configuration, repetition): µs per particle-step; and the suite's provenance."""
    rows, prov = [], None
    for path in sorted(glob.glob(os.path.join(work, "mpi*_n*_r*.json"))):
        r = results.load(path)
        n, rep = map(int, re.search(r"_n(\d+)_r(\d+)\.json$", path).groups())
        t = r.table
        compute = t[t.phase != "communicate"].groupby("rank")["seconds"].sum()
        ranks = t[t.phase == "predict"]
        rows.append({"N": n, "config": f"mpi R={r.meta['processes']}", "repetition": rep, "us": r.meta["us_per_particle_step"],
                     # the slowest rank's compute (every phase but communicate), the ranks' mean communicate, per step
                     "compute_s": compute.max(), "communicate_s": t[t.phase == "communicate"]["seconds"].mean(),
                     "ghosts_mean": ranks["ghosts"].mean()})
        prov = prov or r.provenance
    for path in sorted(glob.glob(os.path.join(work, "fast_n*_r*.json"))):
        r = results.load(path)
        rep = int(re.search(r"_r(\d+)\.json$", path).group(1))
        per_sample = r.table.groupby(["threads_asked", "N", "sample"], as_index=False)["seconds"].sum()
        for _, s in per_sample.iterrows():
            t = int(s["threads_asked"])
            rows.append({"N": int(s["N"]), "config": f"fast {t} thread{'s' if t > 1 else ''}", "repetition": rep,
                         "us": s["seconds"] / s["N"] * 1e6})
    for path in sorted(glob.glob(os.path.join(work, "lammps_n*_r*.json"))):
        with open(path) as f:
            raw = json.load(f)
        rows.append({"N": raw["particles"], "config": "lammps np=2", "repetition": raw["repetition"],
                     "us": raw["seconds"] / raw["steps"] / raw["particles"] * 1e6})
    return pd.DataFrame(rows), prov


def halo(work):
    rows = []
    for path in sorted(glob.glob(os.path.join(work, "halo_n*_np*.json"))):
        r = results.load(path)
        t = r.table[r.table["phase"] == "predict"]  # one row per rank
        rows.append({"N": int(t["N"].iloc[0]), "R": int(r.meta["processes"]),
                     "particles_mean": t["particles"].mean(), "particles_max": t["particles"].max(),
                     "ghosts_mean": t["ghosts"].mean(), "ghosts_max": t["ghosts"].max(),
                     "messages_per_step_mean": t["messages_per_step"].mean(), "messages_per_step_max": t["messages_per_step"].max(),
                     "bytes_per_step_mean": t["bytes_per_step"].mean(), "bytes_per_step_max": t["bytes_per_step"].max(),
                     "grid": r.meta["decomposition"].get("grid", "slabs along " + str(r.meta["decomposition"].get("axis"))),
                     "face_area_m2": r.meta["decomposition"].get("face_area_m2"),
                     "halo_m": r.meta["decomposition"].get("halo_m")})
    return pd.DataFrame(rows).sort_values(["N", "R"]) if rows else pd.DataFrame()


def imbalance(work):
    rows = []
    for path in sorted(glob.glob(os.path.join(work, "imbalance_n*_*_*_np*.json"))):
        n, stage, balance, np_ = re.search(r"imbalance_n(\d+)_(\w+?)_(count|even)_np(\d+)\.json$", path).groups()
        r = results.load(path)
        t = r.table[r.table["phase"] == "predict"]
        ranks = r.meta["decomposition"]["ranks"]
        most = max(q["particles_most"] for q in ranks)
        mean = t["particles"].mean()
        rows.append({"N": int(n), "stage": stage, "balance": balance, "R": int(np_), "steps": r.meta["steps"],
                     "grid": r.meta["decomposition"].get("grid", "slabs"),
                     "max_over_mean": t["particles"].max() / mean, "most_held_over_mean": most / mean,
                     "min_over_mean": t["particles"].min() / mean})
    return pd.DataFrame(rows).sort_values(["N", "stage", "balance", "R"]) if rows else pd.DataFrame()


def verdict(ok):
    return "met" if ok else "not met"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", required=True)
    ap.add_argument("--versions", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    df, prov = samples(a.work)
    if df.empty:
        sys.exit(f"mpi_bench.py: no samples in {a.work}")
    with open(a.versions) as f:
        versions = json.load(f)
    med = df.groupby(["N", "config"])["us"].agg(["median", "min", "max", "count"]).reset_index()
    extra = [c for c in ("compute_s", "communicate_s", "ghosts_mean") if c in df]
    if extra:
        med = med.merge(df.groupby(["N", "config"])[extra].median().reset_index(), on=["N", "config"], how="left")
    med.to_csv(os.path.join(a.out, "bench_mpi.csv.tmp"), index=False)
    os.replace(os.path.join(a.out, "bench_mpi.csv.tmp"), os.path.join(a.out, "bench_mpi.csv"))
    write_text(os.path.join(a.out, "bench_mpi.json"), json.dumps(
        {"provenance": prov, "peers": versions, "summary": med.where(med.notna(), None).to_dict("records"),
         "samples": df.where(df.notna(), None).to_dict("records")}, indent=2) + "\n")

    md = ["# The mpi variant against fast and LAMMPS (scripts/run_mpi_bench.sh)", "",
          f"Suite: {results.provenance_line(prov)}. MPI: {versions.get('mpi', '?')}; LAMMPS package {versions.get('lammps_package') or 'absent'}.",
          "Median µs per particle-step over the interleaved repetitions (min–max), the settled dense bed.", "",
          "| N | " + " | ".join(CONFIGS) + " |", "|---|" + "---|" * len(CONFIGS)]
    checks = []
    for n, g in med.groupby("N"):
        m = dict(zip(g["config"], g["median"]))
        cells = [f"{m[c]:.4f} ({g[g.config == c]['min'].iloc[0]:.4f}–{g[g.config == c]['max'].iloc[0]:.4f})" if c in m else "–"
                 for c in CONFIGS]
        md.append(f"| {n} | " + " | ".join(cells) + " |")
        if "mpi R=1" in m and "mpi R=2" in m:
            s = m["mpi R=1"] / m["mpi R=2"]
            checks.append(f"- N = {n}: R = 2 is {s:.2f}× R = 1 (target at N ≥ 10⁵: at least 1.7×): {verdict(s >= 1.7)}")
        if "mpi R=2" in m and "fast 2 threads" in m:
            d = m["mpi R=2"] / m["fast 2 threads"] - 1.0
            checks.append(f"- N = {n}: R = 2 takes {100 * d:+.1f} % of the time of fast on 2 threads (target: within 15 %): "
                          f"{verdict(d <= 0.15)}")
        if "mpi R=2" in m and "lammps np=2" in m:
            q = m["lammps np=2"] / m["mpi R=2"]
            checks.append(f"- N = {n}: R = 2 is {q:.2f}× LAMMPS mpirun -np 2 (target: faster): {verdict(q > 1.0)}")
    md += ["", "Targets (docs/scaling.md):", ""] + checks
    write_text(os.path.join(a.out, "bench_mpi.md"), "\n".join(md) + "\n")

    h = halo(a.work)
    if not h.empty:
        h.to_csv(os.path.join(a.out, "halo_mpi.csv.tmp"), index=False)
        os.replace(os.path.join(a.out, "halo_mpi.csv.tmp"), os.path.join(a.out, "halo_mpi.csv"))
        lines = ["# Halo traffic of the mpi variant per step per rank (scripts/run_mpi_bench.sh)", "",
                 f"Suite: {results.provenance_line(prov)}. The dense bed's lattice on the grid of bricks the planner chose "
                 "(the least cut area); messages and bytes sent per step per rank (ghosts and migrants), mean and max over the ranks.", "",
                 "| N | R | grid | particles per rank (mean, max) | ghosts per rank (mean, max) | messages per step (mean, max) | bytes per step (mean, max) |",
                 "|---|---|---|---|---|---|---|"]
        for _, r in h.iterrows():
            lines.append(f"| {r.N} | {r.R} | {r.grid} | {r.particles_mean:.0f}, {r.particles_max:.0f} | {r.ghosts_mean:.0f}, {r.ghosts_max:.0f} | "
                         f"{r.messages_per_step_mean:.2f}, {r.messages_per_step_max:.2f} | {r.bytes_per_step_mean:.0f}, {r.bytes_per_step_max:.0f} |")
        write_text(os.path.join(a.out, "halo_mpi.md"), "\n".join(lines) + "\n")

    im = imbalance(a.work)
    if not im.empty:
        im.to_csv(os.path.join(a.out, "imbalance_mpi.csv.tmp"), index=False)
        os.replace(os.path.join(a.out, "imbalance_mpi.csv.tmp"), os.path.join(a.out, "imbalance_mpi.csv"))
        lines = ["# Imbalance of the static bricks (scripts/run_mpi_bench.sh)", "",
                 f"Suite: {results.provenance_line(prov)}. Particles per rank over their mean after the run (max, min), and "
                 "the most any rank held during it over the mean; bricks cut at init along each axis by count (quantiles) or evenly.", "",
                 "| N | stage | cut | R | grid | steps | max/mean | min/mean | most held/mean |", "|---|---|---|---|---|---|---|---|---|"]
        for _, r in im.iterrows():
            lines.append(f"| {r.N} | {r.stage} | {r.balance} | {r.R} | {r.grid} | {r.steps} | {r.max_over_mean:.3f} | {r.min_over_mean:.3f} | "
                         f"{r.most_held_over_mean:.3f} |")
        write_text(os.path.join(a.out, "imbalance_mpi.md"), "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
