#!/usr/bin/python3
"""What each model feature costs per step, from demmat_bench_features' Google Benchmark JSON.

Reads the label of every repetition (a JSON object: variant, level, kernel, model, ...) and its counters
(seconds per step per phase, contacts per particle); nothing is parsed out of benchmark names. Writes:

- a Markdown table (and a CSV) per variant and level: the specialised model's median seconds per step,
  its cost against the normal-force-only level and against the level before, the full model's time on
  the same scene (the same trajectory bit for bit) and what specialisation saves, contacts per particle;
- a figure: per variant, the specialised model's phases stacked per level, the full model's total beside.

Usage: /usr/bin/python3 analysis/plot_features.py BENCH.json --figure OUT.png --markdown OUT.md [--table OUT.csv]
"""
import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from atomic_io import atomic_write, write_text  # noqa: E402
from results import PHASES, footer, load, save_figure, wide  # noqa: E402

# What a GPU study of this group's code measured over normal forces alone: history-dependent
# friction +38 %, torques +4 %. The table sets the suite's feature costs beside them.
GPU_STUDY = {"friction": 0.38, "torques": 0.04}


def samples(res):
    """One row per repetition of a features benchmark: its label's fields and the phases' seconds per step."""
    df = wide(res.table)
    df = df[df.get("family", pd.Series(dtype=str)) == "features"] if "family" in df else df.iloc[:0]
    if df.empty:
        sys.exit("plot_features.py: no features benchmarks in the file")
    df = df.rename(columns={f"{p}_s": p for p in PHASES + ["total"]})
    return df.reset_index(drop=True)


def table(df):
    keys = ["variant", "level", "level_name", "kernel"]
    med = df.groupby(keys).agg(
        total=("total", "median"), total_min=("total", "min"), total_max=("total", "max"),
        forces=("forces", "median"), contacts=("contacts_per_particle", "median"), model=("model", "first"),
        repetitions=("repetition", "count"),
        **{p + "_med": (p, "median") for p in PHASES}).reset_index()
    spec = med[med.kernel == "specialised"].set_index(["variant", "level"])
    full = med[med.kernel == "full"].set_index(["variant", "level"])
    out = []
    for (variant, level), r in spec.sort_index().iterrows():
        base = spec.loc[(variant, 0), "total"]
        base_forces = spec.loc[(variant, 0), "forces"]
        prev = spec.loc[(variant, level - 1), "total"] if level > 0 else float("nan")
        f = full.loc[(variant, level)]
        out.append({
            "variant": variant, "level": level, "feature": r.level_name, "model": r.model,
            "specialised_ms": r.total * 1e3, "spec_min_ms": r.total_min * 1e3, "spec_max_ms": r.total_max * 1e3,
            "forces_ms": r.forces * 1e3, "forces_vs_normal": r.forces / base_forces - 1.0,
            "vs_normal": r.total / base - 1.0, "vs_previous": r.total / prev - 1.0 if level > 0 else float("nan"),
            "full_ms": f.total * 1e3, "full_over_specialised": f.total / r.total - 1.0,
            "contacts_per_particle": r.contacts, "repetitions": int(r.repetitions),
            **{p + "_ms": r[p + "_med"] * 1e3 for p in PHASES},
        })
    return pd.DataFrame(out)


def pct(x):
    return "" if pd.isna(x) else f"{x * 100:+.1f} %"


