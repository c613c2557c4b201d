"""The peer benchmark's Markdown (bench_peers.md; docs/peers.md, "Reading the results"): per thread count
and stage each code's time relative to the reference (LAMMPS built here, peers_bench.reference), the
paired ratios, the speed-up from one thread, the loose grid beside the settled bed, `fast`'s targets and
where the time goes. Reads the tables peers_bench.summarise makes."""
import math

from peers_bench import PEER_PHASES, PEERS, PHASE_TITLE, STAGE_TITLE, STAGES, TARGETS, builds_note, label


def order(variants):
    """The suite's variants first (by name), then the peers in PEERS's order."""
    return sorted(variants, key=lambda v: (PEERS.index(v) + 1 if v in PEERS else 0, v))


def timed_steps(df, stage, n):
    """The timed steps of one stage at one N, as a table cell: one number when every run had the same."""
    k = sorted(df[(df.stage == stage) & (df.particles == n)].steps.unique())
    return "/".join(str(int(v)) for v in k)


def steps_note(df):
    """What the tables' last rows, the timed steps, mean for reading one N beside another."""
    if df.steps.nunique() == 1:
        return "Every code runs the same timed steps at every N (each table's last row)."
    return ("The timed steps differ from one N to another (each table's last row): on a stage that changes as it "
            "runs (the loose grid falls and its grains collide, the compression stage is squeezed), each N covers a "
            "different stretch of it, so one N's ratios are read beside another's with that in mind (docs/peers.md, "
            "the loose grid).")


def header(ns):
    return ["| code | " + " | ".join(f"N = {n}" for n in ns) + " |", "|---|" + "---:|" * len(ns)]


def cell(m, v, n, fmt):
    r = m[(m.variant == v) & (m.particles == n)]
    return "" if r.empty else fmt(r.iloc[0])


def stage_tables(df, med, ref, versions, stage, threads, ns):
    m = med[(med.stage == stage) & (med.threads == threads)]
    if m.empty:
        return []
    fewer = lambda r: " †" if r.ran_on < r.threads else ""  # noqa: E731 (ran on fewer threads than asked)
    variants = order(m.variant.unique())
    lines = [f"### {STAGE_TITLE[stage]}", ""] + header(ns)
    for v in variants:
        lines.append(f"| {label(v, versions, threads)} | " + " | ".join(
            cell(m, v, n, lambda r: f"{r.ratio_to_lammps:.2f}{fewer(r)}") for n in ns) + " |")
    lines.append(f"| *{label(ref, versions, threads)}: µs per particle-step* | "
                 + " | ".join(cell(m, ref, n, lambda r: f"{r['median']:.3f}") for n in ns) + " |")
    lines.append("| *timed steps* | " + " | ".join(timed_steps(df, stage, n) for n in ns) + " |")
    lines += ["", "Paired: each repetition's own ratio (the code and the reference run side by side), median (min–max).", ""]
    lines += header(ns)
    for v in variants:
        if v != ref:
            lines.append(f"| {label(v, versions, threads)} | " + " | ".join(cell(m, v, n, lambda r: (
                f"{r.paired_ratio:.2f} ({r.paired_min:.2f}–{r.paired_max:.2f})" if not math.isnan(r.paired_ratio) else "")) for n in ns) + " |")
    return lines + [""]


def speed_up(med, versions, threads, ns):
    """Each threaded code's one-thread median over its median at `threads`."""
    one = med[med.threads == 1].set_index(["variant", "stage", "particles"])["median"]
    m = med[med.threads == threads]
    many = m.set_index(["variant", "stage", "particles"])["median"]
    lines = [f"### From one thread to {threads}", "",
             f"Each code's median time on one thread over its median on {threads} (> 1: faster on {threads}).", "",
             "| code | stage | " + " | ".join(f"N = {n}" for n in ns) + " |", "|---|---|" + "---:|" * len(ns)]
    for v in order(m.variant.unique()):
        for stage in [s for s in STAGES if s in set(m.stage)]:
            cells = [one.get((v, stage, n), float("nan")) / many.get((v, stage, n), float("nan")) for n in ns]
            lines.append(f"| {label(v, versions, threads)} | {STAGE_TITLE[stage]} | "
                         + " | ".join("" if math.isnan(c) else f"{c:.2f}" for c in cells) + " |")
    return lines + [""]


