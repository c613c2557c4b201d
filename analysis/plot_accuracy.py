#!/usr/bin/python3
"""Work-precision diagrams, error against dt with the measured order, and the recommendation table of
the speed-accuracy study (docs/accuracy.md), from the CSV and JSON of build*/bench/demmat_accuracy.

Usage: /usr/bin/python3 analysis/plot_accuracy.py results/accuracy/accuracy.json \
           [--figures results/figures] [--table results/accuracy/recommendation.md]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from atomic_io import write_text  # noqa: E402
from results import footer, legend_outside, load, save_figure  # noqa: E402

INTEGRATORS = ["gear5", "gear3", "verlet", "symplectic_euler"]
COLORS = {"gear5": "tab:blue", "gear3": "tab:green", "verlet": "tab:orange", "symplectic_euler": "tab:red"}
STYLES = {"double": "-", "float": "--"}
MARKERS = {"double": "o", "float": "x"}

# (kind, scene, measure, title) of the panels
PANELS = [
    ("two_body", "head_on_elastic", "max_overlap", "elastic head-on: max overlap\n(vs analytic Hertz)"),
    ("two_body", "head_on_elastic", "contact_time", "elastic head-on: contact time\n(vs analytic Hertz)"),
    ("two_body", "head_on_damped", "restitution", "damped head-on: restitution\n(vs converged RK4)"),
    ("two_body", "oblique_sliding", "spin", "oblique, gross sliding: spin\n(vs converged RK4)"),
    ("many_body", None, "position_error_quarter", "dense bed: mean position error\nat T/4 (vs Δt_ref run)"),
    ("many_body", None, "ke_history", "dense bed: kinetic-energy history\n(rel. L2 vs Δt_ref run)"),
]


def select(d, kind, scene, measure):
    s = d[(d.kind == kind) & (d.measure == measure)]
    if scene:
        s = s[s.scene == scene]
    return s


def fitted_order(s):
    """Slope of log(error) against log(dt) over the finest half of the stable points (least squares)."""
    s = s[(s.status == "ok") & (s.error > 0)].sort_values("dt")
    if len(s) < 3:
        return float("nan")
    s = s.iloc[: max(3, (len(s) + 1) // 2)]
    slope, _ = np.polyfit(np.log(s.dt), np.log(s.error), 1)
    return slope


def slope_label(p):
    """The fitted slope as what it says: error ∝ Δt^p. Where the error grows as Δt shrinks (float at fine
    steps: the round-off of more steps outweighs the truncation error), p is no order of convergence: said so."""
    if p != p:
        return ""
    power = rf"$\propto\Delta t^{{{p:.1f}}}$"
    return f" (round-off: error {power})" if p < 0 else f" (error {power})"


def draw(d, refs, x, path, xlabel_two, xlabel_many, with_order, foot):
    fig, axes = plt.subplots(2, 3, figsize=(15, 11 if with_order else 9))
    for ax, (kind, scene, measure, title) in zip(axes.flat, PANELS):
        s = select(d, kind, scene, measure)
        for integ in INTEGRATORS:
            for prec in ["double", "float"]:
                c = s[(s.integrator == integ) & (s.precision == prec) & (s.status == "ok")].sort_values("dt")
                if c.empty:
                    continue
                label = f"{integ} {prec}"
                if with_order:
                    label += slope_label(fitted_order(c))
                ax.loglog(c[x(kind)], c.error.clip(lower=1e-16), STYLES[prec], marker=MARKERS[prec], color=COLORS[integ],
                          label=label, ms=4, lw=1.2)
        if kind == "many_body":
            floor = refs["dense_bed"]["chaos_floor"].get(measure)
            if floor:
                ax.axhline(floor, color="grey", ls=":", lw=1.5, label="chaos floor (1 nm nudge)")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(xlabel_two if kind == "two_body" else xlabel_many)
        ax.set_ylabel("relative error" if "position" not in measure else "error / mean radius")
        ax.grid(True, which="both", alpha=0.3)
        if with_order:  # each panel its own slopes: the legend under its panel
            ax.legend(fontsize=6.5, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.16), frameon=False)
    if not with_order:  # the same curves in every panel: one legend, beside them
        handles, labels = axes.flat[-1].get_legend_handles_labels()
        legend_outside(axes[0][-1], handles, labels, fontsize=8)
    save_figure(fig, path, foot, dpi=130)


def recommendation(d, refs, tolerances):
    """For each tolerance: the largest dt/t_c at which every two-body error (all cases and measures) is
    within it, at that dt and every smaller one swept; and the CPU time per simulated second that the
    dense bed costs at that dt (its per-step cost divided by the dt, t_c of the head-on impact)."""
    two = d[d.kind == "two_body"]
    tc = refs["head_on_elastic"]["tc_hertz_s"]
    bed = d[(d.kind == "many_body") & (d.status == "ok")]
    rows = []
    for integ in INTEGRATORS:
        for prec in ["double", "float"]:
            c = two[(two.integrator == integ) & (two.precision == prec)]
            worst = c.groupby("dt_over_tc").error.max().sort_index()  # NaN (unstable) counts as failing
            worst = worst.fillna(np.inf)
            per_step = bed[(bed.integrator == integ) & (bed.precision == prec)].groupby("dt").seconds_per_step.first()
            step_cost = float(per_step.median()) if len(per_step) else float("nan")
            row = {"integrator": integ, "precision": prec, "bed_seconds_per_step": step_cost}
            for tol in tolerances:
                ok = (worst <= tol).values
                best = None
                for k in range(len(worst)):  # the largest dt with every dt up to it within tol
                    if ok[: k + 1].all():
                        best = worst.index[k]
                    else:
                        break
                row[tol] = best
            rows.append(row)
    lines = ["| integrator | precision | " + " | ".join(f"tol {t:g}: Δt/t_c (CPU s per simulated s)" for t in tolerances) + " |",
             "|---|---|" + "---|" * len(tolerances)]
    for r in rows:
        cells = []
        for tol in tolerances:
            v = r[tol]
            if v is None:
                cells.append("not met")
            else:
                cpu = r["bed_seconds_per_step"] / (v * tc)
                cells.append(f"1/{1 / v:.0f} ({cpu:.3g})")
        lines.append(f"| {r['integrator']} | {r['precision']} | " + " | ".join(cells) + " |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", help="accuracy.json written by demmat_accuracy (accuracy.csv beside it)")
    ap.add_argument("--figures", default="results/figures")
    ap.add_argument("--table", default=None, help="Markdown recommendation table (default: beside the JSON)")
    a = ap.parse_args()
    res = load(a.json)
    meta, d, prov = res.meta, res.table, res.provenance
    refs = meta["references"]
    wp = os.path.join(a.figures, "accuracy_work_precision.png")
    ev = os.path.join(a.figures, "accuracy_error_vs_dt.png")
    draw(d, refs, lambda kind: "cpu_seconds", wp, "CPU time of the impact (s)", "CPU time of the run (s)", False, footer(prov))
    draw(d, refs, lambda kind: "dt_over_tc" if kind == "two_body" else "dt", ev, "Δt / t_c (Hertz contact time at 1 m/s)",
         "Δt (s)", True, footer(prov, "legend: error ∝ Δt^p, p the slope of log error against log Δt over the finest half of "
                                "the stable steps (the measured order where the truncation error dominates); p < 0: no "
                                "convergence, the round-off of more steps outweighs the truncation error (float)"))

    # Measured orders (double, finest half of the sweep), for the docs.
    order_rows = []
    for kind, scene, measure, _ in PANELS:
        s = select(d, kind, scene, measure)
        for integ in INTEGRATORS:
            c = s[(s.integrator == integ) & (s.precision == "double")]
            order_rows.append(f"| {scene or 'dense_bed'} | {measure} | {integ} | {fitted_order(c):.2f} |")

    tolerances = [1e-2, 1e-3, 1e-4, 1e-5]
    md = [f"# Speed–accuracy recommendation (generated by analysis/plot_accuracy.py from {os.path.basename(a.json)})", "",
          f"Commit {prov.get('commit')}{' (dirty)' if prov.get('dirty') else ''}, {prov.get('compiler')}, "
          f"flags `{prov.get('flags')}`, CPU {prov.get('cpu')}, {prov.get('date')}.", "",
          "Largest time step (as a fraction of the Hertz contact time t_c of a 1 m/s impact of two 4 mm grains) at which "
          "every two-body error — contact time, maximum overlap, restitution (elastic and damped head-on), rebound angle "
          "and spin (oblique, gross sliding) — stays within the tolerance, at that Δt and every smaller one swept; in "
          "brackets the CPU seconds per simulated second of the dense bed "
          f"({meta['settings']['bed_particles']} grains, arrays variant) at that Δt (its median cost per step / Δt).", ""]
    md += recommendation(d, refs, tolerances)
    md += ["", "Measured order of convergence (slope of log error against log Δt over the finest half of the sweep, double):",
           "", "| case | measure | integrator | order |", "|---|---|---|---|"] + order_rows
    md += ["", "Chaos floor of the dense bed (the reference against itself with one grain moved 1 nm at t = 0): " +
           ", ".join(f"{k} {v:.2g}" for k, v in refs["dense_bed"]["chaos_floor"].items()) + "."]
    table = a.table or os.path.join(os.path.dirname(a.json), "recommendation.md")
    write_text(table, "\n".join(md) + "\n")
    print(f"wrote {wp}, {ev}, {table}")


if __name__ == "__main__":
    main()
