"""Every result file the suite writes, read into tidy pandas tables, and what the figures share.

One loader for every schema, so that no script parses a result file of its own:
  demmat bench --json   (app/main.cpp cmd_bench)        kind "bench"
  demmat_mpi bench/run --json (app/mpi_main.cpp)        kind "mpi": one row per (rank, phase), with the
                        rank's particles, ghosts, messages and bytes per step
  demmat run --json     (app/main.cpp cmd_run)          kind "run"
  Google Benchmark JSON (bench/bench_suite.cpp, bench/bench_features.cpp): the label of each benchmark is
                        a JSON object, its counters the measurements; provenance as a "provenance"
                        block at the top (older files: demmat_* strings in the context, "dirty": "false")
                                                                                     kind "gbench"
  results/peers/bench_peers.json (analysis/plot_peers.py bench)                      kind "peers"
  demmat_stability JSON (bench/stability_study.cpp)                                 kind "stability"
  demmat_accuracy JSON + the CSV beside it (bench/accuracy_study.cpp)                kind "accuracy"
  callgrind_<v>.json (analysis/callgrind_phases.py)                                  kind "callgrind"
  demmat_validation validation.json + the test<K>.csv beside it (bench/validation_study.cpp) kind "validation"

Timing tables are tidy: one row per (sample, phase) with the columns variant, threads, N, phase,
repetition, seconds (per step), sample (the id of the timed run the row belongs to), and whatever else
identifies or describes the sample (state, family, search, counters...); `wide` turns them back into one
row per sample. Provenance is normalised: the same keys whatever the schema, "dirty" a bool.

The figures share: one colour and marker per variant (STYLE), a provenance footer wrapped to the
figure's width, legends outside the axes, and an atomic save (atomic_io).
"""
import json
import sys
import os
import textwrap
from dataclasses import dataclass, field

import pandas as pd

from atomic_io import atomic_write

PHASES = ["predict", "search", "forces", "correct"]
# The paper's figures and claims (data/paper.json at the repository's root).
PAPER_JSON = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "data", "paper.json"))


@dataclass
class Result:
    kind: str                 # see the module's docstring
    path: str
    provenance: dict          # commit, dirty (bool), compiler, flags, build_type, cpu, host, date, ...
    table: pd.DataFrame       # tidy; timing kinds: variant, threads, N, phase, repetition, seconds, sample, ...
    meta: dict = field(default_factory=dict)  # the rest of the file (scene, steps, settings, references...)


# ---- provenance ------------------------------------------------------------------------------------------

def normalise_provenance(raw, context=None):
    """The same keys for every schema; "dirty" a bool (Google Benchmark's context holds it as a string)."""
    p = dict(raw or {})
    d = p.get("dirty", False)
    p["dirty"] = d if isinstance(d, bool) else str(d).strip().lower() in ("true", "1", "yes")
    if context:
        p["host_cpus"] = context.get("num_cpus")
        p["mhz_per_cpu"] = context.get("mhz_per_cpu")
    return p


def provenance_line(p):
    """One line for Markdown: commit (dirty), compiler, flags, CPU, date."""
    return (f"commit {str(p.get('commit', '?'))[:10]}{' (dirty)' if p.get('dirty') else ''}, {p.get('compiler', '?')}, "
            f"`{p.get('flags', '')}`, CPU {p.get('cpu', '?')}" + (f" ({p['host_cpus']} CPUs)" if p.get("host_cpus") else "")
            + f", {p.get('date', '?')}")


def footer(p, *extra):
    """The figure footer: machine, compiler and flags, commit, date, then any extra parts."""
    parts = [f"{p.get('cpu', '?')}" + (f", {p['host_cpus']} CPUs" if p.get("host_cpus") else ""),
             f"{p.get('compiler', '?')} {p.get('flags', '')}".strip(),
             f"commit {str(p.get('commit', '?'))[:10]}{' (dirty)' if p.get('dirty') else ''}", str(p.get("date", ""))]
    return " · ".join(x for x in parts + [str(e) for e in extra] if x)


# ---- readers ---------------------------------------------------------------------------------------------

