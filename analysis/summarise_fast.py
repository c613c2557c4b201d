#!/usr/bin/python3
"""The fast variant's benchmark (scripts/bench_fast.sh) as tables: µs per particle-step of arrays,
fast and fast_unordered on the settled bed for each N and thread count, each phase's share, the
speed-up from one to two threads; what the canonical order costs (fast over fast_unordered, as the
ratio of the medians and paired within each repetition); and the 10⁶-particle run's time and peak memory.

Usage: /usr/bin/python3 analysis/summarise_fast.py results/fast [-o results/fast/summary.md]
"""
import argparse
import pathlib
import re
import sys

import pandas as pd

from atomic_io import emit
import results


def canonical_cost(tot, state, n):
    """fast over fast_unordered per thread count: each repetition's two totals were taken side by side
    (one interleaved round), so their ratio is the order's cost with the machine's drift cancelled."""
    variants = set(tot.index.get_level_values("variant"))
    if not {"fast", "fast_unordered"} <= variants:
        return []
    out = []
    for t in tot.columns:
        ratio = (tot.loc["fast"][t] / tot.loc["fast_unordered"][t]).dropna()
        if not ratio.empty:
            out.append({"state": state, "N": n, "threads": int(t), "paired": ratio.median(), "paired_min": ratio.min(), "paired_max": ratio.max()})
    return out


def read(folder):
    """One row per (state, N, variant, threads) from bench_settled_<N>.json and bench_loose_<N>.json
    (every thread count in one run, interleaved); also the paired speed-ups: per repetition, the 1-thread total over the t-thread total
    of the same variant, taken side by side; and the canonical order's paired cost (canonical_cost)."""
    rows, paired, costs, prov = [], [], [], {}
    for path in sorted(folder.glob("bench_*.json")):
        m = re.fullmatch(r"bench_(settled|loose)_(\d+)\.json", path.name)
        if not m:
            continue
        res = results.load(str(path))
        state, n = m.group(1), int(m.group(2))
        prov.setdefault(state, {})[n] = res.provenance
        # Rows by the threads asked: a variant may run a small bed on fewer (fast below 3000 grains).
        rows += [dict(r, state=state) for r in results.summary_rows(res)]
        asked = "threads_asked" if "threads_asked" in res.table.columns else "threads"
        tot = res.table.groupby(["variant", asked, "repetition"])["seconds"].sum().unstack(asked)
        costs += canonical_cost(tot, state, n)
        if 1 in tot.columns:
            for t in tot.columns:
                if t != 1:
                    ratio = (tot[1] / tot[t]).dropna()
                    for v, r in ratio.groupby(level="variant"):
                        paired.append({"state": state, "N": n, "variant": v, "threads": int(t), "paired": r.median(), "paired_min": r.min(), "paired_max": r.max()})
    return pd.DataFrame(rows), pd.DataFrame(paired), pd.DataFrame(costs), prov


