#!/usr/bin/python3
"""The GPU device check (scripts/device_check.sh) as tables: whether cuda was bit-identical to arrays
under each contact law, and µs per particle-step of cuda, fast on every core and fast on one, per bed,
N and law, with cuda's speed-up over each, each law's time against the paper's law, and the phases;
the GPU, its driver and the host CPU the run found. The law of each file is read from the run's
runs.tsv (a file it does not list, as in a run made before the laws, is the paper's law).

Usage: /usr/bin/python3 analysis/summarise_gpu.py results/gpu [-o results/gpu/summary.md]
"""
import argparse
import pathlib
import re
import sys

from atomic_io import emit
import results

GPU_VARIANTS = ("cuda", "cuda_host")
LAWS = ("paper", "tsuji", "linear_history", "mindlin", "mindlin_sds")
LAW_LABEL = {"paper": "paper's law", "tsuji": "tsuji", "linear_history": "linear_history", "mindlin": "mindlin",
             "mindlin_sds": "mindlin + sds"}


def laws_of(folder):
    """File name -> law, from the run's runs.tsv (two tab-separated columns under a header: file, law)."""
    path = folder / "runs.tsv"
    if not path.exists():
        return {}
    lines = [l.split("\t") for l in path.read_text().splitlines()[1:] if l.strip()]
    return {f: law for f, law in lines}


def read(folder):
    """One row per bench_<state>_<N>_….json: its law, median and min–max µs per particle-step, its
    phases' shares, contacts and bytes per particle."""
    rows, prov, laws = [], {}, laws_of(folder)
    for path in sorted(folder.glob("bench_*.json")):
        m = re.match(r"bench_(settled|loose)_(\d+)_", path.name)
        if not m:
            continue
        res = results.load(str(path))
        rows += [dict(r, state=m.group(1), law=laws.get(path.name, "paper")) for r in results.summary_rows(res)]
        prov[path.name] = res.provenance
    return rows, prov


def comparisons(folder):
    """Each compare_<scene>.txt's law, stage and verdict line (demmat compare prints 'identical: ...' or
    where the first difference is)."""
    out, laws = [], laws_of(folder)
    for path in sorted(folder.glob("compare_*.txt")):
        lines = [l.strip() for l in path.read_text().splitlines() if l.strip()]
        stage = "compression stage" if path.stem.endswith("_compression") else "settling bed"
        out.append((laws.get(path.name, "paper"), stage, lines[-1] if lines else "(no output: the compare did not run)"))
    return sorted(out, key=lambda c: (LAWS.index(c[0]) if c[0] in LAWS else len(LAWS), c[1] != "settling bed"))


def device_line(folder):
    """The GPU, driver and compute capability (nvidia-smi's CSV in log.txt) and the host CPU (host.txt)."""
    gpu = ""
    log = folder / "log.txt"
    if log.exists():
        text = log.read_text().splitlines()
        for k, line in enumerate(text):
            if line.startswith("name, driver_version") and k + 1 < len(text):
                name, driver, cap, mem = (x.strip() for x in (text[k + 1].split(",") + ["", "", "", ""])[:4])
                gpu = f"GPU {name}, driver {driver}, compute capability {cap}, {mem}"
    cpu = ""
    host = folder / "host.txt"
    if host.exists():
        t = host.read_text()
        model = re.search(r"Model name:\s*(.+)", t)
        lines = t.splitlines()
        cores = lines[2].strip() if len(lines) > 2 and lines[2].strip().isdigit() else "?"
        cpu = f"host CPU {model.group(1).strip() if model else 'unknown'} ({cores} logical CPUs)"
    return "; ".join(x for x in (gpu, cpu) if x)


def law_order(law):
    return LAWS.index(law) if law in LAWS else len(LAWS)


