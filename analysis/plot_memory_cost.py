#!/usr/bin/python3
"""What contact memory costs each style: µs per particle-step and bytes per particle per variant × law ×
stage, from the `demmat bench` files (and `demmat_mpi bench` files: the mpi variant, its processes in the
threads column) that scripts/run_memory_cost.sh lists in its runs.tsv (law, stage,
round, file: the law and stage come from the manifest, never from a file or scene name).

µs per particle-step is the median over the rounds of each bench run's step time (the four phases
summed) over N, with the rounds' min and max; bytes per particle is Variant::memory_bytes over N, as the
variant reported it at the end of its timed steps (the median over the rounds). Each variant's cost of a
law is also given as its ratio to the same variant under the paper's law on the same stage.

Usage: /usr/bin/python3 analysis/plot_memory_cost.py RUNS.tsv --table OUT.md --csv OUT.csv --figure OUT.png
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from atomic_io import atomic_write, write_text  # noqa: E402
from results import VARIANT_ORDER, footer, legend_outside, load, provenance_line, save_figure, wide  # noqa: E402

LAWS = ["paper", "linear_history", "mindlin", "mindlin_sds"]
LAW_LABEL = {"paper": "paper's law", "linear_history": "linear_history", "mindlin": "mindlin", "mindlin_sds": "mindlin + sds"}
LAW_COLOUR = {"paper": "#7f7f7f", "linear_history": "#1f77b4", "mindlin": "#ff7f0e", "mindlin_sds": "#2ca02c"}
STAGES = ["settled", "compression"]


def samples(manifest):
    """One row per (law, stage, round, variant, threads): µs per particle-step, bytes per particle, contacts."""
    runs = pd.read_csv(manifest, sep="\t")
    folder = os.path.dirname(os.path.abspath(manifest))
    rows, provenance, meta = [], None, None
    for run in runs.itertuples():
        res = load(os.path.join(folder, run.file))
        provenance, meta = provenance or res.provenance, meta or res.meta
        n = res.meta["scene"]["particles"]
        if res.kind == "mpi":  # demmat_mpi bench --json: one configuration, its median step over the repetitions
            m = res.meta
            rows.append({"law": run.law, "stage": run.stage, "round": run.round, "variant": "mpi", "threads": int(m["processes"]),
                         "N": n, "us_per_particle_step": m["us_per_particle_step"], "bytes_per_particle": m["memory_bytes"] / n,
                         "contacts_per_particle": m["contacts_per_particle"], "model": m["model"]})
            continue
        w = wide(res.table)
        summary = {(s["variant"], s["threads_asked"]): s for s in res.meta["summary"]}
        for s in w.itertuples():
            info = summary[(s.variant, s.threads_asked)]
            rows.append({"law": run.law, "stage": run.stage, "round": run.round, "variant": s.variant, "threads": s.threads,
                         "N": n, "us_per_particle_step": s.total_s / n * 1e6, "bytes_per_particle": info["memory_bytes"] / n,
                         "contacts_per_particle": info["contacts_per_particle"], "model": info["model"]})
    if not rows:
        raise SystemExit(f"{manifest}: no bench runs listed")
    return pd.DataFrame(rows), provenance, meta


def summarise(df):
    """Medians over the rounds, with min and max of the time, and each law's ratio to the paper's law."""
    keys = ["stage", "law", "variant", "threads"]
    g = df.groupby(keys)
    out = g.agg(us_median=("us_per_particle_step", "median"), us_min=("us_per_particle_step", "min"),
                us_max=("us_per_particle_step", "max"), bytes_per_particle=("bytes_per_particle", "median"),
                contacts_per_particle=("contacts_per_particle", "median"), rounds=("round", "nunique"),
                model=("model", "first")).reset_index()
    paper = out[out.law == "paper"].set_index(["stage", "variant", "threads"])
    ref = out.set_index(["stage", "variant", "threads"]).index.map(lambda k: paper["us_median"].get(k, float("nan")))
    ref_b = out.set_index(["stage", "variant", "threads"]).index.map(lambda k: paper["bytes_per_particle"].get(k, float("nan")))
    out["time_ratio_to_paper"] = out["us_median"] / list(ref)
    out["bytes_ratio_to_paper"] = out["bytes_per_particle"] / list(ref_b)
    out["law"] = pd.Categorical(out["law"], LAWS)
    out["stage"] = pd.Categorical(out["stage"], STAGES)
    order = [v for v in VARIANT_ORDER if v in set(out.variant)] + sorted(set(out.variant) - set(VARIANT_ORDER))
    out["variant"] = pd.Categorical(out["variant"], order)
    return out.sort_values(["stage", "variant", "threads", "law"]).reset_index(drop=True)


def series_name(variant, threads):
    return f"{variant} ×{threads}" if int(threads) > 1 else str(variant)


def markdown(stats, provenance, meta):
    rounds = int(stats["rounds"].max())
    lines = [f"# What contact memory costs each style\n",
             f"The dense bed of {int(meta['scene']['particles'])} grains, settled under each law (walls at rest) and its "
             f"compression stage; {rounds} rounds of {meta['steps']} timed steps (after {meta['warmup_steps']} untimed), the "
             f"(law, stage) order rotated each round and the variants interleaved within each run (scripts/run_memory_cost.sh). "
             f"µs per particle-step: median over the rounds (min–max), and in brackets the ratio to the same variant under the "
             f"paper's law; bytes per particle: what the variant holds (Variant::memory_bytes), with its ratio. A variant "
             f"missing from a law's column does not implement it.\n", f"{provenance_line(provenance)}\n"]
    for stage in STAGES:
        sub = stats[stats.stage == stage]
        if sub.empty:
            continue
        laws = [l for l in LAWS if l in set(sub.law.astype(str))]
        for what, title in (("time", "µs per particle-step"), ("bytes", "bytes per particle")):
            lines.append(f"\n## {stage}: {title}\n")
            lines.append("| variant | " + " | ".join(LAW_LABEL[l] for l in laws) + " | contacts per particle |")
            lines.append("|" + "---|" * (len(laws) + 2))
            for (v, t), grp in sub.groupby(["variant", "threads"], observed=True):
                by_law = grp.set_index(grp.law.astype(str))
                cells = []
                for l in laws:
                    if l not in by_law.index:
                        cells.append("—")
                    elif what == "time":
                        r = by_law.loc[l]
                        cells.append(f"{r.us_median:.3f} ({r.us_min:.3f}–{r.us_max:.3f}) [{r.time_ratio_to_paper:.2f}×]")
                    else:
                        r = by_law.loc[l]
                        cells.append(f"{r.bytes_per_particle:.0f} [{r.bytes_ratio_to_paper:.2f}×]")
                contacts = by_law["contacts_per_particle"].median()
                lines.append(f"| {series_name(v, t)} | " + " | ".join(cells) + f" | {contacts:.2f} |")
    return "\n".join(lines) + "\n"


def figure(stats, provenance, path):
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex="col")
    for row, stage in enumerate(STAGES):
        sub = stats[stats.stage == stage]
        names = [series_name(v, t) for (v, t), _ in sub.groupby(["variant", "threads"], observed=True)]
        for col, (value, label) in enumerate((("us_median", "µs per particle-step"), ("bytes_per_particle", "bytes per particle"))):
            ax = axes[row][col]
            width = 0.8 / len(LAWS)
            for k, law in enumerate(LAWS):
                part = sub[sub.law == law]
                x, y, lo, hi = [], [], [], []
                for i, ((v, t), grp) in enumerate(sub.groupby(["variant", "threads"], observed=True)):
                    r = part[(part.variant == v) & (part.threads == t)]
                    if r.empty:
                        continue
                    x.append(i + (k - (len(LAWS) - 1) / 2) * width)
                    y.append(float(r[value].iloc[0]))
                    if value == "us_median":
                        lo.append(y[-1] - float(r.us_min.iloc[0]))
                        hi.append(float(r.us_max.iloc[0]) - y[-1])
                err = [lo, hi] if value == "us_median" else None
                ax.bar(x, y, width, yerr=err, capsize=1.2, error_kw={"elinewidth": 0.7}, color=LAW_COLOUR[law],
                       label=LAW_LABEL[law] if row == 0 and col == 1 else None)
            ax.set_xticks(range(len(names)))
            ax.set_xticklabels(names, rotation=30, ha="right", fontsize=7)
            ax.set_yscale("log")
            ax.set_ylabel(label, fontsize=8)
            ax.set_title(f"{stage}: {label}", fontsize=9)
            ax.grid(axis="y", which="both", alpha=0.3)
    legend_outside(axes[0][1], fontsize=8)
    save_figure(fig, path, footer(provenance, "median over the rounds, min–max whiskers (scripts/run_memory_cost.sh)"))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("manifest", help="runs.tsv written by scripts/run_memory_cost.sh")
    ap.add_argument("--table", required=True, help="Markdown table")
    ap.add_argument("--csv", required=True, help="the same numbers as CSV")
    ap.add_argument("--figure", required=True)
    a = ap.parse_args(argv)
    df, provenance, meta = samples(a.manifest)
    stats = summarise(df)
    atomic_write(a.csv, lambda tmp: stats.to_csv(tmp, index=False, float_format="%.6g"))
    write_text(a.table, markdown(stats, provenance, meta))
    figure(stats, provenance, a.figure)
    print(stats[["stage", "law", "variant", "threads", "us_median", "bytes_per_particle", "time_ratio_to_paper"]]
          .to_string(index=False, float_format=lambda x: f"{x:.4g}"))


if __name__ == "__main__":
    main(sys.argv[1:])
