#!/usr/bin/python3
"""The rule for negligible derivatives (physics.md §3) timed, as tables (scripts/bench_subnormal.sh):
(a) the main job's settle stage with fast and arrays, µs per step and the predictor's share, without and
with the rule; (b) every variant's µs per particle-step on the loose grid beside the settled bed's,
without and with the rule. Each ratio "with/without" is paired: taken within one repetition, where the
two builds ran one after the other, then the median (and the range) over the repetitions.

Usage: /usr/bin/python3 analysis/subnormal_table.py results/subnormal/raw [-o results/subnormal/subnormal.md]
"""
import argparse
import pathlib
import re
import sys

import pandas as pd

from atomic_io import emit
import results

BUILDS = ["before", "after"]


def read(folder):
    """Tidy rows (part, stage, variant, build, repetition, phase, seconds) and each build's provenance."""
    rows, prov = [], {}
    for path in sorted(folder.glob("*.json")):
        m = re.fullmatch(r"(settle)_(\w+?)_n\d+_(before|after)_r(\d+)\.json|bench_(loose|bed)_n\d+_(before|after)_r(\d+)\.json", path.name)
        if not m:
            continue
        res = results.load(str(path))
        if m.group(1):
            part, stage, build, rep = "settle", "settle", m.group(3), int(m.group(4))
        else:
            part, stage, build, rep = "bench", m.group(5), m.group(6), int(m.group(7))
        prov[build] = res.provenance
        # a file's own repetitions (demmat bench -r) become one sample: their median, phase by phase
        t = res.table.groupby(["variant", "phase", "N"], as_index=False)["seconds"].median()
        t = t.assign(part=part, stage=stage, build=build, repetition=rep)
        rows.append(t[["part", "stage", "variant", "build", "repetition", "phase", "seconds", "N"]])
    if not rows:
        sys.exit(f"subnormal_table.py: no result files in {folder}")
    return pd.concat(rows, ignore_index=True), prov


def paired(tot):
    """tot: seconds indexed by (variant, repetition) with columns before, after → median, min, max of after/before."""
    r = (tot["after"] / tot["before"]).dropna().groupby(level="variant")
    return r.median(), r.min(), r.max()


def fmt_ratio(med, lo, hi):
    return f"{med:.3f} ({lo:.3f}–{hi:.3f})"


def settle_table(df):
    s = df[df.part == "settle"]
    step = s.groupby(["variant", "build", "repetition"])["seconds"].sum().unstack("build")
    pred = s[s.phase == "predict"].groupby(["variant", "build", "repetition"])["seconds"].sum().unstack("build")
    share = (pred / step).groupby(level="variant").median()
    med = step.groupby(level="variant").median()
    ratio = paired(step)
    pratio = paired(pred)
    lines = ["| variant | µs/step without | µs/step with | with/without, paired | predict's share without | predict's share with | predict with/without, paired |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for v in med.index:
        lines.append(f"| {v} | {1e6 * med.loc[v, 'before']:.1f} | {1e6 * med.loc[v, 'after']:.1f} | "
                     f"{fmt_ratio(ratio[0][v], ratio[1][v], ratio[2][v])} | {100 * share.loc[v, 'before']:.0f} % | "
                     f"{100 * share.loc[v, 'after']:.0f} % | {fmt_ratio(pratio[0][v], pratio[1][v], pratio[2][v])} |")
    return lines, int(s.repetition.nunique())


def bench_table(b):
    n = b.N.iloc[0]
    tot = b.groupby(["stage", "variant", "build", "repetition"])["seconds"].sum() / n * 1e6  # µs per particle-step
    tot = tot.unstack("build")
    med = tot.groupby(level=["stage", "variant"]).median()
    lines = ["| variant | loose without | loose with | loose with/without, paired | bed without | bed with | bed with/without, paired | loose/bed without | loose/bed with |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    stages = [st for st in ("loose", "bed") if st in med.index.get_level_values("stage")]
    ratios = {st: paired(tot.loc[st]) for st in stages}

    def cells(st, v):
        """µs without, µs with, the paired ratio; dashes where the stage was not measured"""
        if st not in stages or v not in med.loc[st].index:
            return ["—", "—", "—"], None
        m, r = med.loc[st].loc[v], ratios[st]
        return [f"{m['before']:.3f}", f"{m['after']:.3f}", fmt_ratio(r[0][v], r[1][v], r[2][v])], m

    for v in med.index.get_level_values("variant").unique():
        lo, ml = cells("loose", v)
        bd, mb = cells("bed", v)
        if ml is not None and mb is not None:
            rel = [f"{ml['before'] / mb['before']:.2f}", f"{ml['after'] / mb['after']:.2f}"]
        else:
            rel = ["—", "—"]
        lines.append("| " + " | ".join([v] + lo + bd + rel) + " |")
    return lines, int(n), int(b.repetition.nunique())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("raw", type=pathlib.Path)
    ap.add_argument("-o", "--out", type=pathlib.Path)
    ap.add_argument("--note", action="append", default=[], help="a line on how this run departed from the script")
    ap.add_argument("--after-commit", help="the commit whose code a build from a working tree (dirty) was, to name beside it")
    a = ap.parse_args()
    df, prov = read(a.raw)
    out = ["# The rule for negligible derivatives: speed without and with it", "",
           "Generated by analysis/subnormal_table.py from scripts/bench_subnormal.sh. One thread; each ratio",
           "with/without is paired within a repetition (the two builds ran one after the other, their order",
           "swapped every repetition), then the median (min–max) over the repetitions.", ""]
    for b in BUILDS:
        if b in prov:
            label = "without the rule" if b == "before" else "with the rule"
            out.append(f"- {label}: {results.provenance_line(prov[b])}")
            if b == "after" and a.after_commit:
                out.append(f"  (built from the working tree whose code is that of commit {a.after_commit[:10]})")
    out += ["", "The machine was shared with other builds and runs while these were taken: read the paired ratios,",
            "not the absolute times.", ""] + [f"Note: {n}" for n in a.note] + ([""] if a.note else [])
    if (df.part == "settle").any():
        lines, reps = settle_table(df)
        n = int(df[df.part == "settle"].N.iloc[0])
        out += [f"## The main job's settle stage: the dense bed of {n} grains for 0.4 s from its loose grid ({reps} repetitions)", ""]
        out += lines + [""]
    bench = df[df.part == "bench"]
    for n in sorted(bench.N.unique()):
        lines, n, reps = bench_table(bench[bench.N == n])
        steps = max(200, -(-1000000 // n))
        out += [f"## Every variant: µs per particle-step, loose grid (t = 0) and settled bed, N = {n} ({reps} repetitions)", "",
                f"{steps} timed steps after 20 untimed, from the loose grid at t = 0 and from the bed settled for 0.4 s by the same build.", ""]
        out += lines + [""]
    emit("\n".join(out), a.out)


if __name__ == "__main__":
    main()
