"""The report's first screen: each question answered in a few lines from the result files.

Each function adds its answer to the report (make_report.Report) under a bold label from ANSWERS, in
that order, or one line naming the script that makes the missing result. The details, the full tables
and the provenance follow in make_report.py.
"""
import glob
import os
import re

ANSWERS = (
    "Which style costs what on this machine (Figure 7)",
    "The suite beside LAMMPS",
    "What contact memory costs each style",
    "Speed against accuracy",
    "Validation (Chung & Ooi tests 1–8)",
    "mpi",
    "cuda",
)


def label(rep, k, text="", item=False):
    rep.add(("- " if item else "") + f"**{ANSWERS[k]}**" + (f": {text}" if text else ""))


def absent(rep, k, script):
    label(rep, k, f"not present; `{script}` makes it.")
    rep.add("")


def figure7(rep, stats_of):
    """Each style's whole step on the report's CPU, as µs per step and its ratio to arrays."""
    files = sorted(glob.glob(rep.path("main/bench_compression_*.json")))
    if not files:
        return absent(rep, 0, "scripts/run_main.sh")
    res, stats, names = stats_of(files[-1])
    n = res.meta["scene"]["particles"]
    label(rep, 0, f"the compression stage of {n} grains, median of {res.meta['repetitions']} interleaved repetitions; "
          f"details in [Figure 7](#figure-7-per-phase-cpu-time-per-variant-against-the-paper).")
    rep.add("", "| variant | µs per step | × arrays | search + forces | µs per particle-step |", "|---|---:|---:|---:|---:|")
    for v in names:
        sub = stats[stats.variant == v].set_index("phase")
        total = sub.loc["total", "median"]
        ratio = sub.loc["total", "ratio_to_arrays"] if "ratio_to_arrays" in sub else float("nan")
        share = sub.loc["search_plus_forces", "median"] / total
        rep.add(f"| {v} | {total * 1e6:.1f} | {ratio:.2f} | {share:.0%} | {total / n * 1e6:.3f} |")
    rep.add("")
    rep.image(f"figures/phases_compression_{n}.png", "Per-phase time per variant (Figure 7)")


def _paired_span(csv, code, stage="bed"):
    import pandas as pd
    df = pd.read_csv(csv)
    x = df[(df.variant == code) & (df.stage == stage)]
    if x.empty:
        return None
    return x.paired_ratio.min(), x.paired_ratio.max(), int(x.particles.min()), int(x.particles.max())


def lammps(rep, cpu_of):
    """fast (and every style where the full run has them) over LAMMPS, settled bed, paired ratios."""
    lines = []
    for folder in ("peers_fast", "peers_fast_xeon", "peers"):
        csv = rep.path(f"{folder}/bench_peers.csv")
        if not os.path.exists(csv):
            continue
        parts = []
        for code in (("fast", "fast_unordered") if folder != "peers" else ("arrays", "oop", "f90")):
            s = _paired_span(csv, code)
            if s:
                parts.append(f"{code} {s[0]:.2f}–{s[1]:.2f}×")
        s = _paired_span(csv, "fast") or _paired_span(csv, "arrays")
        if parts and s:
            lines.append(f"- {', '.join(parts)} LAMMPS's time (settled bed, N = {s[2]}–{s[3]}, one core each, paired "
                         f"medians; {cpu_of(folder)}; {rep.link(folder + '/bench_peers.md')})")
    if not lines:
        return absent(rep, 1, "scripts/run_peers.sh")
    label(rep, 1)
    rep.add(*lines, "")


def memory(rep):
    """Each style's time and bytes under the laws with memory, over its own under the paper's law."""
    csv = rep.path("memory_cost/table.csv")
    if not os.path.exists(csv):
        return absent(rep, 2, "scripts/run_memory_cost.sh")
    import pandas as pd
    df = pd.read_csv(csv)
    df = df[df.stage == "settled"]
    laws = [l for l in ("linear_history", "mindlin", "mindlin_sds") if l in set(df.law)]
    label(rep, 2, f"time and bytes over the style's own under the paper's law, settled bed; "
          f"{rep.link('memory_cost/table.md')}.")
    rep.add("", "| variant | " + " | ".join(f"time, {l}" for l in laws) + f" | bytes, {laws[-1]} |",
            "|---|" + "---:|" * (len(laws) + 1))
    for v, x in df.groupby("variant", sort=False):
        x = x.set_index("law")
        if not any(l in x.index for l in laws):
            continue
        cells = [f"{x.loc[l, 'time_ratio_to_paper']:.2f}" if l in x.index else "–" for l in laws]
        cells.append(f"{x.loc[laws[-1], 'bytes_ratio_to_paper']:.1f}" if laws[-1] in x.index else "–")
        rep.add(f"| {v} | " + " | ".join(cells) + " |")
    rep.add("")


