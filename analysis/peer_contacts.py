#!/usr/bin/python3
"""Single contacts against LAMMPS (docs/peers.md, run by scripts/run_peers.sh --diagnose).

  peer_contacts.py scene --stage TOML -o TOML
      the stage's scene (its material, walls and contact law) without gravity, with four grains that
      make one kind of contact each, in isolation: a pair meeting off-centre with spins, a grain struck by
      the moving x_max wall, and one hitting the fixed z_min wall obliquely with spin.
  peer_contacts.py compare --work DIR --versions JSON --build NAME=DEMMAT ... --out DIR
      each code's dump (DIR/<code>.dump) against LAMMPS's (DIR/lammps.dump): per grain, the largest
      difference over the frames in velocity and in R·ω (m/s); a table and a CSV in DIR_out.

In the bed, contacts are many and the trajectories separate (docs/peers.md): this check is where a code
can be compared with LAMMPS contact by contact. With every difference of physics.md §9's list removed
(the experiment build run with velocity Verlet), what is left is the order of floating-point operations.
"""
import argparse
import json
import os
import platform
import re
import subprocess
import tomllib

import numpy as np
import pandas as pd

from atomic_io import write_text
from plot_peers import read_frames

# (radius m, position relative to the domain, velocity m/s, angular velocity rad/s, what it meets).
# Positions are fractions of the domain except where a wall sets them; the grains never meet each other.
GRAINS = [
    (0.004, ("frac", 0.44, 0.44, 0.48), (0.3, 0.05, 0.0), (0.0, 0.0, 20.0), "pair (with the next)"),
    (0.005, ("offset", 1, (0.0095, 0.0025, 0.001)), (-0.3, 0.0, 0.02), (5.0, 0.0, -20.0), "pair (with the previous)"),
    (0.004, ("x_max", 0.0075, 0.22, 0.24), (0.2, 0.1, 0.05), (0.0, 10.0, 30.0), "moving x_max wall"),
    (0.0045, ("z_min", 0.001, 0.22, 0.73), (0.1, -0.05, -0.2), (15.0, 0.0, 0.0), "fixed z_min wall"),
]
STEPS, EVERY = 3000, 500
CODES = {"suite": "suite (Gear)", "suite_verlet": "suite (velocity Verlet)",
         "suite_as_lammps": "suite (velocity Verlet, LAMMPS's lever arms and half-step velocity)"}


def fmt(v):
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def cmd_scene(a):
    with open(a.stage) as f:
        text = f.read()
    s = tomllib.loads(text)
    lo, hi = s["domain"]["min"], s["domain"]["max"]
    text = re.split(r"(?m)^\[particles\]", text)[0]
    text, n = re.subn(r"(?m)^gravity = .*$", "gravity = [0, 0, 0]", text)
    if n != 1:
        raise SystemExit(f"peer_contacts.py: {a.stage}: no gravity line in [time]")
    ext = [h - l for l, h in zip(lo, hi)]
    placed = []
    for r, where, v, w, _ in GRAINS:
        kind = where[0]
        if kind == "frac":
            x = [l + f * e for l, f, e in zip(lo, where[1:], ext)]
        elif kind == "offset":
            x = [b + d for b, d in zip(placed[where[1] - 1], where[2])]
        elif kind == "x_max":  # a gap of where[1] to the wall, which comes on at the stage's speed
            x = [hi[0] - r - where[1], lo[1] + where[2] * ext[1], lo[2] + where[3] * ext[2]]
        else:  # z_min
            x = [lo[0] + where[2] * ext[0], lo[1] + where[3] * ext[1], lo[2] + r + where[1]]
        placed.append(x)
    text = text.rstrip() + "\n\n[particles]\nsource = \"list\"\n"
    for (r, _, v, w, _), x in zip(GRAINS, placed):
        text += (f"\n[[particles.particle]]\nradius = {r}\nposition = {fmt(x)}\nvelocity = {fmt(v)}\n"
                 f"angular_velocity = {fmt(w)}\n")
    write_text(a.o, text)


