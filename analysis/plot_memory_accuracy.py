#!/usr/bin/python3
"""Work against precision of the contact laws with memory (docs/accuracy.md, "Laws with memory").

Reads memory_accuracy.csv and .json of demmat_memory_accuracy; writes
  FIGURES/memory_work_precision.png   error against CPU time, a panel per test x law, a line per integrator
                                       (colour) and stretch update (solid trapezoidal, dashed first_order)
  FIGURES/memory_error_vs_dt.png      the same errors against dt/t_c, with the fitted order of each line
  TABLE (memory_recommendation.md)    for each target error, the cheapest law update / integrator / dt

Usage: /usr/bin/python3 analysis/plot_memory_accuracy.py DIR/memory_accuracy.json [--figures DIR] [--table FILE]
"""
import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from atomic_io import write_text  # noqa: E402
from results import footer, legend_outside, provenance_line, save_figure  # noqa: E402

LAWS = ["paper", "linear_history", "mindlin", "mindlin_sds", "mindlin_tsuji"]
LAW_LABEL = {"paper": "paper", "linear_history": "linear_history", "mindlin": "mindlin", "mindlin_sds": "mindlin + sds",
             "mindlin_tsuji": "mindlin, tsuji damping"}
SCHEMES = ["gear5", "gear3", "verlet", "symplectic_euler"]
COLOUR = {"gear5": "#1f77b4", "gear3": "#2ca02c", "verlet": "#d62728", "symplectic_euler": "#9467bd"}
DASH = {"trapezoidal": "-", "first_order": "--", "none": "-"}
TESTS = {4: "test 4 (sphere onto a plane, 5–85°)", 8: "test 8 (spinning sphere onto a sphere)"}
TARGETS = [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4]