def per_repetition(df, select, by):
    """Per repetition, the one-thread total of the rows `select` picks, indexed by `by` and the repetition."""
    t = df[(df.phase == "total") & (df.threads == 1)]
    return t[select(t)].set_index(by + ["repetition"])["us_per_particle_step"]


def loose_beside_bed(df, versions, ns):
    """µs per particle-step of the loose grid and of the settled bed, one thread, and their paired ratio."""
    if not {"loose", "bed"} <= set(df.stage):
        return []
    lines = ["## The loose grid beside the settled bed", "",
             "µs per particle-step on one thread, median over the repetitions: loose grid / settled bed "
             "(the two stages' paired ratio, median over the repetitions).", ""] + header(ns)
    t = df[(df.phase == "total") & (df.threads == 1)]
    for v in order(t.variant.unique()):
        cells = []
        for n in ns:
            s = t[(t.variant == v) & (t.particles == n)].set_index(["stage", "repetition"])["us_per_particle_step"]
            if "loose" not in s or "bed" not in s:
                cells.append("")
                continue
            ratio = (s["loose"] / s["bed"]).dropna().median()
            cells.append(f"{s['loose'].median():.3f} / {s['bed'].median():.3f} ({ratio:.2f})")
        lines.append(f"| {label(v, versions)} | " + " | ".join(cells) + " |")
    return lines + [""]


def verdict(x, limit, strict=False):
    if math.isnan(x):
        return ""
    met = x < limit if strict else x <= limit
    return f"{x:.2f} met" if met else f"{x:.2f} missed by {100.0 * (x / limit - 1.0):.0f} %"


def targets(df, med, versions, ns):
    """`fast`'s targets (docs/variants/fast.md), each cell the paired median and met or missed."""
    if "fast" not in set(med.variant) or "lammps_native" not in set(med.code):
        return []
    ref = label("lammps_native", versions)
    lines = ["## fast's targets on this CPU", "",
             f"Each cell the median over the repetitions of a paired ratio (two runs of one repetition), against its limit. "
             f"The reference: {ref}.", "",
             "| target | stage | " + " | ".join(f"N = {n}" for n in ns) + " |", "|---|---|" + "---:|" * len(ns)]
    timed = [s for s in ("bed", "compression") if s in set(med.stage)]
    fast = med[med.variant == "fast"].set_index(["threads", "stage", "particles"])
    for stage in timed:
        cells = [verdict(fast.paired_ratio.get((1, stage, n), float("nan")), TARGETS["peer"]) for n in ns]
        lines.append(f"| fast ≤ {TARGETS['peer']}× {ref}, one core | {STAGE_TITLE[stage]} | " + " | ".join(cells) + " |")
    for stage in timed:
        f = per_repetition(df, lambda t: (t.variant == "fast") & (t.stage == stage), ["particles"])
        u = per_repetition(df, lambda t: (t.variant == "fast_unordered") & (t.stage == stage), ["particles"])
        r = (f / u).dropna()
        cells = [verdict(r[n].median() if n in r.index.get_level_values(0) else float("nan"), TARGETS["order"]) for n in ns]
        lines.append(f"| fast ≤ {TARGETS['order']:.2f}× fast_unordered, one core | {STAGE_TITLE[stage]} | " + " | ".join(cells) + " |")
    if {"loose", "bed"} <= set(df.stage):
        f = per_repetition(df, lambda t: t.variant == "fast", ["stage", "particles"])
        cells = []
        for n in ns:
            try:
                cells.append(verdict((f["loose"][n] / f["bed"][n]).dropna().median(), TARGETS["loose"]))
            except KeyError:
                cells.append("")
        lines.append(f"| fast's loose grid ≤ {TARGETS['loose']}× its settled bed, one core | per particle-step | " + " | ".join(cells) + " |")
    for t in sorted(x for x in med.threads.unique() if x > 1):
        for stage in timed:
            cells = [verdict(fast.paired_ratio.get((t, stage, n), float("nan")), TARGETS["threads"], strict=True) for n in ns]
            lines.append(f"| fast on {t} threads faster than {label('lammps_native', versions, t)} | {STAGE_TITLE[stage]} | "
                         + " | ".join(cells) + " |")
    return lines + [""]


