#!/usr/bin/python3
"""The suite beside LAMMPS and LIGGGHTS (docs/peers.md); run by scripts/run_peers.sh with /usr/bin/python3.

  plot_peers.py bench --work DIR --versions JSON --out DIR --figure PNG
      medians of the interleaved repetitions (suite variants from `demmat bench --json`, peers from the
      logs of their timed runs), µs per particle-step against N, each variant's ratio to LAMMPS built
      here at the same thread count, fast's targets and where the time goes on the settled bed
      (peers_bench.py, peers_tables.py).
  plot_peers.py observables --dump FILE --scene TOML --code C --member M --stage S [--step-scale F] -o CSV
      per frame of a LAMMPS-style dump: kinetic energy, bed height, normal force on the x_max wall,
      computed the same way for every code.
  plot_peers.py physics --work DIR --versions JSON --particles N --amplitude A --out DIR --figure PNG
      ensemble bands per code, a figure and a Markdown summary.
  plot_peers.py replot-bench BENCH_PEERS.json --figure PNG
  plot_peers.py replot-physics PHYSICS_N.csv --versions JSON --amplitude A --figure PNG
      the tables and figures again from the files bench and physics wrote (results/peers/), beside them.
"""
import argparse
import glob
import json
import math
import os
import sys
import tomllib

import numpy as np
import pandas as pd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from atomic_io import write_text  # noqa: E402
from results import footer, legend_outside, load, n_axis, save_figure, style  # noqa: E402
from peers_bench import STAGES, STAGE_TITLE, label as peer_label, read_work, replot_frame, summarise, write_json  # noqa: E402
from peers_tables import markdown  # noqa: E402


# ---- bench ----------------------------------------------------------------------------------------------
def cmd_bench(a):
    df, provenance = read_work(a.work)
    write_bench(df, provenance, json.load(open(a.versions)), a.out, a.figure)


def write_bench(df, provenance, versions, out, figure):
    """Medians, ratios to the reference LAMMPS, bench_peers.{csv,json,md} in out, and the figure, from every sample."""
    df, med, ref = summarise(df)
    write_json(df, med, provenance, versions, out)
    # Figure: µs per particle-step against N, one panel per stage; more threads dashed and hollow.
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), sharey=True)
    for ax, stage in zip(axes, STAGES):
        m = med[med.stage == stage]
        for (code, variant, threads), s in m.groupby(["code", "variant", "threads"]):
            s = s.sort_values("particles")
            kw = style(variant, threads)
            if code != "suite":
                kw.update(linewidth=2.5, markersize=6)
                if code == "liggghts":
                    kw.update(linestyle=":")
            ax.errorbar(s.particles, s["median"], yerr=[s["median"] - s["min"], s["max"] - s["median"]],
                        label=peer_label(variant, versions, threads), linewidth=kw.pop("linewidth", 1.0), capsize=2, **kw)
        n_axis(ax, med.particles)
        ax.set_yscale("log")
        ax.set_title(STAGE_TITLE[stage])
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("µs per particle-step (median, min–max)")
    handles, labels = axes[0].get_legend_handles_labels()
    legend_outside(axes[-1], handles, labels)
    cpu = (provenance or {}).get("cpu", "")
    law = versions.get("contact_law", "")
    fig.suptitle(f"The suite's variants beside {peer_label(ref, versions)} ({cpu})" + (f"\ncontact law: {law}" if law else ""), fontsize=10)
    save_figure(fig, figure, footer(provenance or {}, f"median of {int(med.repetitions.max())} interleaved repetitions"), dpi=110)
    write_text(os.path.join(out, "bench_peers.md"), markdown(df, med, ref, provenance, versions))
    print(f"results: {os.path.join(out, 'bench_peers.md')} (.csv, .json), {figure}")


# ---- observables -----------------------------------------------------------------------------------------
def read_frames(path):
    with open(path) as f:
        lines = f.read().split("\n")
    k = 0
    while k < len(lines):
        if not lines[k].strip():
            k += 1
            continue
        step = int(lines[k + 1])
        n = int(lines[k + 3])
        cols = lines[k + 8].split()[2:]
        data = np.loadtxt(lines[k + 9:k + 9 + n], ndmin=2)
        k += 9 + n
        yield step, dict(zip(cols, data.T))


