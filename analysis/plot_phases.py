#!/usr/bin/python3
"""Per-phase CPU time per variant from a `demmat bench` JSON file (the paper's Figure 7 layout).

Writes a grouped bar chart (log scale, median with min–max whiskers over the interleaved repetitions)
and a CSV table of seconds per step and of each variant's ratio to the arrays variant per phase.
Reads structured fields only; nothing is parsed out of labels.

Usage: /usr/bin/python3 analysis/plot_phases.py BENCH.json --figure OUT.png --table OUT.csv [--markdown OUT.md]
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from atomic_io import atomic_write, write_text  # noqa: E402
from results import PAPER_JSON, PHASES, bar_style, footer, legend_outside, load, load_paper, save_figure, wide  # noqa: E402

GROUPS = PHASES + ["search_plus_forces", "total"]


def series(variant, threads, multi):
    """A bar's name: the variant, and its thread count where the run timed several (`--threads 1,2`)."""
    return f"{variant} ×{threads}" if multi.get(variant, False) else variant


def several_counts(table):
    """variant -> whether the run timed it at more than one thread count."""
    return {v: t > 1 for v, t in table.groupby("variant")["threads"].nunique().items()}


def tidy_samples(table):
    """One row per (series, repetition, phase) with seconds per step (a series: a variant at a thread count)."""
    multi = several_counts(table)
    w = wide(table)
    w["variant"] = [series(v, t, multi) for v, t in zip(w["variant"], w["threads"])]
    w["search_plus_forces_s"] = w["search_s"] + w["forces_s"]
    tidy = w.melt(id_vars=["variant", "repetition"], value_vars=[g + "_s" for g in GROUPS], var_name="phase",
                  value_name="seconds_per_step")
    tidy["phase"] = tidy["phase"].str[:-2]
    return tidy


def table(tidy, order):
    stats = tidy.groupby(["variant", "phase"])["seconds_per_step"].agg(["median", "min", "max"]).reset_index()
    ref = stats[stats.variant == "arrays"].set_index("phase")["median"] if "arrays" in order else None
    if ref is not None:
        stats["ratio_to_arrays"] = stats.apply(lambda r: r["median"] / ref[r["phase"]], axis=1)
    stats["variant"] = pd.Categorical(stats["variant"], order)
    stats["phase"] = pd.Categorical(stats["phase"], GROUPS)
    return stats.sort_values(["variant", "phase"]).reset_index(drop=True)


def caption(res):
    s, m = res.meta["scene"], res.meta
    return (f"{s['name']}: {s['particles']} particles, {s['search']} {s['cell_size_rmax']:g}·Rmax, "
            f"{m['repetitions']} interleaved repetitions × {m['steps']} steps")


def figure(stats, order, res, path):
    phases = ["predict", "search", "forces", "correct", "total"]
    fig, ax = plt.subplots(figsize=(9, 4.8))
    width = 0.8 / max(1, len(order))
    for k, (name, variant, threads) in enumerate(order):
        sub = stats[stats.variant == name].set_index("phase").loc[phases]
        x = [i + (k - (len(order) - 1) / 2) * width for i in range(len(phases))]
        err = [sub["median"] - sub["min"], sub["max"] - sub["median"]]
        ax.bar(x, sub["median"], width, yerr=err, capsize=1.5, error_kw={"elinewidth": 0.8},
               label=name + (f" ({threads} threads)" if int(threads) > 1 and "×" not in name else ""), **bar_style(variant, threads))
    ax.set_yscale("log")
    ax.set_xticks(range(len(phases)))
    ax.set_xticklabels(phases)
    ax.set_ylabel("CPU time per step (s)")
    legend_outside(ax, fontsize=8)
    ax.grid(axis="y", which="both", alpha=0.3)
    ax.set_title("Per-phase CPU time per variant (median, min–max whiskers)", fontsize=10)
    save_figure(fig, path, footer(res.provenance, caption(res)))