def phase_table(phases, stage, versions):
    """µs per particle-step by each code's own phases on one stage, one thread (median over the repetitions),
    the suite's predict and correct as one row (fast does its corrector in the next step's Gear pass)."""
    p = phases[(phases.stage == stage) & (phases.threads == 1)].copy()
    if p.empty:
        return []
    p["phase"] = p.phase.replace({"correct": "predict"})
    per_rep = p.groupby(["code", "variant", "particles", "phase", "repetition"])["us_per_particle_step"].sum()
    med = per_rep.groupby(["code", "variant", "particles", "phase"]).median()
    ns = sorted(p.particles.unique())
    lines = [f"## Where the time goes: {STAGE_TITLE[stage]}", "",
             "µs per particle-step in each code's own phases on one thread (median over the repetitions). The phases do "
             "not map one to one: the walls' law is in the suite's forces and in the peers' fixes (the rest); "
             "docs/peers.md says what each phase holds.", "",
             "| code | phase | " + " | ".join(f"N = {n}" for n in ns) + " |",
             "|---|---|" + "---:|" * len(ns)]
    for v in order(p.variant.unique()):
        code = p[p.variant == v].code.iloc[0]
        for phase in (["predict", "search", "forces"] if code == "suite" else PEER_PHASES):
            cells = [med.get((code, v, n, phase), float("nan")) for n in ns]
            lines.append(f"| {label(v, versions)} | {PHASE_TITLE[phase]} | " + " | ".join("" if math.isnan(c) else f"{c:.4f}" for c in cells) + " |")
    return lines + [""]


def markdown(df, med, ref, provenance, versions):
    """The whole bench_peers.md."""
    prov = provenance or {}
    liggghts = (f"LIGGGHTS {versions['liggghts']} (Debian {versions.get('liggghts_package', '?')}). " if versions.get("liggghts") else "")
    ns = sorted(med.particles.unique())
    lines = [f"# The suite beside LAMMPS: time per step relative to {label(ref, versions)}", "",
             f"Median of {int(med.repetitions.max())} interleaved repetitions (the codes' order rotated each repetition). "
             + builds_note(versions) + " " + liggghts
             + f"Suite commit {prov.get('commit', '?')}, {prov.get('compiler', '?')}, CPU {prov.get('cpu', '')}. "
             f"Ratio < 1: faster than {label(ref, versions)} at the same thread count. Per stage, the ratio of the medians, "
             "then the paired ratios. Produced by scripts/run_peers.sh; every sample in bench_peers.json.", ""]
    if versions.get("note"):
        lines += [versions["note"], ""]
    lines += [steps_note(df), "",
              f"Contact law: {versions.get('contact_law', 'the paper' + chr(39) + 's (physics.md section 2)')}.", ""]
    for threads in sorted(med.threads.unique()):
        if threads == 1:
            lines += ["## One core", "", "Every code on one core (OMP_NUM_THREADS=1, no MPI).", ""]
        else:
            lines += [f"## {threads} threads", "",
                      f"The threaded codes on {threads} threads: the suite's threaded variants (`demmat bench --threads`) and "
                      f"LAMMPS built here with `-sf omp -pk omp {threads}` (its OPENMP package: a style with an /omp version "
                      "runs threaded, any other as on one thread; docs/peers.md). Ratios to LAMMPS OPENMP at the same threads; "
                      "† marks a run on fewer threads than asked (fast runs a bed of fewer than 3000 grains on one).", ""]
        for stage in STAGES:
            lines += stage_tables(df, med, ref, versions, stage, threads, ns)
        if threads > 1:
            lines += speed_up(med, versions, threads, ns)
    lines += loose_beside_bed(df, versions, ns)
    lines += targets(df, med, versions, ns)
    lines += phase_table(df[df.phase != "total"], "bed", versions)
    return "\n".join(lines)