def scene_params(path):
    s = tomllib.load(open(path, "rb"))
    m = s.get("material", {})
    rho, E, nu = m.get("density", 1000.0), m.get("young", 0.3e6), m.get("poisson", 0.3)
    wm = s.get("wall_material", {})
    Ew, nuw = wm.get("young", E), wm.get("poisson", nu)
    estar_pw = 1.0 / ((1 - nu * nu) / E + (1 - nuw * nuw) / Ew)
    xmax = s["domain"]["max"][0]
    vx = 0.0
    for w in s.get("wall", []):
        if w.get("face") == "x_max":
            vx = w.get("velocity", [0, 0, 0])[0]
    return {"rho": rho, "hertz_pw": 4.0 / 3.0 * estar_pw, "gamma_n": m.get("gamma_n", 60.0),
            "dt": s.get("time", {}).get("dt", 1e-5), "xmax": xmax, "wall_vx": vx, "zmin": s["domain"]["min"][2]}


def cmd_observables(a):
    p = scene_params(a.scene)
    rows = []
    first = None
    for step, c in read_frames(a.dump):
        # Steps from the stage's start: demmat dump continues the state's step count, LAMMPS restarts at 0.
        first = step if first is None else first
        step = round((step - first) * a.step_scale)
        r = c["radius"]
        m = p["rho"] * (4.0 / 3.0) * math.pi * r ** 3
        inertia = 0.4 * m * r * r
        v2 = c["vx"] ** 2 + c["vy"] ** 2 + c["vz"] ** 2
        w2 = c["omegax"] ** 2 + c["omegay"] ** 2 + c["omegaz"] ** 2
        ke = float(np.sum(0.5 * m * v2 + 0.5 * inertia * w2))
        t = step * p["dt"]
        # The bed's height: twice the mean centre height above the floor (robust to a few bouncing grains).
        height = 2.0 * float(np.mean(c["z"] - p["zmin"]))
        # Normal force of the paper's law on the x_max wall where it stands at this step, for every code alike.
        xw = p["xmax"] + p["wall_vx"] * t
        h = r - (xw - c["x"])
        on = h > 0
        un = c["vx"][on] - p["wall_vx"]
        fn = p["hertz_pw"] * np.sqrt(r[on]) * h[on] * np.sqrt(h[on]) + p["gamma_n"] * m[on] * un
        force = float(np.sum(np.maximum(fn, 0.0)))
        rows.append({"code": a.code, "member": a.member, "stage": a.stage, "step": step, "time": t,
                     "kinetic_energy": ke, "bed_height": height, "wall_force_x_max": force, "wall_contacts": int(on.sum())})
    write_text(a.o, pd.DataFrame(rows).to_csv(index=False, float_format="%.9g"))


# ---- physics -----------------------------------------------------------------------------------------------
CODE_STYLE = {"suite": ("tab:blue", "suite (arrays, Gear)"),
              "suite_verlet": ("tab:green", "suite (arrays, velocity Verlet)"),
              "suite_lammps_arms": ("tab:purple", "suite (arrays, Gear, LAMMPS's lever arms)"),
              "suite_as_lammps": ("tab:red", "suite (arrays, velocity Verlet, LAMMPS's lever arms and half-step velocity)"),
              "lammps": ("black", "LAMMPS (velocity Verlet)"),
              "lammps_half_dt": ("tab:gray", "LAMMPS (velocity Verlet, Δt/2)"),
              "liggghts": ("tab:orange", "LIGGGHTS 3.8 (hertz/stiffness)")}
# suite_verlet: the suite's law with LAMMPS's integrator family, so that the table can tell how much of
# the suite's distance from LAMMPS is the integrator and how much the law's details (docs/peers.md).
# With run_peers.sh --diagnose: suite_lammps_arms, the suite built with LAMMPS's lever arms;
# suite_as_lammps, that build's velocity Verlet at LAMMPS's half-step velocity (every difference of
# physics.md §9's list removed); lammps_half_dt, LAMMPS at Δt/2, whose distance from LAMMPS is LAMMPS's
# own time-step error.
DIAGNOSTIC = ("suite_lammps_arms", "suite_as_lammps", "lammps_half_dt")
RELATIVE_TO_LAMMPS = ("suite", "suite_verlet") + DIAGNOSTIC


