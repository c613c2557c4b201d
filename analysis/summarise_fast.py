#!/usr/bin/python3
"""The fast variant's benchmark (scripts/bench_fast.sh) as one table: µs per particle-step of arrays,
fast and fast_unordered on the settled bed for each N and thread count, each phase's share, the
speed-up from one to two threads, and the 10⁶-particle run's time and peak memory.

Usage: /usr/bin/python3 analysis/summarise_fast.py results/fast [-o results/fast/summary.md]
"""
import argparse
import json
import pathlib
import re
import sys

import pandas as pd

from atomic_io import write_text


def load(folder):
    rows, prov = [], None
    for path in sorted(folder.glob("bench_settled_*_t*.json")):
        m = re.fullmatch(r"bench_settled_(\d+)_t(\d+)\.json", path.name)
        if not m:
            continue
        d = json.loads(path.read_text())
        prov = prov or d["provenance"]
        for s in d["summary"]:
            sec = s["seconds_per_step"]
            total = sec["total"]["median"]
            rows.append({
                "N": int(m.group(1)), "threads": int(d["threads"]), "variant": s["variant"],
                "us_per_particle_step": s["us_per_particle_step"],
                "min_us": sec["total"]["min"] / d["scene"]["particles"] * 1e6,
                "max_us": sec["total"]["max"] / d["scene"]["particles"] * 1e6,
                **{f"{p} %": 100.0 * sec[p]["median"] / total for p in ("predict", "search", "forces", "correct")},
                "contacts/particle": s["contacts_per_particle"], "bytes/particle": s["memory_bytes"] / d["scene"]["particles"],
                "repetitions": d["repetitions"], "steps": d["steps"],
            })
    return pd.DataFrame(rows), prov


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=pathlib.Path)
    ap.add_argument("-o", "--output", type=pathlib.Path)
    a = ap.parse_args(argv)
    df, prov = load(a.folder)
    if df.empty:
        print(f"summarise_fast.py: no bench_settled_<N>_t<threads>.json in {a.folder}", file=sys.stderr)
        return 1
    df = df.sort_values(["N", "variant", "threads"])
    one = df[df.threads == 1].set_index(["N", "variant"])["us_per_particle_step"]
    df["speed-up vs 1 thread"] = [one.get((n, v), float("nan")) / u for n, v, u in zip(df.N, df.variant, df.us_per_particle_step)]
    arrays1 = df[(df.variant == "arrays") & (df.threads == 1)].set_index("N")["us_per_particle_step"]
    df["vs arrays (1 thread)"] = [u / arrays1.get(n, float("nan")) for n, u in zip(df.N, df.us_per_particle_step)]

    out = [
        "# fast on the settled bed: N, threads, canonical order",
        "",
        f"Produced by scripts/bench_fast.sh and analysis/summarise_fast.py: commit {prov['commit'][:10]}"
        f"{' (dirty)' if prov.get('dirty') else ''}, {prov['compiler']}, `{prov['flags']}`, CPU {prov['cpu']}, {prov['date']}.",
        "Median µs per particle-step over interleaved repetitions (min–max); phases as % of the step; the"
        " dense bed settled 0.4 s by fast, then continued with the walls at rest.",
        "",
        "| N | variant | threads | µs/particle-step | min–max | speed-up vs 1 thread | vs arrays (1 thread) | predict | search | forces | correct | contacts/particle | bytes/particle |",
        "|---:|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for _, r in df.iterrows():
        out.append(f"| {r['N']} | {r['variant']} | {r['threads']} | {r['us_per_particle_step']:.3f} | {r['min_us']:.3f}–{r['max_us']:.3f} | "
                   f"{r['speed-up vs 1 thread']:.2f} | {r['vs arrays (1 thread)']:.2f} | {r['predict %']:.0f} % | {r['search %']:.0f} % | "
                   f"{r['forces %']:.0f} % | {r['correct %']:.0f} % | {r['contacts/particle']:.2f} | {r['bytes/particle']:.0f} |")
    million = a.folder / "million.json"
    mtime = a.folder / "million_time.txt"
    if million.exists() and mtime.exists():
        m = json.loads(million.read_text())
        text = mtime.read_text()
        rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
        out += ["", "## 10⁶ particles", ""]
        phases = {p: m["seconds_per_step"][p]["median"] if isinstance(m["seconds_per_step"][p], dict) else m["seconds_per_step"][p]
                  for p in ("predict", "search", "forces", "correct")} if "seconds_per_step" in m else {}
        line = (f"fast ran {m['steps']} steps of the loose lattice of {m['scene']['particles']} grains at {m['threads']} threads: "
                f"{m['us_per_particle_step']:.3f} µs per particle-step, {m['wall_seconds']:.1f} s of wall time in all")
        if phases:
            line += " (ms per step: " + ", ".join(f"{p} {1e3 * v:.1f}" for p, v in phases.items()) + ")"
        if rss:
            line += f"; peak resident set {int(rss.group(1)) / 1024 ** 2:.2f} GiB"
        out.append(line + ".")
    text = "\n".join(out) + "\n"
    if a.output:
        write_text(str(a.output), text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