def table(rows):
    """Per (state, N, law): each configuration's line, cuda's speed-ups over fast at 1 thread and at the
    most, and its time against the same configuration under the paper's law."""
    out = ["| bed | N | law | variant | threads | µs/particle-step | min–max | cuda's speed-up over it | × paper's law | predict | search "
           "| forces | correct | contacts/particle | bytes/particle | steps × repetitions |",
           "|---|---:|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    order = {"settled": 0, "loose": 1}
    rows = sorted(rows, key=lambda r: (order[r["state"]], r["N"], law_order(r["law"]), r["variant"] not in GPU_VARIANTS, r["variant"],
                                       -r["threads"]))
    for r in rows:
        same = [g for g in rows if g["state"] == r["state"] and g["N"] == r["N"] and g["law"] == r["law"]]
        gpu = [g for g in same if g["variant"] in GPU_VARIANTS]
        speedup = f"{r['us_per_particle_step'] / gpu[0]['us_per_particle_step']:.1f}×" if gpu and r["variant"] not in GPU_VARIANTS else ""
        paper = [g for g in rows if g["state"] == r["state"] and g["N"] == r["N"] and g["law"] == "paper" and g["variant"] == r["variant"]
                 and g["threads"] == r["threads"]]
        vs_paper = f"{r['us_per_particle_step'] / paper[0]['us_per_particle_step']:.2f}×" if paper and r["law"] != "paper" else ""
        threads = f"{r['threads']}" + (f" (ran on {r['ran_on']})" if r["ran_on"] != r["threads"] else "")
        out.append(f"| {r['state']} | {r['N']} | {LAW_LABEL.get(r['law'], r['law'])} | {r['variant']} | {threads} | {r['us_per_particle_step']:.4f} "
                   f"| {r['min_us']:.4f}–{r['max_us']:.4f} | {speedup} | {vs_paper} "
                   f"| {r['predict %']:.0f} % | {r['search %']:.0f} % | {r['forces %']:.0f} % | {r['correct %']:.0f} % | {r['contacts/particle']:.2f} "
                   f"| {r['bytes/particle']:.0f} | {r['steps']} × {r['repetitions']} |")
    return out


def verdicts(cmp):
    """Law by law: the settling bed's and the compression stage's verdicts side by side."""
    out = ["| law | settling bed | compression stage |", "|---|---|---|"]
    for law in sorted({c[0] for c in cmp}, key=law_order):
        cell = {stage: verdict for l, stage, verdict in cmp if l == law}
        out.append(f"| {LAW_LABEL.get(law, law)} | {cell.get('settling bed', '(not run)')} | {cell.get('compression stage', '(not run)')} |")
    return out


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=pathlib.Path)
    ap.add_argument("-o", "--output", type=pathlib.Path)
    a = ap.parse_args(argv)
    rows, prov = read(a.folder)
    cmp = comparisons(a.folder)
    if not rows and not cmp:
        print(f"summarise_gpu.py: no bench_*.json or compare_*.txt in {a.folder}", file=sys.stderr)
        return 1
    p = next(iter(prov.values()), {})
    out = ["# The cuda variant on a GPU", "",
           "Produced by scripts/device_check.sh on a lent GPU machine and analysis/summarise_gpu.py. "
           + device_line(a.folder) + ". "
           + (f"Built here and carried: commit {p.get('commit', '?')[:10]}{' (dirty)' if p.get('dirty') else ''}, {p.get('compiler', '?')}, "
              f"`{p.get('flags', '?')}` (the CUDA flags: build-info.txt; the PTX check: ptx-check.txt), run {p.get('date', '?')}." if p else ""),
           "", "## Bit for bit against arrays", "",
           "`demmat compare --variants cuda,arrays,cuda` under each law: the dense bed settling from its loose lattice, and its "
           "compression stage (a moving wall) from the state settled on the device under that law (its stretches included); the "
           "second cuda run checks that the device repeats itself.", ""]
    out += verdicts(cmp) if cmp else ["- no comparison ran (log.txt says why)"]
    if rows:
        out += ["", "## Time per particle-step", "",
                "Median µs per particle-step over the repetitions (min–max), each configuration its own `demmat bench`; phases as % "
                "of the step, each phase timed after the device has finished it (docs/cuda.md, Timing). *settled*: the dense bed "
                "settled on the device under each law, continued with its walls at rest (and its stretches); *loose*: the bed's loose "
                "lattice at t = 0. cuda's speed-up is the configuration's median over cuda's under the "
                "same law; × paper's law, the configuration's median over its own under the paper's law.", ""]
        out += table(rows)
    text = "\n".join(out) + "\n"
    emit(text, a.output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
