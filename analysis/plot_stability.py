#!/usr/bin/python3
"""The stability map (docs/stability.md) from demmat_stability's JSON.

    /usr/bin/python3 analysis/plot_stability.py [results/stability/stability_default.json]

Writes results/figures/stability_map.png (stability_map_long.png for the long run): the largest stable
time step in units of the Hertz contact time against restitution, one panel per scene and stiffness, one
line per integrator (colour) and precision (solid double, dashed float); and beside the JSON a Markdown
table (the same name, .md).
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from atomic_io import write_text  # noqa: E402
from results import footer, legend_outside, load as load_result, save_figure  # noqa: E402

SCENES = {"head_on": "head-on pair", "wall": "sphere on a wall (gravity)", "dense_bed": "dense bed, 125 grains"}
COLOURS = {"gear5": "tab:blue", "gear3": "tab:orange", "verlet": "tab:green", "symplectic_euler": "tab:red"}


def load(path):
    res = load_result(str(path))
    return dict(res.meta, provenance=res.provenance), res.table


def plot(doc, rows, out):
    youngs = sorted(rows["young"].unique())
    scenes = [s for s in SCENES if s in set(rows["scene"])]
    fig, axes = plt.subplots(len(scenes), len(youngs), figsize=(3.6 * len(youngs), 2.9 * len(scenes)),
                             sharex=True, sharey=True, squeeze=False)
    for i, scene in enumerate(scenes):
        for j, young in enumerate(youngs):
            ax = axes[i][j]
            sub = rows[(rows.scene == scene) & (rows.young == young)]
            for (integ, prec), g in sub.groupby(["integrator", "precision"], sort=False):
                g = g.sort_values("target_restitution")
                ax.plot(g.target_restitution, g.dt_over_tc, color=COLOURS.get(integ, "k"),
                        linestyle="-" if prec == "double" else "--", marker="o" if prec == "double" else "x",
                        markersize=4, label=f"{integ}, {prec}")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            if i == 0:
                ax.set_title(f"E = {young:.0e} Pa")
            if j == 0:
                ax.set_ylabel(f"{SCENES[scene]}\nlargest stable Δt / t_c")
            if i == len(scenes) - 1:
                ax.set_xlabel("restitution (target)")
    legend_outside(axes[0][-1], fontsize=8)
    fig.suptitle(f"Stability map ({doc['mode']} run, variant {doc['variant']}): stable = no detection, contact ended, "
                 "restitution within 0.1", fontsize=9)
    save_figure(fig, str(out), footer(doc["provenance"], f"{doc['seconds']:.0f} s"), dpi=120, top=0.97)
    print(f"wrote {out}")


def table(doc, rows, out):
    prov = doc["provenance"]
    lines = [f"# Stability limits ({doc['mode']} run)", "",
             f"Produced by `scripts/run_stability.sh` (demmat_stability, variant {doc['variant']}): "
             f"commit {prov.get('commit')}{' (dirty)' if prov.get('dirty') else ''}, {prov.get('compiler')}, "
             f"{prov.get('flags')}, {prov.get('cpu')}, {prov.get('date')}; {doc['seconds']:.0f} s.", "",
             "Largest stable Δt in units of the Hertz contact time t_c at 1 m/s (the Rayleigh time T_R in brackets). "
             f"Stable: {doc['settings']['stable_means']}. See docs/stability.md.", ""]
    # Summary: the lower envelope per integrator × precision over every case.
    lines += ["## Lower envelope over every scene, stiffness and restitution", "",
              "| integrator | precision | min Δt/t_c | at | min Δt/t_c (checked t_c) | Δt/T_R range |", "|---|---|---|---|---|---|"]
    for (integ, prec), g in rows.groupby(["integrator", "precision"], sort=False):
        k = g.dt_over_tc.idxmin()
        w = g.loc[k]
        lines.append(f"| {integ} | {prec} | {w.dt_over_tc:.3f} | {w.scene}, E = {w.young:.0e}, e = {w.target_restitution:.1f} "
                     f"| {g.dt_over_tc_check.min():.3f} | {g.dt_over_rayleigh.min():.3f} … {g.dt_over_rayleigh.max():.2f} |")
    lines.append("")
    es = sorted(rows.target_restitution.unique())
    for scene in [s for s in SCENES if s in set(rows.scene)]:
        lines += [f"## {SCENES[scene]}", "", "| integrator | precision | E (Pa) | " + " | ".join(f"e = {e:.1f}" for e in es) + " |",
                  "|---|---|---|" + "---|" * len(es)]
        sub = rows[rows.scene == scene]
        for (integ, prec, young), g in sub.groupby(["integrator", "precision", "young"], sort=False):
            cells = []
            for e in es:
                r = g[g.target_restitution == e]
                cells.append("" if r.empty else f"{r.dt_over_tc.iloc[0]:.3f} ({r.dt_over_rayleigh.iloc[0]:.2f})")
            lines.append(f"| {integ} | {prec} | {young:.0e} | " + " | ".join(cells) + " |")
        lines.append("")
    # Why the first failing step failed, counted.
    lines += ["## What stopped the first run beyond the limit", "", "| reason | cases |", "|---|---|"]
    kinds = rows.fail_reason.str.replace(r"step \d+: ", "", regex=True).str.replace(r"particles? [\d and]+", "particle(s) …", regex=True)
    kinds = kinds.str.replace(r"[\d.e+-]+ J", "… J", regex=True).str.replace(r"by [\d.]+ of", "by … of", regex=True)
    kinds = kinds.str.replace(r"restitution [\d.-]+ is more than 0.1 from the converged [\d.-]+", "restitution off by more than 0.1",
                              regex=True).str.replace(r"'[xyz]_(min|max)'", "'…'", regex=True)
    for reason, n in kinds.value_counts().items():
        lines.append(f"| {reason or 'no failure up to 8 t_c'} | {n} |")
    lines.append("")
    write_text(str(out), "\n".join(lines))
    print(f"wrote {out}")


def main():
    path = Path(sys.argv[1] if len(sys.argv) > 1 else "results/stability/stability_default.json")
    doc, rows = load(path)
    fig = Path("results/figures") / ("stability_map.png" if doc["mode"] == "default" else "stability_map_long.png")
    plot(doc, rows, fig)
    table(doc, rows, path.with_suffix(".md"))


if __name__ == "__main__":
    main()
