#!/usr/bin/python3
"""The run log of `demmat run --log FILE` as a figure.

    /usr/bin/python3 analysis/plot_log.py LOG [--out PNG]

Four panels against time: the energies (kinetic translational and rotational, gravitational, elastic and
their total), the contacts (particle pairs and particle-wall), the largest overlap over the smaller
radius, and the magnitude of the force of the particles on each wall (the log holds its components; a
wall with no force in the whole log is left out; walls are numbered in the scene's order, from 0). Written next to the log (LOG with .png) unless
--out names the file. A log still being written is read up to its last whole row, so the figure can be
redrawn while the run goes on.
"""
import argparse
import io
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from atomic_io import atomic_write  # noqa: E402

ENERGIES = [("kinetic_translational", "kinetic, translational"), ("kinetic_rotational", "kinetic, rotational"),
            ("gravitational", "gravitational"), ("elastic", "elastic"), ("total", "total")]
WALL = re.compile(r"^wall(\d+)_f([xyz])$")


def load(path):
    """The log's whole rows (a row still being written, without its newline, is dropped)."""
    text = Path(path).read_text()
    if not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    if not text.startswith("step,time,"):
        sys.exit(f"plot_log.py: {path}: not a demmat run log (its first line is not the header step,time,...)")
    try:
        rows = pd.read_csv(io.StringIO(text))
    except (ValueError, pd.errors.ParserError) as e:
        sys.exit(f"plot_log.py: {path}: not a demmat run log ({str(e).strip()})")
    missing = [c for c, _ in ENERGIES if c not in rows.columns] + \
        [c for c in ("step", "time", "contacts_particle", "contacts_wall", "largest_overlap_ratio") if c not in rows.columns]
    if missing:
        sys.exit(f"plot_log.py: {path}: not a demmat run log (no column {', '.join(missing)})")
    if rows.empty:
        sys.exit(f"plot_log.py: {path}: the log has no rows yet")
    return rows


def plot(rows, title, out):
    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    t = rows["time"]
    ax = axes[0]
    for col, label in ENERGIES:
        ax.plot(t, rows[col], label=label, linewidth=2.0 if col == "total" else 1.2,
                color="k" if col == "total" else None)
    ax.set_ylabel("energy (J)")
    ax.legend(fontsize=8, ncol=3)
    ax = axes[1]
    ax.plot(t, rows["contacts_particle"], label="particle-particle")
    ax.plot(t, rows["contacts_wall"], label="particle-wall")
    ax.set_ylabel("contacts")
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(t, rows["largest_overlap_ratio"])
    ax.set_ylabel("largest overlap /\nsmaller radius")
    ax = axes[3]
    walls = sorted({int(m.group(1)) for c in rows.columns if (m := WALL.match(c))})
    shown = 0
    for w in walls:
        f = rows[[f"wall{w}_f{a}" for a in "xyz"]]
        if (f != 0).any().any():
            ax.plot(t, (f ** 2).sum(axis=1) ** 0.5, label=f"wall {w}")
            shown += 1
    if shown:
        ax.legend(fontsize=8, ncol=3)
    else:
        ax.text(0.5, 0.5, "no wall force in the log", transform=ax.transAxes, ha="center", va="center")
    ax.set_ylabel("|force on the wall| (N)")
    ax.set_xlabel("time (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{title}: steps {rows['step'].iloc[0]} to {rows['step'].iloc[-1]} ({len(rows)} rows)", fontsize=10)
    fig.tight_layout()
    atomic_write(str(out), lambda tmp: fig.savefig(tmp, dpi=120, format="png"))
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description="Plot the CSV run log of demmat run --log.")
    p.add_argument("log", help="the log (CSV) written by demmat run --log")
    p.add_argument("--out", help="the figure (PNG); default: next to the log, with .png")
    a = p.parse_args()
    log = Path(a.log)
    if not log.is_file():
        sys.exit(f"plot_log.py: {log}: no such file")
    out = Path(a.out) if a.out else log.with_suffix(".png")
    if out.resolve() == log.resolve():
        sys.exit(f"plot_log.py: --out {out} is the log itself")
    plot(load(log), log.name, out)
    print(out)


if __name__ == "__main__":
    main()