def load(path):
    """Reads any result file of the suite (the kind from its content, not its name)."""
    with open(path) as f:
        raw = json.load(f)
    if "benchmarks" in raw and "context" in raw:
        return _gbench(path, raw)
    if raw.get("variant") == "mpi" and "processes" in raw:
        return _mpi(path, raw)
    if "samples" in raw and "scene" in raw:
        return _bench(path, raw)
    if "wall_seconds" in raw and "scene" in raw:
        return _run(path, raw)
    if "peers" in raw and "summary" in raw:
        df = pd.DataFrame(raw["samples"]).rename(columns={"particles": "N", "seconds_per_step": "seconds"})
        if "threads" not in df:  # files of before the thread comparison: one core per code
            df["threads"] = 1
        df["sample"] = range(len(df))
        if "phase" not in df:  # files of before the phases: the step's time only
            df["phase"] = "total"
        return Result("peers", path, normalise_provenance(raw.get("provenance")), df,
                      {k: v for k, v in raw.items() if k not in ("samples", "provenance")})
    if "rows" in raw and "mode" in raw:
        return Result("stability", path, normalise_provenance(raw["provenance"]), pd.DataFrame(raw["rows"]),
                      {k: v for k, v in raw.items() if k not in ("rows", "provenance")})
    if "rows" in raw and "references" in raw:
        csv = os.path.splitext(path)[0] + ".csv"
        table = pd.read_csv(csv) if os.path.exists(csv) else pd.DataFrame(raw["rows"])
        return Result("accuracy", path, normalise_provenance(raw["provenance"]), table,
                      {k: v for k, v in raw.items() if k not in ("rows", "provenance")})
    if "chung_ooi" in raw and "files" in raw:
        folder = os.path.dirname(path)
        runs = [pd.read_csv(os.path.join(folder, f)) for f in raw["files"] if not f.endswith("_curves.csv")]
        meta = {k: v for k, v in raw.items() if k != "provenance"}
        meta["curves"] = {f: pd.read_csv(os.path.join(folder, f)) for f in raw["files"] if f.endswith("_curves.csv")}
        return Result("validation", path, normalise_provenance(raw["provenance"]), pd.concat(runs, ignore_index=True), meta)
    if "instructions_per_particle_step" in raw:
        ip = raw["instructions_per_particle_step"]
        table = pd.DataFrame({"variant": raw["variant"], "N": raw["particles"], "phase": list(ip),
                              "instructions_per_particle_step": list(ip.values())})
        return Result("callgrind", path, normalise_provenance(raw.get("provenance")), table,
                      {k: v for k, v in raw.items() if k != "provenance"})
    raise ValueError(f"{path}: not a result file of the suite (unknown schema)")


def load_paper(path=PAPER_JSON):
    """The paper's figures and claims (data/paper.json); {} where the file is absent."""
    if not path or not os.path.exists(path):
        return {}
    with open(path) as f:
        return json.load(f)


def _bench(path, raw):
    df = pd.DataFrame(raw["samples"])
    if "threads_asked" not in df:  # older files: the count asked was the only one recorded
        df["threads_asked"] = df.get("threads", 0)
    df = df[["variant", "threads", "threads_asked", "repetition", "phase", "seconds_per_step"]]
    df = df.rename(columns={"seconds_per_step": "seconds"}).fillna({"threads": 0, "threads_asked": 0})
    df["N"] = raw["scene"]["particles"]
    # One sample per configuration asked for and repetition: `threads` is the count a variant really ran
    # on (fast runs small beds on one thread whatever is asked), so two configurations may share it.
    df["sample"] = df.groupby(["variant", "threads_asked", "repetition"], sort=False).ngroup()
    meta = {k: v for k, v in raw.items() if k not in ("samples", "provenance")}
    return Result("bench", path, normalise_provenance(raw["provenance"]),
                  df[["variant", "threads", "threads_asked", "N", "phase", "repetition", "seconds", "sample"]], meta)


MPI_PHASES = ["predict", "communicate", "search", "forces", "correct"]


def _mpi(path, raw):
    # bench: the median repetition's decomposition; run: the run's.
    dec = raw["median"] if "median" in raw else raw["decomposition"]
    rows = []
    for q in dec["ranks"]:
        for p in MPI_PHASES:
            rows.append({"variant": "mpi", "processes": raw["processes"], "threads": 1, "N": raw["scene"]["particles"],
                         "rank": q["rank"], "phase": p, "repetition": 0, "seconds": q["seconds_per_step"][p], "sample": 0,
                         "particles": q["particles"], "ghosts": q["ghosts"], "messages_per_step": q["messages_per_step"],
                         "bytes_per_step": q["bytes_per_step"], "migrants_per_step": q["migrants_per_step"]})
    meta = {k: v for k, v in raw.items() if k not in ("provenance", "samples")}
    return Result("mpi", path, normalise_provenance(raw["provenance"]), pd.DataFrame(rows), meta)


