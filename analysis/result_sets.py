#!/usr/bin/python3
"""The result sets under results/: which question each answers, which code it measured, and whether it
is current.

A result set is one folder of results/ written by one script. Each carries its provenance in its own
files (every JSON result names its commit, compiler, flags, CPU and date); `describe` condenses them
to one line per set. A set is *current* when the last commit that changed the code it measured is an
ancestor of (or is) the commit it measured, and it ran on the report's CPU; otherwise the report says
why it is not. A second CPU's set of a question sits beside the first with the CPU in its name
(`_xeon`), and each set's `set.json` (written by `write_set_files`) names its question and CPU.
"""
import functools
import glob
import json
import os
import re
import subprocess

from results import load

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir)

# folder: (question, command, the code it measured). The code paths are what a change must not postdate.
# The layers below the variants (common/ held them all before the layering; its history still counts).
BELOW = ["common", "core", "harness"]
CODE_ALL = BELOW + ["engines", "variants", "app"]
LANE = BELOW + ["engines/lane_engine", "engines/columns"]  # fast and the mpi ranks, beside arrays' columns
CODE_ARRAYS = BELOW + [":(exclude)common/include/demmat/soa", "engines/columns", "variants/arrays"]
SETS = {
    "main": ("Figure 7: each style phase by phase", "scripts/run_main.sh", CODE_ALL),
    "sweep_short": ("Figure 4, cell size, scaling, where the time goes", "scripts/run_main.sh --sweep", CODE_ALL),
    "sweep_million": ("the same at 10⁶ loose grains", "scripts/run_main.sh --full", CODE_ALL),
    "fast": ("fast at 1 and 2 threads, 10³–10⁶ grains", "scripts/bench_fast.sh", LANE + ["variants/fast", "variants/arrays"]),
    "fast_xeon": ("fast at 1 and 2 threads, 10³–6.4·10⁴ grains, second CPU", "scripts/bench_fast.sh --out results/fast_xeon",
                  LANE + ["variants/fast", "variants/arrays"]),
    "peers": ("every style beside LAMMPS and LIGGGHTS; the physics cross-check", "scripts/run_peers.sh", CODE_ALL + ["peers"]),
    "peers_fast": ("fast beside LAMMPS, phase by phase", "scripts/run_peers.sh --bench-only --variants fast,fast_unordered --out results/peers_fast",
                   LANE + ["variants/fast", "app", "peers"]),
    "peers_fast_xeon": ("fast beside LAMMPS built for the CPU and Debian's binary, one core and two: fast's targets; second CPU",
                        "OMP_WAIT_POLICY=PASSIVE scripts/run_peers.sh --bench-only --no-liggghts --variants fast,fast_unordered "
                        "--n \"1000 4000 16000\" --threads \"1 2\" --repetitions 3 --out results/peers_fast_xeon",
                        LANE + ["variants/fast", "app", "peers", "scripts/build_lammps.sh"]),
    "peers_mindlin": ("fast and arrays beside LAMMPS with mindlin", "scripts/run_peers.sh --contact … --out results/peers_mindlin",
                      LANE + ["variants/fast", "variants/arrays", "app", "peers"]),
    "peers_mindlin_sds": ("fast and arrays beside LAMMPS with mindlin + sds", "scripts/run_peers.sh --contact … --out results/peers_mindlin_sds",
                          LANE + ["variants/fast", "variants/arrays", "app", "peers"]),
    "memory_cost": ("what contact memory costs each style", "scripts/run_memory_cost.sh", CODE_ALL),
    "features": ("what each model feature costs", "scripts/run_features.sh", CODE_ALL + ["bench"]),
    "accuracy": ("error against CPU time: integrator × precision × Δt", "scripts/run_accuracy.sh", CODE_ARRAYS + ["bench"]),
    "accuracy/memory": ("error against CPU time of the laws with memory", "scripts/run_accuracy.sh --memory",
                        CODE_ARRAYS + ["bench"]),
    "stability": ("the largest stable Δt", "scripts/run_stability.sh", CODE_ARRAYS + ["bench"]),
    "validation": ("Chung & Ooi tests 1–8", "scripts/run_validation.sh", CODE_ALL + ["analysis/validation_reference.py"]),
    "mpi": ("the mpi variant beside fast and LAMMPS", "scripts/run_mpi_bench.sh", LANE + ["variants/mpi", "variants/fast", "app"]),
    "subnormal": ("what the rule for negligible derivatives saves: settle stage, loose grid beside settled bed",
                  "scripts/bench_subnormal.sh --before DIR --after DIR", CODE_ALL),
    "gpu": ("the cuda variant on a GPU", "scripts/device_check.sh", LANE + ["variants/cuda", "variants/fast", "app"]),
}