def cmd_physics(a):
    files = sorted(glob.glob(os.path.join(a.work, "obs_*.csv")))
    if not files:
        sys.exit("plot_peers.py: no observables in " + a.work)
    write_physics(pd.concat([pd.read_csv(f) for f in files]), json.load(open(a.versions)), a.particles, a.amplitude,
                  a.out, a.figure)


def write_physics(df, versions, particles, amplitude, out, figure):
    """Ensemble bands per code (figure), physics_<N>.csv (every frame) and physics_<N>.md in out."""
    panels = [("loose", "kinetic_energy", "kinetic energy (J), settling", True),
              ("loose", "bed_height", "bed height 2⟨z⟩ (m), settling", False),
              ("compression", "wall_force_x_max", "force on the moving wall (N), compression", False),
              ("compression", "kinetic_energy", "kinetic energy (J), compression", True)]
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    for ax, (stage, q, title, logy) in zip(axes.flat, panels):
        for code, s in df[df.stage == stage].groupby("code"):
            color, label = CODE_STYLE.get(code, ("gray", code))
            g = s.groupby("time")[q]
            t = g.mean().index
            ax.fill_between(t, g.min(), g.max(), color=color, alpha=0.25, linewidth=0)
            ax.plot(t, g.mean(), color=color, label=f"{label}, {s.member.nunique()} starts")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("time (s)")
        if logy:
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    fig.suptitle(f"{particles} grains, perturbed starts (velocity ±{amplitude} m/s): ensemble mean and min–max band per code", fontsize=10)
    # The observables carry no build provenance of their own: the footer says what made them.
    save_figure(fig, figure, f"LAMMPS {versions.get('lammps', '?')} (Debian {versions.get('lammps_package', '?')}) · LIGGGHTS "
                f"{versions.get('liggghts', '?')} · the suite: arrays variant, the paper's Gear scheme · {df.member.nunique()} "
                f"perturbed starts per code, the same data files for every code · scripts/run_peers.sh", dpi=110)

    # Summary: at a few times, each code's ensemble mean ± standard deviation, and the suite's and
    # LIGGGHTS's distance from LAMMPS in units of the pooled ensemble standard deviation.
    os.makedirs(out, exist_ok=True)
    write_text(os.path.join(out, f"physics_{particles}.csv"), df.to_csv(index=False, float_format="%.9g"))
    lines = [f"# Physics cross-check: the suite, LAMMPS and LIGGGHTS from the same {particles} grains", "",
             f"Each code ran {df.member.nunique()} perturbed starts (velocities ± {amplitude} m/s, the same data files for "
             f"every code). Mean ± standard deviation over the ensemble; *z* = (code − LAMMPS) / pooled std. "
             f"LAMMPS {versions.get('lammps', '?')}, "
             + (f"LIGGGHTS {versions.get('liggghts', '?')}. " if "liggghts" in df.code.unique() else "LIGGGHTS not run. ")
             + "Produced by scripts/run_peers.sh. "
             f"Where the perturbations have not yet grown (the short compression window), the ensemble band is "
             f"narrower than the codes' systematic differences and z is large for differences of 0.1 %: read the "
             f"relative difference there (docs/peers.md explains the causes)."
             + (" Diagnostic rows (run_peers.sh --diagnose): the suite built with LAMMPS's lever arms (Gear), the "
                "same build's velocity Verlet at LAMMPS's half-step velocity (every difference listed in docs/physics.md "
                "removed), and LAMMPS at half the time step, whose distance from LAMMPS is LAMMPS's own time-step error."
                if set(DIAGNOSTIC) & set(df.code.unique()) else ""), ""]
    for stage, q, title, _ in panels:
        s = df[df.stage == stage]
        times = sorted(s.time.unique())
        picks = [times[len(times) // 4], times[len(times) // 2], times[-1]]
        codes = [c for c in CODE_STYLE if c in s.code.unique()]
        rel_codes = [c for c in RELATIVE_TO_LAMMPS if c in codes and "lammps" in codes]
        z_codes = [c for c in codes if c != "lammps" and "lammps" in codes]
        lines += [f"## {title}", "",
                  "| t (s) | " + " | ".join(CODE_STYLE[c][1] for c in codes)
                  + "".join(f" | {CODE_STYLE[c][1].replace('suite (arrays, ', 'suite (')} − LAMMPS" for c in rel_codes)
                  + "".join(f" | z {CODE_STYLE[c][1]}" for c in z_codes) + " |",
                  "|---:|" + "---:|" * (len(codes) + len(rel_codes) + len(z_codes))]
        for t in picks:
            at = s[s.time == t].groupby("code")[q]
            mean, std = at.mean(), at.std(ddof=1)
            cells = [f"{mean[c]:.4g} ± {std[c]:.2g}" for c in codes]
            cells += [f"{100.0 * (mean[c] - mean['lammps']) / abs(mean['lammps']):+.2f} %" if mean["lammps"] != 0 else ""
                      for c in rel_codes]
            for c in z_codes:
                pooled = math.sqrt(0.5 * (std[c] ** 2 + std["lammps"] ** 2))
                cells.append(f"{(mean[c] - mean['lammps']) / pooled:+.1f}" if pooled > 0 else "n/a")
            lines.append(f"| {t:.3f} | " + " | ".join(cells) + " |")
        lines.append("")
    write_text(os.path.join(out, f"physics_{particles}.md"), "\n".join(lines))
    print(f"results: {os.path.join(out, f'physics_{particles}.md')}, {figure}")


def cmd_replot_bench(a):
    """The tables and the figure again from bench_peers.json (every sample is in it), beside it."""
    df, provenance, versions = replot_frame(a.json)
    write_bench(df, provenance, versions, os.path.dirname(a.json), a.figure)


def cmd_replot_physics(a):
    """The summary and the figure again from physics_<N>.csv (every frame of every code), beside it."""
    n = int(os.path.basename(a.csv)[len("physics_"):-len(".csv")])
    versions = load(a.versions).meta["peers"] if a.versions.endswith("bench_peers.json") else json.load(open(a.versions))
    write_physics(pd.read_csv(a.csv), versions, n, a.amplitude, os.path.dirname(a.csv), a.figure)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("bench")
    b.add_argument("--work", required=True)
    b.add_argument("--versions", required=True)
    b.add_argument("--out", required=True)
    b.add_argument("--figure", required=True)
    o = sub.add_parser("observables")
    o.add_argument("--dump", required=True)
    o.add_argument("--scene", required=True)
    o.add_argument("--code", required=True)
    o.add_argument("--member", type=int, required=True)
    o.add_argument("--stage", required=True)
    o.add_argument("--step-scale", type=float, default=1.0,
                   help="the run's time step over the scene's (a run at Δt/2: 0.5); its frames keep the others' times")
    o.add_argument("-o", required=True)
    p = sub.add_parser("physics")
    p.add_argument("--work", required=True)
    p.add_argument("--versions", required=True)
    p.add_argument("--particles", type=int, required=True)
    p.add_argument("--amplitude", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--figure", required=True)
    r = sub.add_parser("replot-bench")
    r.add_argument("json", help="bench_peers.json written by `plot_peers.py bench`")
    r.add_argument("--figure", required=True)
    r = sub.add_parser("replot-physics")
    r.add_argument("csv", help="physics_<N>.csv written by `plot_peers.py physics`")
    r.add_argument("--versions", required=True, help="versions.json of the peers, or a bench_peers.json that holds them")
    r.add_argument("--amplitude", required=True, help="the perturbation the run used (m/s)")
    r.add_argument("--figure", required=True)
    a = ap.parse_args()
    {"bench": cmd_bench, "observables": cmd_observables, "physics": cmd_physics,
     "replot-bench": cmd_replot_bench, "replot-physics": cmd_replot_physics}[a.cmd](a)


if __name__ == "__main__":
    main()
