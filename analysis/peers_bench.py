"""The peer benchmark's samples and tables (plot_peers.py bench and replot-bench; docs/peers.md).

Every sample is one row: code (suite, lammps_native, lammps, liggghts), variant (the suite's variant, else
the code), threads (asked), particles, stage, repetition, steps, phase, seconds_per_step. The reference
of every ratio is LAMMPS built on the machine of the run (lammps_native: scripts/build_lammps.sh, -O3
-march=native) at the same thread count; files of before that build have Debian's binary (lammps) only,
which is then the reference.
"""
import glob
import json
import os
import re
import sys

import pandas as pd

from atomic_io import write_text
from results import load

STAGES = ["loose", "bed", "compression"]
STAGE_TITLE = {"loose": "loose grid (t = 0)", "bed": "settled bed", "compression": "compression stage"}
SUITE_PHASES = ["predict", "search", "forces", "correct"]
PEER_PHASES = ["pair", "neigh", "rest"]
PEERS = ("lammps_native", "lammps", "liggghts")
# The phases side by side (the phase table): what each code times, in the order of a step.
PHASE_TITLE = {"predict": "predict + correct (Gear)", "search": "search (cells, lists)", "forces": "forces (pairs, walls)",
               "pair": "Pair (pair style)", "neigh": "Neigh (lists)", "rest": "rest (fixes: integration, gravity, walls; other)"}
# A peer's log: <code>[_t<threads>]_n<N>_<stage>_r<repetition>.out (no _t: one thread).
PEER_LOG = re.compile(r"^(lammps_native|lammps|liggghts)(?:_t(\d+))?_n(\d+)_(.+)_r(\d+)\.out$")
SUITE_JSON = re.compile(r"^suite(?:_t\d+)?_n(\d+)_(.+)_r(\d+)\.json$")
# Debian's binary: the package's build (dpkg-buildflags' defaults, for a baseline x86-64), no OPENMP package.
DEBIAN_FLAGS = "-g -O2, baseline x86-64"
# fast's targets (docs/peers.md, "The benchmark"): the limit of each paired ratio.
TARGETS = {"peer": 0.5, "loose": 1.5, "order": 1.10, "threads": 1.0}


def read_peer_log(path):
    """A LAMMPS or LIGGGHTS run's last loop (the timed run after the warm-up), in seconds per step: the
    total ('Loop time of') and its breakdown: the pair style, the neighbour lists, and the rest (fixes, among
    them the integrator and the walls, communication, output, other). LAMMPS prints its breakdown as
    'Pair | min | avg | max | ...' rows, LIGGGHTS (a LAMMPS of 2013) as 'Pair  time (%) = t (p)' lines.
    Returns (steps, particles, {phase: seconds per step})."""
    with open(path) as f:
        text = f.read()
    loops = list(re.finditer(r"^Loop time of (\S+) on \d+ procs? for (\d+) steps with (\d+) atoms", text, re.M))
    if not loops:
        sys.exit(f"plot_peers.py: {path}: no 'Loop time of' line: the run failed (its output is that file)")
    last = loops[-1]
    total, steps, particles = float(last[1]), int(last[2]), int(last[3])
    tail = text[last.end():]
    sections = {}
    for name, avg in re.findall(r"^(Pair|Neigh)\s*\|[^|]*\|\s*(\S+)\s*\|", tail, re.M):  # avg, the middle column
        sections.setdefault(name, float(avg))
    for name, t in re.findall(r"^(Pair|Neigh)\s+time \(%\) = (\S+)", tail, re.M):
        sections.setdefault(name, float(t))
    if set(sections) != {"Pair", "Neigh"}:
        sys.exit(f"plot_peers.py: {path}: no Pair and Neigh times after the last 'Loop time of'")
    pair, neigh = sections["Pair"], sections["Neigh"]
    return steps, particles, {"total": total / steps, "pair": pair / steps, "neigh": neigh / steps,
                              "rest": (total - pair - neigh) / steps}


def read_work(work):
    """Every sample of a run's work folder: the suite's `demmat bench --json` files and the peers' logs."""
    rows, provenance = [], None
    for f in sorted(glob.glob(os.path.join(work, "suite_*.json"))):
        m = SUITE_JSON.match(os.path.basename(f))
        if not m:
            continue
        res = load(f)
        provenance = provenance or res.provenance
        n, stage, rep = int(m[1]), m[2], int(m[3])
        for s in res.meta["summary"]:
            for phase in ["total"] + SUITE_PHASES:
                rows.append({"code": "suite", "variant": s["variant"], "threads": int(s.get("threads_asked", 1)) or 1,
                             "ran_on": int(s.get("threads", 1)), "particles": n, "stage": stage, "repetition": rep,
                             "steps": res.meta["steps"], "phase": phase, "seconds_per_step": s["seconds_per_step"][phase]["median"]})
    for f in sorted(glob.glob(os.path.join(work, "*.out"))):
        m = PEER_LOG.match(os.path.basename(f))
        if not m:
            continue
        code, threads, n, stage, rep = m[1], int(m[2] or 1), int(m[3]), m[4], int(m[5])
        steps, particles, seconds = read_peer_log(f)
        if particles != n:
            sys.exit(f"plot_peers.py: {f}: {particles} atoms, not the {n} of its name")
        rows += [{"code": code, "variant": code, "threads": threads, "ran_on": threads, "particles": n, "stage": stage,
                  "repetition": rep, "steps": steps, "phase": phase, "seconds_per_step": t} for phase, t in seconds.items()]
    return pd.DataFrame(rows), provenance