def describe(root, folder):
    """The set's provenance from its result files: commits (full), CPUs, compilers, dates."""
    prov = {"commits": set(), "cpus": set(), "compilers": set(), "dates": set(), "dirty": False}
    for path in sorted(glob.glob(os.path.join(root, folder, "**", "*.json"), recursive=True)):
        inner = os.path.relpath(os.path.dirname(path), root).replace(os.sep, "/")
        if os.path.basename(path) == "set.json" or (inner != folder and inner in SETS):
            continue  # a set's own file, or a set of its own inside this one
        try:
            p = load(path).provenance
        except (ValueError, KeyError):
            continue  # not a result file
        prov["commits"].add(str(p.get("commit", "?")))
        prov["cpus"].add(str(p.get("cpu", "?")))
        prov["compilers"].add(str(p.get("compiler", "?")))
        prov["dates"].add(str(p.get("date", "?"))[:10])
        prov["dirty"] |= bool(p.get("dirty"))
    return prov if prov["commits"] else None


def _git(repo, *args):
    try:
        r = subprocess.run(["git", "-C", repo, *args], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return r


COMMENT = re.compile(r"\s*(//|#|\*|/\*|!|\{|\(\*|$)")  # C++, CMake/shell/Python, Fortran, Pascal, blank


def _last_change(repo, paths, limit):
    head = _git(repo, "rev-parse", "HEAD")
    return _last_change_at(repo, head.stdout.strip() if head else None, paths, limit)


@functools.lru_cache(maxsize=None)
def _last_change_at(repo, head, paths, limit):  # keyed by HEAD: a new commit is a new question
    return last_change(repo, list(paths), limit)


def last_change(repo, paths, limit=400):
    """The last commit of HEAD that changed a line of code (not only comments or blank lines) in paths,
    or None (no git, or no such paths)."""
    try:
        proc = subprocess.Popen(["git", "-C", repo, "log", "-p", "-U0", "-M", "--format=@@commit %H", "HEAD", "--", *paths],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, errors="replace")
    except OSError:
        return None
    found, commit, seen = None, None, 0
    for line in proc.stdout:
        if line.startswith("@@commit "):
            commit, seen = line.split()[1], seen + 1
            if seen > limit:
                break
        elif line[:1] in "+-" and not line.startswith(("+++", "---")) and not COMMENT.match(line[1:]):
            found = commit
            break
    proc.kill()
    proc.wait()
    return found


def measured_after(repo, change, commit):
    """True when change is an ancestor of commit (or is it); None when git cannot tell."""
    if change is None or commit in ("?", "None", ""):
        return None
    r = _git(repo, "merge-base", "--is-ancestor", change, commit)
    if r is None or r.returncode not in (0, 1):
        return None
    return r.returncode == 0


def status(root, folder, prov, report_cpu, repo):
    """'current', or why not: older than the code, another CPU, a dirty tree, or unchecked."""
    why = []
    paths = SETS.get(folder, ("", "", CODE_ALL))[2]
    change = _last_change(repo, tuple(paths), 400)
    after = [measured_after(repo, change, c) for c in sorted(prov["commits"])]
    if any(a is False for a in after):
        why.append(f"older than the code it measured (changed at {change[:10]})")
    elif any(a is None for a in after):
        why.append("age not checked (no git history of its commit)")
    if report_cpu and prov["cpus"] != {report_cpu}:
        why.append("another CPU")
    if prov["dirty"]:
        why.append("a modified tree")
    return "current" if not why else "; ".join(why)


def sets(root, report_cpu, repo=None):
    """(folder, question, command, provenance, status) of every set present, in SETS order, then any other."""
    repo = repo or REPO
    present = [d for d in SETS if os.path.isdir(os.path.join(root, d))]
    present += sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d)) and d not in SETS
                      and describe(root, d))
    out = []
    for d in present:
        prov = describe(root, d)
        if prov is None:
            continue
        question, command, _ = SETS.get(d, ("(a set no script names)", "?", CODE_ALL))
        out.append((d, question, command, prov, status(root, d, prov, report_cpu, repo)))
    return out


def write_set_files(root, described):
    """results/<set>/set.json: the question, the command, the CPU, the commits, compilers and dates (not the
    status, which changes with the code, not with the set)."""
    from atomic_io import write_text
    for folder, question, command, prov, _ in described:
        doc = {"question": question, "command": command, "cpu": sorted(prov["cpus"]),
               "commits": sorted(c[:10] for c in prov["commits"]), "compiler": sorted(prov["compilers"]),
               "dates": sorted(prov["dates"])}
        write_text(os.path.join(root, folder, "set.json"), json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
