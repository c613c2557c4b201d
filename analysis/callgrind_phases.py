#!/usr/bin/python3
"""Instructions per particle-step and phase from a callgrind profile of `demmat run`.

Reads `callgrind_annotate --inclusive=yes` output and takes, for each phase, the largest inclusive
count among the functions named `...::predict(long)`, `...::search()`, `...::forces()`, `...::correct()`:
the variant's override of the Variant interface, which includes everything it calls.

Usage: /usr/bin/python3 analysis/callgrind_phases.py ANNOTATE.txt RUN.json --steps K -o OUT.json
"""
import argparse
import json
import re
import sys

from atomic_io import write_text
from results import load

PATTERNS = {"predict": r"::predict\(long\)", "search": r"::search\(\)", "forces": r"::forces\(\)", "correct": r"::correct\(\)"}


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("annotate")
    ap.add_argument("run_json", help="the --json of the profiled demmat run (scene, variant, contacts)")
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("-o", "--out", required=True)
    a = ap.parse_args(argv)
    res = load(a.run_json)
    run = dict(res.meta, provenance=res.provenance)
    best = {p: 0 for p in PATTERNS}
    line_re = re.compile(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?\S*:(.*)$")
    with open(a.annotate, errors="replace") as f:
        lines = f.readlines()
    for line in lines:
        m = line_re.match(line)
        if not m:
            continue
        count, fn = int(m.group(1).replace(",", "")), m.group(2)
        for p, pat in PATTERNS.items():
            if re.search(pat, fn):
                best[p] = max(best[p], count)
    missing = [p for p, c in best.items() if c == 0]
    if missing:
        sys.exit(f"callgrind_phases.py: no function found for phase(s) {', '.join(missing)} in {a.annotate}")
    n = run["scene"]["particles"]
    out = {"variant": run["variant"], "scene": run["scene"]["name"], "particles": n, "steps": a.steps,
           "instructions": best,
           "instructions_per_particle_step": {p: c / (n * a.steps) for p, c in best.items()},
           "contacts_per_particle": run["contacts"]["per_particle"], "provenance": run["provenance"],
           "tool": "valgrind --tool=callgrind; callgrind_annotate --inclusive=yes"}
    write_text(a.out, json.dumps(out, indent=1))
    print(f"{run['variant']}: " + ", ".join(f"{p} {v:.0f}" for p, v in out["instructions_per_particle_step"].items()) + " instructions per particle-step")


if __name__ == "__main__":
    main(sys.argv[1:])