def provenance_line(prov):
    """Each state's runs with their commit, compiler, flags, CPU and dates (the states may come from
    different runs: bench_fast.sh --sizes "" reruns only the loose lattice of 10⁶)."""
    parts = []
    for state, by_n in prov.items():
        first = next(iter(by_n.values()))
        commits = sorted({p["commit"][:10] + (" (dirty)" if p.get("dirty") else "") for p in by_n.values()})
        dates = sorted(p["date"] for p in by_n.values())
        parts.append(f"*{state}* N = {', '.join(str(n) for n in sorted(by_n))}: commit {', '.join(commits)}, {first['compiler']}, "
                     f"`{first['flags']}`, CPU {first['cpu']}, {dates[0]}" + (f" to {dates[-1]}" if dates[-1] != dates[0] else ""))
    return "; ".join(parts) + "."


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=pathlib.Path)
    ap.add_argument("-o", "--output", type=pathlib.Path)
    a = ap.parse_args(argv)
    df, paired, costs, prov = read(a.folder)
    if df.empty:
        print(f"summarise_fast.py: no bench_settled_<N>.json or bench_loose_<N>.json in {a.folder}", file=sys.stderr)
        return 1
    df["state order"] = df.state.map({"settled": 0, "loose": 1})
    df = df.sort_values(["state order", "N", "variant", "threads"])
    one = df[df.threads == 1].set_index(["state", "N", "variant"])["us_per_particle_step"]
    df["speed-up vs 1 thread"] = [one.get((st, n, v), float("nan")) / u for st, n, v, u in zip(df.state, df.N, df.variant, df.us_per_particle_step)]
    arrays1 = df[(df.variant == "arrays") & (df.threads == 1)].set_index(["state", "N"])["us_per_particle_step"]
    df["vs arrays (1 thread)"] = [u / arrays1.get((st, n), float("nan")) for st, n, u in zip(df.state, df.N, df.us_per_particle_step)]

    out = [
        "# fast against N, threads and the canonical order",
        "",
        "Produced by scripts/bench_fast.sh and analysis/summarise_fast.py; " + provenance_line(prov),
        "Median µs per particle-step over interleaved repetitions (min–max); phases as % of the step."
        " *settled*: the dense bed settled 0.4 s by fast, then continued with the walls at rest; *loose*: the"
        " bed's loose lattice at t = 0 (no contacts yet: 10⁶ grains would take hours to settle). Every thread count of an N"
        " ran in one `demmat bench`, interleaved with the variants; the speed-up is the ratio of the medians,"
        " the paired speed-up the median (min–max) over the repetitions of each repetition's own ratio, its"
        " two samples taken side by side. `arrays` is not threaded and runs once, at 1 thread.",
        "",
        "| state | N | variant | threads | µs/particle-step | min–max | speed-up vs 1 thread | paired speed-up | vs arrays (1 thread) | predict | search | forces | correct | contacts/particle | bytes/particle |",
        "|---|---:|---|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    pair = paired.set_index(["state", "N", "variant", "threads"]) if not paired.empty else None
    for _, r in df.iterrows():
        key = (r["state"], r["N"], r["variant"], r["threads"])
        p = f"{pair.loc[key, 'paired']:.2f} ({pair.loc[key, 'paired_min']:.2f}–{pair.loc[key, 'paired_max']:.2f})" \
            if pair is not None and key in pair.index else ""
        threads = f"{r['threads']}" + (f" (ran on {r['ran_on']})" if r["ran_on"] != r["threads"] else "")
        out.append(f"| {r['state']} | {r['N']} | {r['variant']} | {threads} | {r['us_per_particle_step']:.3f} | {r['min_us']:.3f}–{r['max_us']:.3f} | "
                   f"{r['speed-up vs 1 thread']:.2f} | {p} | {r['vs arrays (1 thread)']:.2f} | {r['predict %']:.0f} % | {r['search %']:.0f} % | "
                   f"{r['forces %']:.0f} % | {r['correct %']:.0f} % | {r['contacts/particle']:.2f} | {r['bytes/particle']:.0f} |")
    if not costs.empty:
        med = df.set_index(["state", "N", "variant", "threads"])["us_per_particle_step"]
        out += ["", "## What the canonical order costs", "",
                "fast (bit-identical for any thread count) over fast_unordered (the same code without the canonical order):"
                " the ratio of the medians above, and the paired ratio, the median (min–max) over the repetitions of each"
                " repetition's own ratio, its two samples taken side by side in one interleaved round.", "",
                "| state | N | threads | fast / fast_unordered (medians) | paired |", "|---|---:|---:|---:|---|"]
        costs["state order"] = costs.state.map({"settled": 0, "loose": 1})
        for _, c in costs.sort_values(["state order", "N", "threads"]).iterrows():
            key = (c["state"], c["N"])
            ratio = med.get(key + ("fast", c["threads"]), float("nan")) / med.get(key + ("fast_unordered", c["threads"]), float("nan"))
            out.append(f"| {c['state']} | {c['N']} | {c['threads']} | {ratio:.3f} | {c['paired']:.3f} ({c['paired_min']:.3f}–{c['paired_max']:.3f}) |")
    million = a.folder / "million.json"
    mtime = a.folder / "million_time.txt"
    if million.exists() and mtime.exists():
        m = results.load(str(million)).meta
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
    emit(text, a.output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