def markdown(t, prov):
    lines = [
        "# What each model feature costs per step",
        "",
        f"Produced by scripts/run_features.sh (bench/bench_features.cpp, analysis/plot_features.py) on "
        f"{prov.get('cpu', '?')}, {prov.get('compiler', '?')} {prov.get('flags', '')}, "
        f"commit {prov.get('commit', '?')}{' (dirty)' if prov.get('dirty') else ''}, {prov.get('date', '?')}.",
        "",
        "A monodisperse dense bed settled for "
        f"{prov.get('settle_time_s', '?')} s; each level's scene needs one feature more than the one above. "
        "*specialised*: the model the variant picks for the scene; *full*: the paper's full model on the same "
        "scene (the same trajectory, bit for bit). Times are medians over the interleaved repetitions of "
        "milliseconds per step (min–max in brackets). *vs normal*: the whole step against the normal-force-only "
        "level; *vs previous*: the feature's own cost; *forces vs normal*: the forces phase alone (contact "
        "law, summation, Newton) against normal-only, the part a GPU force kernel measures; *full / spec.*: what the general kernel costs a scene that "
        "does not need its features. The polydisperse level runs the per-contact R\\*, m\\* kernel on the "
        "same monodisperse bed (inert, so the trajectory is the moving-walls level's): its cost is that work alone.",
        "",
    ]
    for variant, g in t.groupby("variant", sort=False):
        lines += [f"## {variant}", "",
                  "| level | model picked | ms/step (spec.) | vs normal | vs previous | forces phase ms | forces vs normal | ms/step (full) | full / spec. | contacts/particle |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for _, r in g.iterrows():
            lines.append(
                f"| {r.level} {r.feature} | {r.model} | {r.specialised_ms:.3f} ({r.spec_min_ms:.3f}–{r.spec_max_ms:.3f}) | "
                f"{pct(r.vs_normal)} | {pct(r.vs_previous)} | {r.forces_ms:.3f} | {pct(r.forces_vs_normal)} | {r.full_ms:.3f} | "
                f"{pct(r.full_over_specialised)} | {r.contacts_per_particle:.2f} |")
        lines.append("")
    lines += [
        "For comparison, a GPU study of this group's code (its figures in analysis/plot_features.py, GPU_STUDY): over normal forces alone, "
        f"history-dependent friction {pct(GPU_STUDY['friction'])} and torques {pct(GPU_STUDY['torques'])}. "
        "Here friction has no history (viscous-regularised Coulomb, physics.md §2) and comes with rotation "
        "(torques and the rotational Gear state) in one level, since the model set instantiates them together.",
        "",
    ]
    return "\n".join(lines)


def figure(t, prov, path):
    variants = list(dict.fromkeys(t.variant))
    fig, axes = plt.subplots(1, len(variants), figsize=(6.5 * len(variants), 4.8), squeeze=False, sharey=True)
    colours = {"predict": "#4c72b0", "search": "#dd8452", "forces": "#c44e52", "correct": "#55a868"}
    for ax, variant in zip(axes[0], variants):
        g = t[t.variant == variant].sort_values("level")
        x = range(len(g))
        bottom = [0.0] * len(g)
        for p in PHASES:
            vals = list(g[p + "_ms"])
            ax.bar(x, vals, 0.6, bottom=bottom, color=colours[p], label=p if variant == variants[0] else None)
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.scatter(list(x), list(g.full_ms), marker="_", s=600, color="black", zorder=3,
                   label="full model, same scene" if variant == variants[0] else None)
        for xi, (tot, full, vs) in enumerate(zip(g.specialised_ms, g.full_ms, g.vs_normal)):
            if xi:  # above the bar and the full model's marker
                ax.annotate(pct(vs), (xi, max(tot, full)), textcoords="offset points", xytext=(0, 5), ha="center", fontsize=8)
        labels = ["normal\nonly"] + ["+ " + f.replace("_", " ") for f in list(g.feature)[1:]]
        ax.set_xticks(list(x))
        ax.set_xticklabels(labels, fontsize=8)
        ax.set_title(f"{variant}: specialised model per scene")
        ax.grid(axis="y", alpha=0.3)
    axes[0][0].set_ylabel("ms per step (median; phases of the specialised run)")
    fig.legend(loc="upper center", ncol=5, fontsize=8, bbox_to_anchor=(0.5, 1.0))
    n = int(t.attrs.get("N", 0))
    save_figure(fig, path, footer(prov, f"{n} grains, dense bed settled {prov.get('settle_time_s', '?')} s",
                                  f"median of {int(t.repetitions.max())} interleaved repetitions"), dpi=130, top=0.93)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bench")
    ap.add_argument("--figure", required=True)
    ap.add_argument("--markdown", required=True)
    ap.add_argument("--table")
    a = ap.parse_args()
    try:
        res = load(a.bench)
    except (OSError, ValueError) as e:
        sys.exit(f"plot_features.py: cannot read {a.bench}: {e}")
    df = samples(res)
    t = table(df)
    t.attrs["N"] = int(df["N"].max())
    text = markdown(t, res.provenance)
    write_text(a.markdown, text)
    if a.table:
        atomic_write(a.table, lambda tmp: t.to_csv(tmp, index=False, float_format="%.6g"))
    figure(t, res.provenance, a.figure)
    print(text)


if __name__ == "__main__":
    main()
