#!/usr/bin/python3
"""The suite's figures and tables from one `demmat_bench` JSON file (Google Benchmark output).

Reads each benchmark's label, a JSON object written by bench/bench_suite.cpp (family, variant, state,
particles, threads, cell size), and its counters; nothing is parsed out of benchmark names. Medians and
min–max over the repetitions (which ran randomly interleaved).

Writes into --out (tables, CSV + Markdown) and --figures (PNG):
  figure4         time for 10⁴ cycles against N: cells of 2·Rmax, 4·Rmax, all pairs, with fitted
                  a·N² + b·N + c curves and the paper's fits
  cellsize        time per step against the cell edge / Rmax at each N
  scaling         µs per particle-step against N per variant (loose, settled, compression) + memory
  where           where the time goes for the fastest variant: integrator phases against the bandwidth
                  bound (STREAM measured in the same run), cost per contact and per candidate pair
  callgrind       instructions per particle-step and phase, when --callgrind JSON files are given

Usage: /usr/bin/python3 analysis/plot_figures.py BENCH.json --out DIR --figures DIR [--suffix S]
       [--callgrind CG.json ...] [--paper PAPER.json]
"""
import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from atomic_io import atomic_write, write_text  # noqa: E402
from results import (PAPER_JSON, PHASES, footer, legend_outside, load, load_paper, n_axis, remove_stale, save_figure, spread, style,  # noqa: E402
                     variant_key, wide)

# Compulsory memory traffic of the 5th-order Gear scheme with rotation, per particle and step, in
# doubles (physics.md §3): a step must read the six Gear values of each degree of freedom and the new
# acceleration and write the six back; three components, translation and rotation. A corrector pass and
# a predictor pass of their own move more, each reading the six values again (predictor: reads 6,
# writes 5; corrector: reads 7, writes 6: 1152 B); a variant that fuses the corrector into the next
# step's predictor (fast) moves the minimum, and its driver-timed predictor holds both (fast's also the
# other per-particle work of its one pass). The bound is therefore set for the two phases together,
# whichever of them a variant does the work in.
GEAR_DOUBLES = (7 + 6) * 3 * 2
GEAR_SEPARATE_DOUBLES = {"predict": (6 + 5) * 3 * 2, "correct": (7 + 6) * 3 * 2}


def read(path):
    """The benchmarks, one row per repetition (phases as <phase>_s columns), and the run's provenance."""
    res = load(path)
    return wide(res.table).rename(columns={"N": "particles"}), res.provenance


def caption(prov, *extra):
    return footer(prov, f"{prov.get('sweep', '')} sweep", *extra)


def single_n(m, name, figs, suffix):
    """A curve against N needs more than one N: with one, the table says it all and no figure is drawn
    (a stale one from other data is removed)."""
    if m.particles.nunique() > 1:
        return False
    path = os.path.join(figs, f"{name}_{suffix}.png")
    if remove_stale(path):
        print(f"plot_figures.py: one N only: removed {path}; the table has the numbers", file=sys.stderr)
    return True


# ---- Figure 4 ----------------------------------------------------------------------------------------

def fit_quadratic(n, t):
    """t ≈ a·N² + b·N + c by least squares on relative error (weights 1/t), like the paper's fits."""
    return np.polyfit(np.asarray(n, float), np.asarray(t, float), 2, w=1.0 / np.asarray(t, float))