def fitted_order(c):
    """Slope of log error against log dt over the finest half of the finite errors (nan with fewer than 2)."""
    c = c[c.error.map(math.isfinite) & (c.error > 0)].sort_values("per_tc")
    c = c.tail(max(2, len(c) // 2 + 1))
    if len(c) < 2:
        return math.nan
    xs, ys = [-math.log(n) for n in c.per_tc], [math.log(e) for e in c.error]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def draw(d, x, xlabel, path, foot, orders):
    fig, axes = plt.subplots(2, len(LAWS), figsize=(3.0 * len(LAWS), 6.0), sharey=True)
    handles = {}
    for row, test in enumerate(TESTS):
        for col, law in enumerate(LAWS):
            ax = axes[row][col]
            s = d[(d.test == test) & (d.law == law)]
            for scheme in SCHEMES:
                for update in ("trapezoidal", "first_order", "none"):
                    c = s[(s.integrator == scheme) & (s["update"] == update)].sort_values("per_tc")
                    c = c[c.error.map(math.isfinite)]
                    if c.empty:
                        continue
                    label = f"{scheme}, {update if update != 'none' else 'no stretch'}"
                    if orders:
                        label = f"p={fitted_order(c):.1f}"
                    (h,) = ax.loglog(c[x], c.error, DASH[update], color=COLOUR[scheme], marker=".", ms=3, lw=1, label=label)
                    handles[(scheme, update)] = h
            ax.set_title(f"{LAW_LABEL[law]}\n{TESTS[test]}", fontsize=7)
            ax.tick_params(labelsize=6)
            ax.grid(True, which="major", lw=0.3)
            if orders:
                ax.legend(fontsize=4.5, ncol=2)
            if row == 1:
                ax.set_xlabel(xlabel, fontsize=7)
            if col == 0:
                ax.set_ylabel("worst error over the sweep\n(over the quantity's scale)", fontsize=7)
    keys = [(s, u) for s in SCHEMES for u in ("trapezoidal", "first_order")]
    legend_outside(fig, [handles[k] for k in keys if k in handles], [f"{s}, {u}" for s, u in keys if (s, u) in handles])
    save_figure(fig, path, foot, dpi=130)


def recommendation(d, resolution):
    """Per law and target: the cheapest run (update, integrator, dt) meeting the target on both tests, with
    the cheapest under LAMMPS's first-order update beside it. Cost: CPU seconds of both tests' sweeps. A
    target under 3 times the law's reference step error (its difference from half as many steps: at second
    order the reference's own error is about a third of it) is not judged."""
    both = d.groupby(["law", "integrator", "update", "per_tc"]).agg(error=("error", "max"), cpu=("cpu_seconds", "sum"),
                                                                   steps=("steps", "sum"), tests=("test", "count"))
    both = both[both.tests == len(TESTS)].reset_index()
    lines = ["| law | target | cheapest: update, integrator, Δt (CPU s, error) | cheapest with the first-order update |",
             "|---|---|---|---|"]
    for law in LAWS:
        for target in TARGETS:
            if target < 3.0 * resolution[law]:
                lines.append(f"| {LAW_LABEL[law]} | {target:g} | below the reference's resolution | |")
                continue
            cells = []
            for updates in (("trapezoidal", "first_order", "none"), ("first_order", "none")):
                c = both[(both.law == law) & both["update"].isin(updates) & (both.error <= target)].sort_values("cpu")
                if c.empty:
                    cells.append("not met")
                else:
                    r = c.iloc[0]
                    upd = r["update"] if r["update"] != "none" else "no stretch"
                    cells.append(f"{upd}, {r.integrator}, t_c/{r.per_tc:g} "
                                 f"({r.cpu:.2g} s, {r.error:.1e})")
            lines.append(f"| {LAW_LABEL[law]} | {target:g} | {cells[0]} | {cells[1]} |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", help="memory_accuracy.json (memory_accuracy.csv beside it)")
    ap.add_argument("--figures", default="results/figures")
    ap.add_argument("--table", default=None, help="the recommendation (default memory_recommendation.md beside the JSON)")
    a = ap.parse_args()
    with open(a.json) as f:
        meta = json.load(f)
    d = pd.read_csv(os.path.join(os.path.dirname(a.json), "memory_accuracy.csv"))
    if d.empty:
        sys.exit(f"{a.json}: no rows")
    prov = meta["provenance"]
    wp = os.path.join(a.figures, "memory_work_precision.png")
    ev = os.path.join(a.figures, "memory_error_vs_dt.png")
    draw(d, "cpu_seconds", "CPU seconds of the sweep's runs", wp, footer(prov, "machine shared with other builds"), False)
    draw(d, "per_tc", "t_c / Δt", ev, footer(prov, "p: slope of log error against log Δt over the finest half"), True)
    # x of the second figure is t_c/dt: the slope against dt is minus the drawn one, as the labels say

    refs = pd.DataFrame(meta["references"])
    md = ["# The laws with memory: the cheapest way to a target error", "",
          f"Generated by analysis/plot_memory_accuracy.py from {os.path.basename(a.json)}; {provenance_line(prov)}. "
          "The machine was shared with other builds while it ran: the CPU times are indicative (std::clock of each run).", "",
          "Chung & Ooi tests 4 (17 angles) and 8 (17 spins), arrays variant. Error: the worst over both tests' sweeps "
          "of the rebound tangential velocity, spin and normal restitution, each against gear5 with the trapezoidal "
          "update at t_c/8000 and over the quantity's largest |reference|. Cost: CPU seconds of both sweeps (runs of "
          "a millisecond or less: differences of a few per cent between integrators at one Δt are noise). The "
          "cheapest run meeting each target, and the cheapest with LAMMPS's first-order update (the default); a "
          "target below 3 times the law's reference step error (table below) is not judged:", ""]
    md += recommendation(d, refs.groupby("law").reference_step_error.max().to_dict())
    md += ["", "The references' own step error (t_c/8000 against t_c/4000, over the scale):", "",
           "| test | law | step error |", "|---|---|---|"]
    md += [f"| {r.test} | {r.law} | {r.reference_step_error:.1e} |" for r in refs.itertuples()]
    md += ["", "Fitted order (slope of log error against log Δt, finest half of the sweep), gear5 and verlet:", "",
           "| test | law | integrator | update | order |", "|---|---|---|---|---|"]
    for test in TESTS:
        for law in LAWS:
            for scheme in ("gear5", "verlet"):
                for update in ("first_order", "trapezoidal", "none"):
                    c = d[(d.test == test) & (d.law == law) & (d.integrator == scheme) & (d["update"] == update)]
                    if not c.empty:
                        md.append(f"| {test} | {law} | {scheme} | {update} | {fitted_order(c):.2f} |")
    table = a.table or os.path.join(os.path.dirname(a.json), "memory_recommendation.md")
    write_text(table, "\n".join(md) + "\n")
    print(f"wrote {wp}, {ev}, {table}")


if __name__ == "__main__":
    main()