def _run(path, raw):
    sec = raw["seconds_per_step"]
    rows = [{"variant": raw["variant"], "threads": raw.get("threads", 1), "N": raw["scene"]["particles"], "phase": p,
             "repetition": 0, "seconds": sec[p]["median"] if isinstance(sec[p], dict) else sec[p], "sample": 0}
            for p in PHASES if p in sec]
    meta = {k: v for k, v in raw.items() if k != "provenance"}
    return Result("run", path, normalise_provenance(raw["provenance"]), pd.DataFrame(rows), meta)


# Counters that are phases (melted into phase/seconds) or sums of them (recomputed by wide()).
_PHASE_COUNTERS = {f"{p}_s": p for p in PHASES}
_DERIVED = {"total_s", "search_plus_forces_s"}


def _gbench(path, raw):
    ctx = raw["context"]
    # The run's own keys (sweep, settle time) as demmat_* strings in the context; the provenance block at
    # the top (older files: demmat_* strings in the context too).
    prov = normalise_provenance({**{k[len("demmat_"):]: v for k, v in ctx.items() if k.startswith("demmat_")},
                                 **raw.get("provenance", {})}, ctx)
    rows = []
    for b in raw["benchmarks"]:
        if b.get("error_occurred"):  # a benchmark that failed is said, not silently dropped
            print(f"results.py: {path}: {b.get('name')} failed: {b.get('error_message', '?')}", file=sys.stderr)
            continue
        if b.get("run_type") != "iteration" or not b.get("label"):
            continue
        row = json.loads(b["label"])  # the label's fields win over Google Benchmark's (its threads is always 1)
        if "particles" in row:
            row["N"] = row.pop("particles")
        row["repetition"] = b.get("repetition_index", 0)
        row["sample"] = len(rows)
        for k, v in b.items():
            if isinstance(v, (int, float)) and k not in row and k not in _DERIVED:
                row[k] = v
        rows.append(row)
    df = pd.DataFrame(rows)
    counters = [c for c in _PHASE_COUNTERS if c in df]
    timed = df.dropna(subset=counters, how="all") if counters else df.iloc[:0]
    tidy = timed.melt(id_vars=[c for c in df if c not in counters], value_vars=counters, var_name="phase", value_name="seconds")
    tidy["phase"] = tidy["phase"].map(_PHASE_COUNTERS)
    untimed = df[~df["sample"].isin(timed["sample"])].drop(columns=counters)  # e.g. the STREAM kernels
    table = pd.concat([tidy, untimed], ignore_index=True).sort_values(["sample", "phase"], kind="stable", na_position="first")
    for c in ("N", "threads"):
        if c in table:
            table[c] = table[c].astype("Int64")  # counts: printed without a decimal point
    meta = {"context": ctx}
    return Result("gbench", path, prov, table.reset_index(drop=True), meta)


def summary_rows(res):
    """One row per configuration of a `demmat bench` result (its "summary"): variant, the threads asked
    (a variant may run a small bed on fewer: ran_on), the median and min–max µs per particle-step, each
    phase's share of the step ("<phase> %"), contacts and bytes per particle, steps and repetitions."""
    d = res.meta
    n = d["scene"]["particles"]
    rows = []
    for s in d["summary"]:
        sec = s["seconds_per_step"]
        total = sec["total"]["median"]
        rows.append({
            "N": n, "variant": s["variant"],
            "threads": int(s.get("threads_asked", s["threads"])), "ran_on": int(s["threads"]),
            "us_per_particle_step": s["us_per_particle_step"],
            "min_us": sec["total"]["min"] / n * 1e6, "max_us": sec["total"]["max"] / n * 1e6,
            **{f"{p} %": 100.0 * sec[p]["median"] / total for p in PHASES},
            "contacts/particle": s["contacts_per_particle"], "bytes/particle": s["memory_bytes"] / n,
            "repetitions": d["repetitions"], "steps": d["steps"],
        })
    return rows


def wide(table):
    """One row per sample: each phase a column `<phase>_s`, and their sum `total_s`."""
    timed = table.dropna(subset=["phase"])
    sec = timed.pivot(index="sample", columns="phase", values="seconds")
    sec = sec[[p for p in PHASES if p in sec]]
    sec["total"] = sec.sum(axis=1, min_count=1)
    sec.columns = [f"{c}_s" for c in sec.columns]
    rest = table.drop(columns=["phase", "seconds"]).drop_duplicates("sample").set_index("sample")
    return rest.join(sec).reset_index()