def reference(df):
    """The code every ratio is taken against: LAMMPS built here where the run has it, else Debian's binary."""
    return "lammps_native" if (df.code == "lammps_native").any() else "lammps"


def label(variant, versions, threads=1):
    """A row's name in the tables and the figure: the peers with their builds' flags."""
    names = {"lammps_native": f"LAMMPS {versions.get('lammps_native_flags', '-O3 -march=native')}",
             "lammps": f"LAMMPS Debian ({versions.get('lammps_package_flags', DEBIAN_FLAGS)})", "liggghts": "LIGGGHTS"}
    name = names.get(variant, variant)
    if threads > 1:
        name += f", OPENMP {threads} threads" if variant == "lammps_native" else f", {threads} threads"
    return name


def builds_note(versions):
    """The sentence that names both LAMMPS builds with their flags (the tables' header)."""
    debian = (f"Debian's binary of LAMMPS {versions.get('lammps', '?')} (package {versions.get('lammps_package', '?')}; "
              f"{versions.get('lammps_package_flags', DEBIAN_FLAGS)}; no OPENMP package)")
    if not versions.get("lammps_native_build"):
        return debian + "."
    return (f"LAMMPS {versions.get('lammps_native', '?')} built on this machine by scripts/build_lammps.sh from Debian's "
            f"source package ({versions['lammps_native_build']}), the reference; beside it {debian}.")


def paired_ratios(df, ref):
    """Each sample's time over the reference's in the same repetition, stage, N and thread count (the two
    ran side by side): the median and range over the repetitions. Robust to a shared machine's slower
    hours, which move both samples of a repetition alike, where the ratio of the medians may pair a quiet
    hour's sample with a loaded one's."""
    tot = df[df.phase == "total"]
    lam = tot[tot.code == ref].set_index(["stage", "particles", "threads", "repetition"])["us_per_particle_step"]
    key = list(zip(tot.stage, tot.particles, tot.threads, tot.repetition))
    r = tot.assign(paired=[t / lam.get(k, float("nan")) for t, k in zip(tot.us_per_particle_step, key)]).dropna(subset=["paired"])
    g = r.groupby(["code", "variant", "threads", "stage", "particles"])["paired"]
    return g.median().rename("paired_ratio").to_frame().join(g.min().rename("paired_min")).join(
        g.max().rename("paired_max")).reset_index()


def summarise(df):
    """Medians per code, variant, threads, stage and N, the ratio to the reference and the paired ratios."""
    if df.empty:
        sys.exit("plot_peers.py: no samples")
    if "threads" not in df:
        df["threads"] = 1
    if "ran_on" not in df:
        df["ran_on"] = df["threads"]
    df["us_per_particle_step"] = df["seconds_per_step"] / df["particles"] * 1e6
    ref = reference(df)
    keys = ["code", "variant", "threads", "stage", "particles"]
    g = df[df.phase == "total"].groupby(keys)["us_per_particle_step"]
    med = g.median().rename("median").to_frame().join(g.min().rename("min")).join(g.max().rename("max")) \
        .join(g.count().rename("repetitions")).join(df[df.phase == "total"].groupby(keys)["ran_on"].max()).reset_index()
    lam = med[med.code == ref].set_index(["stage", "particles", "threads"])["median"]
    med["ratio_to_lammps"] = [r["median"] / lam.get((r["stage"], r["particles"], r["threads"]), float("nan")) for _, r in med.iterrows()]
    return df, med.merge(paired_ratios(df, ref), on=keys, how="left"), ref


def write_json(df, med, provenance, versions, out):
    os.makedirs(out, exist_ok=True)
    write_text(os.path.join(out, "bench_peers.csv"), med.to_csv(index=False, float_format="%.6g"))
    doc = {"provenance": provenance, "peers": versions, "timing": {
        "suite": "demmat bench: sum of the four timed phases per step (health checks excluded), median over its own run",
        "peers": "the code's own 'Loop time of' for the timed run after a warm-up run, divided by its steps"},
        "reference": reference(df), "summary": med.to_dict("records"), "samples": df.to_dict("records")}
    write_text(os.path.join(out, "bench_peers.json"), json.dumps(doc, indent=1) + "\n")


def replot_frame(path):
    """The samples and versions of a bench_peers.json (files of before the thread comparison: one thread)."""
    res = load(path)
    df = res.table.drop(columns=["sample"]).rename(columns={"N": "particles", "seconds": "seconds_per_step"})
    return df.drop(columns=["us_per_particle_step"], errors="ignore"), res.provenance, res.meta["peers"]