def markdown(stats, order, res):
    """A Markdown table of µs per step (median) and the ratio to arrays, with the provenance line."""
    phases = ["predict", "search", "forces", "correct", "search_plus_forces", "total"]
    head = "| variant | " + " | ".join(p.replace("_", " ") for p in phases) + " | µs per particle-step |"
    lines = [head, "|" + "---|" * (len(phases) + 2)]
    n = res.meta["scene"]["particles"]
    for v in order:
        sub = stats[stats.variant == v].set_index("phase")
        cells = []
        for p in phases:
            med = sub.loc[p, "median"] * 1e6
            ratio = sub.loc[p, "ratio_to_arrays"] if "ratio_to_arrays" in sub else float("nan")
            cells.append(f"{med:.1f} ({ratio:.2f}×)")
        lines.append(f"| {v} | " + " | ".join(cells) + f" | {sub.loc['total', 'median'] / n * 1e6:.3f} |")
    return (f"Median µs per step (ratio to arrays). {caption(res)}. {footer(res.provenance)}\n\n" + "\n".join(lines) + "\n")


def paper_ratios(stats, paper_json):
    """The paper's Figure 7 ratios (its three codes) beside this run's, when f90, oop and pascal ran."""
    have = set(stats.variant.astype(str))
    paper = load_paper(paper_json).get("figure7_ratios_stated")
    if not {"f90", "oop"} <= have or not paper:
        return ""
    med = stats.assign(variant=stats.variant.astype(str), phase=stats.phase.astype(str)).set_index(["variant", "phase"])["median"]

    def fmt(v):
        return f"{v[0]:g}–{v[1]:g}" if isinstance(v, list) else f"{v:g}"

    rows = [("OOP C++ / F90, whole step", "CPP_over_F90_whole_step", "oop", "total"),
            ("OOP C++ / F90, predictor", "CPP_over_F90_predictor", "oop", "predict"),
            ("OOP C++ / F90, corrector", "CPP_over_F90_corrector", "oop", "correct"),
            ("OOP C++ / F90, search + forces", "CPP_over_F90_search_and_forces", "oop", "search_plus_forces"),
            ("Object Pascal / F90, whole step", "PAS_over_F90_whole_step", "pascal", "total")]
    lines = ["| ratio | paper (2005) | this run |", "|---|---|---|"]
    for label, key, v, ph in rows:
        if v in have:
            lines.append(f"| {label} | {fmt(paper[key])} | {med[(v, ph)] / med[('f90', ph)]:.2f} |")
    return "\n\nThe paper's three codes (its Figure 7) against today's compilers:\n\n" + "\n".join(lines) + "\n"


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bench", help="JSON written by `demmat bench --json`")
    ap.add_argument("--figure", required=True)
    ap.add_argument("--table", required=True)
    ap.add_argument("--markdown", help="also write the table as Markdown")
    ap.add_argument("--paper", default=PAPER_JSON, help="the paper's figures (default: data/paper.json in the repository)")
    a = ap.parse_args(argv)
    res = load(a.bench)
    stats, order = phase_stats(res)
    atomic_write(a.table, lambda tmp: stats.to_csv(tmp, index=False, float_format="%.6g"))
    figure(stats, order, res, a.figure)
    if a.markdown:
        text = markdown(stats, [name for name, _, _ in order], res) + paper_ratios(stats, a.paper)
        write_text(a.markdown, text)
    print(stats.to_string(index=False, float_format=lambda x: f"{x:.4g}"))


def phase_stats(res):
    """The per-phase table of a `demmat bench` result and its series in the run's order: (name, variant, threads)."""
    multi = several_counts(res.table)
    order = [(series(s["variant"], s.get("threads", 0), multi), s["variant"], s.get("threads", 0)) for s in res.meta["summary"]]
    return table(tidy_samples(res.table), [name for name, _, _ in order]), order


if __name__ == "__main__":
    main(sys.argv[1:])