def accuracy(rep):
    """The cheapest integrator and precision that meets each tolerance (recommendation.md's table)."""
    path = rep.path("accuracy/recommendation.md")
    if not os.path.exists(path):
        return absent(rep, 3, "scripts/run_accuracy.sh")
    with open(path) as f:
        rows = [l.strip().strip("|").split("|") for l in f if l.startswith("| ")]
    head = [c.strip() for c in rows[0]]
    picks = []
    for col, name in enumerate(head):
        m = re.match(r"tol ([0-9.e-]+)", name)
        if not m:
            continue
        best = None
        for r in rows[1:]:
            cell = r[col].strip() if col < len(r) else ""
            c = re.match(r"(\S+) \(([0-9.e+-]+)\)", cell)
            if c and (best is None or float(c.group(2)) < best[0]):
                best = (float(c.group(2)), f"{r[0].strip()} {r[1].strip()} at Δt = {c.group(1)}·t_c")
        picks.append(f"{m.group(1)}: {best[1]} ({best[0]:g} CPU s per simulated s)" if best else f"{m.group(1)}: none")
    label(rep, 3, "the cheapest integrator and precision within each tolerance on every two-body error — "
          + "; ".join(picks) + f" ({rep.link('accuracy/recommendation.md')}).")
    rep.add("")


def validation(rep):
    """One line per test: the judged values that pass per law."""
    rel = "validation/errors.csv"
    if not os.path.exists(rep.path(rel)):
        return absent(rep, 4, "scripts/run_validation.sh")
    import pandas as pd
    df = pd.read_csv(rep.path(rel))
    df = df[df["pass"].isin(["pass", "FAIL", "fail"])]
    label(rep, 4, f"judged values within tolerance, per law, over every variant, material and integrator "
          f"({rep.link('validation/table.md')}).")
    rep.add("")
    for test, t in df.groupby("test"):
        per_law = [f"{law} {int((x['pass'] == 'pass').sum())}/{len(x)}" for law, x in t.groupby("law")]
        rep.add(f"- test {test}: " + ", ".join(per_law))
    rep.add("")


def mpi(rep):
    csv = rep.path("mpi/bench_mpi.csv")
    if not os.path.exists(csv):
        return label(rep, 5, "not present; `scripts/run_mpi_bench.sh` makes it.", item=True)
    import pandas as pd
    df = pd.read_csv(csv)
    n = df.N.max()
    med = df[df.N == n].set_index("config")["median"]
    r1, r2 = med.get("mpi R=1"), med.get("mpi R=2")
    parts = [f"N = {n}: R = 2 is {r1 / r2:.2f}× as fast as R = 1" if r1 and r2 else f"N = {n}"]
    if r2 and "fast 2 threads" in med:
        parts.append(f"takes {r2 / med['fast 2 threads']:.2f}× the time of fast on 2 threads")
    if r2 and "lammps np=2" in med:
        parts.append(f"{r2 / med['lammps np=2']:.2f}× that of LAMMPS `mpirun -np 2`")
    label(rep, 5, ", ".join(parts) + f"; bit-identical to arrays at any R ({rep.link('mpi/bench_mpi.md')}).", item=True)


def cuda(rep):
    path = rep.path("gpu/summary.md")
    if not os.path.exists(path):
        label(rep, 6, "not present; `scripts/device_check.sh` on a GPU machine makes it.", item=True)
        return
    with open(path) as f:
        text = f.read()
    gpu = re.search(r"GPU (NVIDIA [^,]+)", text)
    same = len(re.findall(r"^- \S+: identical", text, flags=re.M))
    checks = len(re.findall(r"^- \S+: ", text, flags=re.M))
    rows = [r.split("|") for r in text.splitlines() if r.startswith("| settled |")]
    best = max((r for r in rows if r[3].strip() == "cuda"), key=lambda r: int(r[2]), default=None)
    fast = [r for r in rows if best and r[2] == best[2] and r[3].strip() == "fast"]
    speed = ", ".join(f"{r[7].strip()} faster than fast on {r[4].strip()} thread(s)" for r in fast)
    label(rep, 6, f"{same} of {checks} scenes bit for bit against arrays on {gpu.group(1) if gpu else 'the GPU'}"
          + (f"; at N = {best[2].strip()} settled, {best[5].strip()} µs per particle-step, {speed}" if best else "")
          + f" ({rep.link('gpu/summary.md')}).", item=True)