def spread(df, keys, cols):
    """Median of each column per group, with <col>_min, <col>_max and the number of repetitions."""
    g = df.groupby(keys)[cols]
    out = g.median()
    lo, hi = g.min(), g.max()
    for c in cols:
        out[c + "_min"] = lo[c]
        out[c + "_max"] = hi[c]
    out["repetitions"] = g.size()
    return out.reset_index()


# ---- figures ---------------------------------------------------------------------------------------------

# One colour and marker per variant and peer, the same in every figure. Twelve series on a ten-colour
# cycle made two variants look alike; here no two share a colour or a marker. More threads: the same
# colour and marker, hollow, dashed.
STYLE = {
    "arrays": ("#1f77b4", "o"), "eigen_soa": ("#ff7f0e", "D"), "linked_list": ("#2ca02c", "^"),
    "linked_list_pool": ("#17becf", "v"), "linked_list_rebuild": ("#bcbd22", "<"), "oop": ("#d62728", "s"),
    "fast": ("#9467bd", "*"), "fast_unordered": ("#e377c2", "P"), "f90": ("#8c564b", "X"), "pascal": ("#000080", "h"),
    "lammps_native": ("#000000", "d"), "lammps": ("#000000", "p"), "liggghts": ("#7f7f7f", "H"),
}
VARIANT_ORDER = list(STYLE)


def style(variant, threads=1):
    """Keyword arguments for plot/errorbar: the variant's colour and marker; hollow and dashed at > 1 thread."""
    colour, marker = STYLE.get(variant, ("#555555", "."))
    kw = {"color": colour, "marker": marker, "linestyle": "-", "markersize": 6 if marker == "*" else 4.5}
    if threads and int(threads) > 1:
        kw.update(linestyle="--", markerfacecolor="white")
    return kw


def bar_style(variant, threads=1):
    """Keyword arguments for bar: the variant's colour; hatched at > 1 thread."""
    colour, _ = STYLE.get(variant, ("#555555", "."))
    return {"color": colour, "hatch": "//" if threads and int(threads) > 1 else None, "edgecolor": "white", "linewidth": 0.3}


def legend_outside(ax_or_fig, handles=None, labels=None, anchor=None, **kw):
    """A legend to the right of the axes (or of the figure's last axes), where it covers no data."""
    ax = ax_or_fig.axes[-1] if hasattr(ax_or_fig, "axes") and not hasattr(ax_or_fig, "plot") else ax_or_fig
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    kw.setdefault("fontsize", 7)
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=anchor or (1.02, 1.0), borderaxespad=0.0, **kw)


def n_axis(ax, ns, label="particles N"):
    """A log axis of N with a tick at each N measured (a few), labelled plainly."""
    import matplotlib.ticker as mt
    ns = sorted({int(n) for n in ns})
    ax.set_xscale("log")
    ax.set_xlabel(label)
    if len(ns) <= 8:
        ax.xaxis.set_major_locator(mt.FixedLocator(ns))
        ax.xaxis.set_minor_locator(mt.NullLocator())
        ax.xaxis.set_major_formatter(mt.FuncFormatter(lambda x, _: f"{x:,.0f}".replace(",", " ")))


def variant_key(label):
    """Sorts legend entries in STYLE's order of the variants, then by the rest of the label (threads)."""
    v = label.split()[0].rstrip(",")
    return (VARIANT_ORDER.index(v) if v in VARIANT_ORDER else len(VARIANT_ORDER), label)


def save_figure(fig, path, foot=None, dpi=150, fontsize=6.5, top=1.0):
    """Puts the footer under the axes, wrapped to the figure's width, lays out, writes atomically, closes.
    bbox_inches="tight" keeps legends placed outside the axes in the picture."""
    import matplotlib.pyplot as plt
    bottom = 0.0
    if foot:
        width_pt = fig.get_figwidth() * 72.0
        chars = max(40, int(0.95 * width_pt / (fontsize * 0.56)))
        text = "\n".join(textwrap.wrap(foot, chars))
        lines = text.count("\n") + 1
        bottom = (lines * fontsize * 1.3 + 8) / (fig.get_figheight() * 72.0)
        fig.text(0.01, 0.005, text, fontsize=fontsize, va="bottom", ha="left")
    fig.tight_layout(rect=(0, bottom, 1, top))
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png", bbox_inches="tight", pad_inches=0.08))
    plt.close(fig)


def remove_stale(path):
    """A figure this data does not make (e.g. a curve against N from one N) must not outlive its data."""
    if os.path.exists(path):
        os.unlink(path)
        return True
    return False