def largest_difference(frames_a, frames_b, radius, cols):
    """Per grain, the largest |a − b| over the frames of the given columns (scaled by radius for ω)."""
    worst = np.zeros(len(radius))
    for (sa, fa), (sb, fb) in zip(frames_a, frames_b):
        if sa != sb:
            raise SystemExit(f"peer_contacts.py: frames at steps {sa} and {sb} do not match")
        d = np.sqrt(sum((fa[c] - fb[c]) ** 2 for c in cols))
        worst = np.maximum(worst, d * radius)
    return worst


def cmd_compare(a):
    with open(a.versions) as f:
        versions = json.load(f)
    ref = list(read_frames(os.path.join(a.work, "lammps.dump")))
    radius = ref[0][1]["radius"]
    rows = []
    for code, label in CODES.items():
        path = os.path.join(a.work, f"{code}.dump")
        if not os.path.exists(path):
            continue
        frames = list(read_frames(path))
        dv = largest_difference(frames, ref, np.ones_like(radius), ["vx", "vy", "vz"])
        dw = largest_difference(frames, ref, radius, ["omegax", "omegay", "omegaz"])
        for g, (_, _, v, _, what) in enumerate(GRAINS):
            rows.append({"code": code, "grain": g + 1, "contact": what, "impact_speed": float(np.linalg.norm(v)),
                         "max_dv": dv[g], "max_r_domega": dw[g]})
    df = pd.DataFrame(rows)
    os.makedirs(a.out, exist_ok=True)
    write_text(os.path.join(a.out, "single_contacts.csv"), df.to_csv(index=False, float_format="%.3e"))
    builds, cpu = [], platform.machine()
    for spec in a.build:
        name, exe = spec.split("=", 1)
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True).stdout.split("\n")
        info = dict(line.split(" ", 1) for line in out[1:] if " " in line)
        builds.append(f"{name}: commit {info.get('commit', '?')[:10]}, {info.get('compiler', '?')}, `{info.get('flags', '?')}`")
        cpu = info.get("cpu", cpu)  # as every result names it (provenance.cpp)
    lines = ["# Single contacts: the suite against LAMMPS, contact by contact", "",
             f"Four grains, no gravity, the contact law of the physics cross-check ({versions.get('contact_law', 'the paper')}), "
             f"{STEPS} steps; each grain makes one contact in isolation. Largest difference from LAMMPS over "
             f"{STEPS // EVERY} frames, per grain: |Δv| and R·|Δω| (m/s). LAMMPS {versions.get('lammps', '?')}; "
             f"CPU {cpu}. Produced by scripts/run_peers.sh --diagnose (analysis/peer_contacts.py).", ""]
    lines += [f"- {b}" for b in builds] + [""]
    for what, col in (("velocity, max |Δv| (m/s)", "max_dv"), ("spin, max R·|Δω| (m/s)", "max_r_domega")):
        wide = df.pivot(index="code", columns="grain", values=col).reindex([c for c in CODES if c in set(df.code)])
        lines += [f"## {what}", "",
                  "| code | " + " | ".join(f"{g}: {GRAINS[g - 1][4]} ({np.linalg.norm(GRAINS[g - 1][2]):.2g} m/s)" for g in wide.columns) + " |",
                  "|---|" + "---:|" * len(wide.columns)]
        for code, r in wide.iterrows():
            lines.append(f"| {CODES[code]} | " + " | ".join(f"{x:.1e}" for x in r) + " |")
        lines.append("")
    write_text(os.path.join(a.out, "single_contacts.md"), "\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("scene")
    s.add_argument("--stage", required=True, help="a stage's scene, e.g. the compression stage of run_peers.sh")
    s.add_argument("-o", required=True)
    c = sub.add_parser("compare")
    c.add_argument("--work", required=True)
    c.add_argument("--versions", required=True)
    c.add_argument("--build", action="append", default=[], help="NAME=path of a demmat binary, for the provenance")
    c.add_argument("--out", required=True)
    a = ap.parse_args()
    {"scene": cmd_scene, "compare": cmd_compare}[a.cmd](a)


if __name__ == "__main__":
    main()