def figure4(df, prov, paper, out, figs, suffix):
    d = df[df.family == "figure4"]
    if d.empty:
        return ""
    m = spread(d, ["search", "particles"], ["total_s", "search_s"])
    m["t_1e4_cycles_s"] = m["total_s"] * 1e4
    m["t_1e4_min"], m["t_1e4_max"] = m["total_s_min"] * 1e4, m["total_s_max"] * 1e4
    names = {"cells_2rmax": "cells 2·Rmax", "cells_4rmax": "cells 4·Rmax", "all_pairs": "no cells (all pairs)"}
    fits = {}
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for s, colour in zip(["cells_2rmax", "cells_4rmax", "all_pairs"], ["C0", "C1", "C3"]):
        sub = m[m.search == s].sort_values("particles")
        if sub.empty:
            continue
        ax.errorbar(sub.particles, sub.t_1e4_cycles_s, yerr=[sub.t_1e4_cycles_s - sub.t_1e4_min, sub.t_1e4_max - sub.t_1e4_cycles_s],
                    fmt="o", color=colour, label=f"{names[s]} (this run)", ms=4, capsize=2)
        if len(sub) >= 3:
            fits[s] = fit_quadratic(sub.particles, sub.t_1e4_cycles_s)
            grid = np.geomspace(sub.particles.min(), sub.particles.max(), 200)
            ax.plot(grid, np.polyval(fits[s], grid), "-", color=colour, lw=1)
    fp = paper.get("figure4", {}) if paper else {}
    nmax = m.particles.max()
    grid = np.geomspace(100, min(nmax, 10000), 100)
    for key, colour, lab in [("fit_no_cells", "C3", "paper fit, no cells"), ("fit_cells_4Rmax", "C1", "paper fit, cells 4·Rmax")]:
        if key in fp:
            ax.plot(grid, np.polyval(fp[key], grid), "--", color=colour, lw=1, alpha=0.7, label=f"{lab} (2.4 GHz Athlon, 2005)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles N")
    ax.set_ylabel("CPU time for 10⁴ cycles (s)")
    ax.set_title("Figure 4: contact search with and without cells (the paper's 2 m box)", fontsize=10)
    ax.grid(which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    save_figure(fig, os.path.join(figs, f"figure4_{suffix}.png"), caption(prov, "arrays variant, 1 thread; time per step × 10⁴"))

    atomic_write(os.path.join(out, "figure4.csv"), lambda tmp: m.to_csv(tmp, index=False, float_format="%.6g"))
    lines = ["| N | cells 2·Rmax (s) | cells 4·Rmax (s) | no cells (s) | no cells / 2·Rmax | no cells / 4·Rmax |", "|---|---|---|---|---|---|"]
    piv = m.pivot(index="particles", columns="search", values="t_1e4_cycles_s")
    for n, r in piv.iterrows():
        g2 = r.get("all_pairs", np.nan) / r.get("cells_2rmax", np.nan)
        g4 = r.get("all_pairs", np.nan) / r.get("cells_4rmax", np.nan)
        lines.append(f"| {n} | {r.get('cells_2rmax', np.nan):.3g} | {r.get('cells_4rmax', np.nan):.3g} | {r.get('all_pairs', np.nan):.3g} | {g2:.2f} | {g4:.2f} |")
    text = "CPU time for 10⁴ cycles (median; time per step × 10⁴). " + caption(prov) + "\n\n" + "\n".join(lines) + "\n"
    if fits:
        text += "\nFitted a·N² + b·N + c (seconds for 10⁴ cycles; weights 1/t):\n\n| search | a | b | c | paper |\n|---|---|---|---|---|\n"
        paper_fit = {"all_pairs": fp.get("fit_no_cells"), "cells_4rmax": fp.get("fit_cells_4Rmax"), "cells_2rmax": None}
        for s, c in fits.items():
            pf = paper_fit.get(s)
            ptxt = f"{pf[0]:g}·N² + {pf[1]:g}·N + {pf[2]:g}" if pf else "linear (stated, no fit given)"
            text += f"| {names[s]} | {c[0]:.3g} | {c[1]:.3g} | {c[2]:.3g} | {ptxt} |\n"
        if "all_pairs" in fits and "cells_2rmax" in fits:
            lo, hi = float(m.particles.min()), float(m.particles.max())
            ng = np.geomspace(lo, hi, 4000)
            wins = ng[np.polyval(fits["cells_2rmax"], ng) < np.polyval(fits["all_pairs"], ng)]
            if len(wins) and wins[0] > lo:
                text += f"\nCells of 2·Rmax win beyond N ≈ {wins[0]:.0f} on the fitted curves (the paper: about the same time up to N ≈ 200).\n"
            elif len(wins):
                text += (f"\nCells of 2·Rmax win at every N measured, from N = {lo:.0f} (where they take "
                         f"{piv.iloc[0].get('cells_2rmax', np.nan) / piv.iloc[0].get('all_pairs', np.nan):.2f}× the time of no cells; "
                         "the paper: about the same time up to N ≈ 200).\n")
        if 1000 in piv.index and "all_pairs" in piv.columns:
            text += (f"At N = 1000 no cells take {piv.loc[1000, 'all_pairs'] / piv.loc[1000, 'cells_2rmax']:.1f}× the time of cells of 2·Rmax "
                     f"(the paper: {fp.get('claims', {}).get('N_1000_gain_2Rmax_over_no_cells', '?')}×).\n")
    write_text(os.path.join(out, "figure4.md"), text)
    return text


# ---- cell-size sweep -----------------------------------------------------------------------------------

def cellsize(df, prov, out, figs, suffix):
    d = df[df.family == "cellsize"]
    if d.empty:
        return ""
    m = spread(d, ["variant", "particles", "cell_size_rmax"], ["total_s", "search_s", "forces_s", "candidates_per_particle"])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    sizes = sorted(m.particles.unique())
    for (v, n), sub in m.groupby(["variant", "particles"]):
        sub = sub.sort_values("cell_size_rmax")
        kw = style(v)
        kw["linestyle"] = ["-", "--", ":", "-."][sizes.index(n) % 4]  # the variant's colour, a line per N
        axes[0].plot(sub.cell_size_rmax, sub.total_s / n * 1e6, label=f"{v}, N = {n}", **kw)
        axes[1].plot(sub.cell_size_rmax, sub.candidates_per_particle, label=f"{v}, N = {n}", **kw)
    axes[0].set_ylabel("µs per particle-step")
    axes[1].set_ylabel("candidate pairs per particle")
    for ax in axes:
        ax.set_xlabel("cell edge / Rmax")
        ax.grid(alpha=0.3)
    legend_outside(axes[1])
    axes[0].set_title("Time per step against cell size (settled bed)", fontsize=10)
    axes[1].set_title("Candidates the search keeps", fontsize=10)
    save_figure(fig, os.path.join(figs, f"cellsize_{suffix}.png"), caption(prov, "1 thread"))
    atomic_write(os.path.join(out, "cellsize.csv"), lambda tmp: m.to_csv(tmp, index=False, float_format="%.6g"))
    lines = ["| variant | N | best cell edge / Rmax | µs/particle-step at best | at 2·Rmax | at 4·Rmax |", "|---|---|---|---|---|---|"]
    for (v, n), sub in m.groupby(["variant", "particles"]):
        us = (sub.set_index("cell_size_rmax").total_s / n * 1e6)
        best = us.idxmin()
        lines.append(f"| {v} | {n} | {best:g} | {us[best]:.3f} | {us.get(2.0, np.nan):.3f} | {us.get(4.0, np.nan):.3f} |")
    text = "Cell-size sweep (median). " + caption(prov) + "\n\n" + "\n".join(lines) + "\n"
    write_text(os.path.join(out, "cellsize.md"), text)
    return text


# ---- scaling and memory --------------------------------------------------------------------------------

def scaling(df, prov, out, figs, suffix):
    d = df[df.family == "phases"].copy()
    if d.empty:
        return ""
    d["threads"] = d["threads"].astype(int)
    d["series"] = d.apply(lambda r: r.variant + (f" ×{r.threads} threads" if r.threads > 1 else ""), axis=1)
    cols = ["us_per_particle_step", "predict_s", "search_s", "forces_s", "correct_s", "total_s", "contacts_per_particle",
            "candidates_per_particle", "memory_bytes_per_particle", "forces_ns_per_contact", "forces_ns_per_candidate",
            "search_ns_per_candidate"]
    m = spread(d, ["state", "series", "variant", "threads", "particles"], cols)
    atomic_write(os.path.join(out, "phases.csv"), lambda tmp: m.to_csv(tmp, index=False, float_format="%.6g"))
    if not single_n(m, "scaling", figs, suffix):
        scaling_figure(m, prov, figs, suffix)
    lines = ["| state | variant | threads | N | µs/particle-step | predict | search | forces | correct | contacts/particle | bytes/particle |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in m.sort_values(["state", "particles", "us_per_particle_step"]).iterrows():
        t = r.total_s
        lines.append(f"| {r.state} | {r.variant} | {r.threads} | {r.particles} | {r.us_per_particle_step:.3f} | "
                     f"{100 * r.predict_s / t:.0f} % | {100 * r.search_s / t:.0f} % | {100 * r.forces_s / t:.0f} % | {100 * r.correct_s / t:.0f} % | "
                     f"{r.contacts_per_particle:.2f} | {r.memory_bytes_per_particle:.0f} |")
    text = "Per-phase cost against N (median over interleaved repetitions; phases as % of the step). " + caption(prov) + "\n\n" + "\n".join(lines) + "\n"
    write_text(os.path.join(out, "scaling.md"), text)
    return text


def scaling_figure(m, prov, figs, suffix):
    states = [s for s in ["loose", "settled", "compression"] if s in set(m.state)]
    fig, axes = plt.subplots(1, len(states), figsize=(4.2 * len(states), 4.2), sharey=True, squeeze=False)
    for ax, s in zip(axes[0], states):
        for (variant, threads), sub in m[m.state == s].groupby(["variant", "threads"], sort=False):
            sub = sub.sort_values("particles")
            ax.errorbar(sub.particles, sub.us_per_particle_step,
                        yerr=[sub.us_per_particle_step - sub.us_per_particle_step_min, sub.us_per_particle_step_max - sub.us_per_particle_step],
                        lw=1, capsize=2, label=variant + (f" ×{threads} threads" if threads > 1 else ""), **style(variant, threads))
        n_axis(ax, m.particles)
        ax.set_yscale("log")
        ax.set_title(f"{s}", fontsize=10)
        ax.grid(which="both", alpha=0.3)
    axes[0][0].set_ylabel("µs per particle-step (median, min–max)")
    handles, labels = axes[0][0].get_legend_handles_labels()
    order = sorted(range(len(labels)), key=lambda k: variant_key(labels[k]))
    legend_outside(axes[0][-1], [handles[k] for k in order], [labels[k] for k in order])
    fig.suptitle("Scaling: cost per particle-step against N", fontsize=11)
    save_figure(fig, os.path.join(figs, f"scaling_{suffix}.png"), caption(prov))


# ---- where the time goes -------------------------------------------------------------------------------

def where(df, prov, callgrind, out, figs, suffix):
    ph = df[df.family == "phases"]
    st = df[df.family == "stream"]
    if ph.empty:
        return ""
    bw = {}
    if not st.empty:
        s = spread(st, ["kernel", "threads"], ["bandwidth_GBps"])
        for t, sub in s.groupby("threads"):
            bw[int(t)] = sub.set_index("kernel").bandwidth_GBps
        atomic_write(os.path.join(out, "stream.csv"), lambda tmp: s.to_csv(tmp, index=False, float_format="%.6g"))
    cols = ["predict_s", "correct_s", "search_s", "forces_s", "total_s", "forces_ns_per_contact", "forces_ns_per_candidate",
            "search_ns_per_candidate", "contacts_per_particle", "candidates_per_particle"]
    # The settled bed where the run has it; otherwise what it has (a slice of the sweep, e.g. the 10⁶ loose grid).
    state = "settled" if "settled" in set(ph.state) else sorted(set(ph.state))[0]
    state_name = {"settled": "settled bed", "loose": "loose grid", "compression": "compression stage"}.get(state, state)
    m = spread(ph[ph.state == state], ["variant", "threads", "particles"], cols)
    bitwise = ph.groupby("variant")["bitwise"].first() if "bitwise" in ph else None
    # The fastest bit-identical variant at the largest N, one thread.
    one = m[(m.threads == 1)]
    if bitwise is not None:
        one = one[one.variant.map(lambda v: bool(bitwise.get(v, True)))]
    nmax = one.particles.max()
    fastest = one[one.particles == nmax].sort_values("total_s").iloc[0].variant
    lines = [f"Where the time goes: **{fastest}** (the fastest bit-identical variant at N = {nmax}, one thread), {state_name}. "
             + caption(prov), "",
             "| N | threads | phase | ns per particle-step | bound from bandwidth (ns) | measured / bound | ns per contact | ns per candidate pair |",
             "|---|---|---|---|---|---|---|---|"]
    for _, r in m[m.variant == fastest].sort_values(["particles", "threads"]).iterrows():
        n, t = r.particles, int(r.threads)
        best_bw = bw.get(t, pd.Series(dtype=float)).max() if t in bw else np.nan
        for p in PHASES:
            ns = r[f"{p}_s"] / n * 1e9
            if p == "forces":
                # Per contact only where there are contacts to speak of (a loose grid has almost none).
                per_contact = f"{r.forces_ns_per_contact:.1f}" if r.contacts_per_particle >= 0.1 else ""
                lines.append(f"| {n} | {t} | {p} | {ns:.1f} | | | {per_contact} | {r.forces_ns_per_candidate:.1f} |")
            elif p == "search":
                lines.append(f"| {n} | {t} | {p} | {ns:.1f} | | | | {r.search_ns_per_candidate:.1f} |")
            else:
                lines.append(f"| {n} | {t} | {p} | {ns:.1f} | | | | |")
        gear_ns = (r.predict_s + r.correct_s) / n * 1e9
        if best_bw == best_bw:
            bound = GEAR_DOUBLES * 8 / (best_bw * 1e9) * 1e9
            lines.append(f"| {n} | {t} | predict + correct | {gear_ns:.1f} | {bound:.1f} | {gear_ns / bound:.2f} | | |")
    if bw:
        lines += ["", "Memory bandwidth measured in the same run (STREAM kernels, 2²⁴ doubles per array, GB/s, median):", "",
                  "| threads | " + " | ".join(bw[min(bw)].index) + " |", "|---|" + "---|" * len(bw[min(bw)])]
        for t, s in sorted(bw.items()):
            lines.append(f"| {t} | " + " | ".join(f"{v:.1f}" for v in s.values) + " |")
        lines += ["", f"Bound = compulsory bytes of a step of the 5th-order Gear scheme with rotation ({GEAR_DOUBLES * 8} B per "
                  "particle: the six values of each degree of freedom and the new acceleration read, the six written) / the best "
                  "STREAM bandwidth at that thread count, for predictor and corrector together: a variant that runs them as "
                  f"separate passes moves {sum(GEAR_SEPARATE_DOUBLES.values()) * 8} B (predict {GEAR_SEPARATE_DOUBLES['predict'] * 8}, "
                  f"correct {GEAR_SEPARATE_DOUBLES['correct'] * 8}); fast runs its corrector fused into the next step's predictor, "
                  "so its predict holds both, and with them Newton's law, the displacement check, the kernel's records and the "
                  "wall candidates (docs/variants/engine.md). Below the bound means the arrays still sat in cache (small N)."]
    if callgrind:
        lines += ["", "Instructions per particle-step (valgrind --tool=callgrind, repeatable whatever the machine's load):", "",
                  "| variant | scene | N | steps | predict | search | forces | correct | total | contacts/particle |", "|---|---|---|---|---|---|---|---|---|---|"]
        for cg in callgrind:
            ip = cg["instructions_per_particle_step"]
            lines.append(f"| {cg['variant']} | {cg['scene']} | {cg['particles']} | {cg['steps']} | " + " | ".join(f"{ip.get(p, float('nan')):.0f}" for p in PHASES)
                         + f" | {sum(ip.get(p, 0) for p in PHASES):.0f} | {cg.get('contacts_per_particle', float('nan')):.2f} |")
    text = "\n".join(lines) + "\n"
    write_text(os.path.join(out, "where_the_time_goes.md"), text)

    if not single_n(m[m.variant == fastest], "where", figs, suffix):
        where_figure(m[m.variant == fastest].sort_values("particles"), fastest, state_name, bw, prov, figs, suffix)
    return text


def where_figure(sub, fastest, state_name, bw, prov, figs, suffix):
    """Per-phase ns per particle-step against N for the fastest variant, with the bandwidth bound."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, p in enumerate(PHASES):
        for t, s2 in sub.groupby("threads"):
            ax.plot(s2.particles, s2[f"{p}_s"] / s2.particles * 1e9, "o-" if t == 1 else "s--", color=f"C{k}", ms=3,
                    label=f"{p}" + (f" ({int(t)} threads)" if t > 1 else ""))
    k = len(PHASES)
    for t, s2 in sub.groupby("threads"):
        ax.plot(s2.particles, (s2.predict_s + s2.correct_s) / s2.particles * 1e9, "o-" if t == 1 else "s--", color=f"C{k}", ms=3,
                label="predict + correct" + (f" ({int(t)} threads)" if t > 1 else ""))
    if 1 in bw:
        ax.axhline(GEAR_DOUBLES * 8 / bw[1].max(), color=f"C{k}", lw=0.8, ls=":", label="predict + correct:\nbandwidth bound, 1 thread")
    n_axis(ax, sub.particles)
    ax.set_yscale("log")
    ax.set_ylabel("ns per particle-step")
    ax.set_title(f"Where the time goes: {fastest}, {state_name}", fontsize=10)
    ax.grid(which="both", alpha=0.3)
    legend_outside(ax)
    save_figure(fig, os.path.join(figs, f"where_{suffix}.png"), caption(prov))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bench", help="JSON written by demmat_bench --benchmark_out=... --benchmark_out_format=json")
    ap.add_argument("--out", required=True, help="folder for tables (CSV, Markdown)")
    ap.add_argument("--figures", required=True, help="folder for PNG figures")
    ap.add_argument("--suffix", default="short", help="suffix of the figure names (short, full)")
    ap.add_argument("--callgrind", nargs="*", default=[], help="JSON files written by scripts/callgrind_phases.sh")
    ap.add_argument("--paper", default=PAPER_JSON, help="the paper's figures (default: data/paper.json in the repository)")
    a = ap.parse_args(argv)
    df, prov = read(a.bench)
    paper = load_paper(a.paper)
    cg = [load(f).meta for f in a.callgrind]
    parts = [figure4(df, prov, paper, a.out, a.figures, a.suffix), cellsize(df, prov, a.out, a.figures, a.suffix),
             scaling(df, prov, a.out, a.figures, a.suffix), where(df, prov, cg, a.out, a.figures, a.suffix)]
    write_text(os.path.join(a.out, "provenance.json"), json.dumps(prov, indent=1) + "\n")
    print("\n\n".join(p for p in parts if p))


if __name__ == "__main__":
    main(sys.argv[1:])
