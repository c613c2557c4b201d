"""The mpi variant's weak and strong scaling to 64–1024 nodes, modelled from what run_mpi_bench.sh measured
(docs/scaling.md says the model and why): per-rank compute t_c per particle-step (mpi at R = 1), the ghost
layer's areal density σ and the bytes per ghost (the halo measurement at R = 2), and a stated network.
Per step, on the slowest rank:
    T = t_c·(n + κ·G) + M·α + P·B/β
n particles owned, G ghosts, M messages and B bytes sent per step by the rank, P ranks per node sharing the
node's link of bandwidth β, latency α per message; κ = 1 (a ghost costs as much as an owned particle: an
upper bound, checked below against R = 2). Domains are cubes of the bed's number density n_v = σ/h.
  slabs  (variants/mpi on an R×1×1 grid): G = 2·σ·A, M = 4, A the global cross-section; needs each slab >= h thick
  bricks (variants/mpi on a 3-D grid): a cube of side L per rank, G = n_v·((L + 2h)³ − L³) (the shell the staged
         exchange fills: faces, edges and corners), M = 12 (6 neighbours, 2 messages each at a rebuild; 1 between)
Writes scaling.csv and scaling.md in --out.
Usage: mpi_scaling.py --bench bench_mpi.json --halo halo_mpi.csv --out DIR [--latency-us 1.0] [--bandwidth-gbs 25]
                      [--ranks-per-node 64]
"""
import argparse
import json
import os
import sys

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402
from atomic_io import write_text  # noqa: E402

NODES = [64, 128, 256, 512, 1024]
WEAK_PER_RANK = [10**4, 10**5]
STRONG_N = [10**7, 10**8, 10**9]


def step_time(n, ghosts, messages, bytes_, p):
    compute = p["t_c"] * (n + ghosts)  # κ = 1
    comm = messages * p["alpha"] + p["ppn"] * bytes_ / p["beta"]
    return compute, comm


def layouts(n_per_rank, n_total, ranks, p):
    """(decomposition, ghosts, messages, bytes, feasible) for one rank of a cube domain of n_total grains."""
    nv, sigma, h, b = p["n_v"], p["sigma"], p["h"], p["bytes_per_ghost"]
    side = (n_total / nv) ** (1.0 / 3.0)
    out = []
    g = 2.0 * sigma * side * side
    out.append(("slabs", g, 4, g * b, side / ranks >= h))
    lr = (n_per_rank / nv) ** (1.0 / 3.0)
    g = nv * ((lr + 2.0 * h) ** 3 - lr ** 3)
    out.append(("bricks", g, 12, g * b, lr >= h))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--halo", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--latency-us", type=float, default=1.0)
    ap.add_argument("--bandwidth-gbs", type=float, default=25.0)
    ap.add_argument("--ranks-per-node", type=int, default=64)
    a = ap.parse_args()
    with open(a.bench) as f:
        bench = json.load(f)
    summary = pd.DataFrame(bench["summary"])
    halo = pd.read_csv(a.halo)
    prov = results.normalise_provenance(bench.get("provenance"))

    # Inputs, from the largest N measured at R = 1 and 2, and the largest N of the halo measurement at R = 2.
    big = summary[summary.config == "mpi R=1"]["N"].max()
    row1 = summary[(summary.N == big) & (summary.config == "mpi R=1")].iloc[0]
    t_c = row1["median"] * 1e-6
    h2 = halo[halo.R == 2].sort_values("N").iloc[-1]
    sigma = h2["ghosts_mean"] / h2["face_area_m2"]
    h = h2["halo_m"]
    p = {"t_c": t_c, "sigma": sigma, "h": h, "n_v": sigma / h, "bytes_per_ghost": h2["bytes_per_step_mean"] / h2["ghosts_mean"],
         "alpha": a.latency_us * 1e-6, "beta": a.bandwidth_gbs * 1e9, "ppn": a.ranks_per_node}

    rows = []
    for nodes in NODES:
        ranks = nodes * a.ranks_per_node
        for n0 in WEAK_PER_RANK:
            for dec, g, m, b, ok in layouts(n0, n0 * ranks, ranks, p):
                comp, comm = step_time(n0, g, m, b, p)
                rows.append({"scaling": "weak", "decomposition": dec, "N": n0 * ranks, "nodes": nodes, "ranks": ranks,
                             "per_rank": n0, "ghosts": g, "messages": m, "bytes": b, "compute_s": comp, "comm_s": comm,
                             "step_s": comp + comm, "efficiency": t_c * n0 / (comp + comm), "feasible": ok})
        for n in STRONG_N:
            n0 = n / ranks
            for dec, g, m, b, ok in layouts(n0, n, ranks, p):
                comp, comm = step_time(n0, g, m, b, p)
                rows.append({"scaling": "strong", "decomposition": dec, "N": n, "nodes": nodes, "ranks": ranks,
                             "per_rank": n0, "ghosts": g, "messages": m, "bytes": b, "compute_s": comp, "comm_s": comm,
                             "step_s": comp + comm, "efficiency": t_c * n0 / (comp + comm), "feasible": ok})
    df = pd.DataFrame(rows).sort_values(["scaling", "decomposition", "N", "nodes"], kind="stable")
    tmp = os.path.join(a.out, "scaling.csv.tmp")
    df.to_csv(tmp, index=False)
    os.replace(tmp, os.path.join(a.out, "scaling.csv"))

    # The check against this machine: R = 2's measured compute between κ = 0 and κ = 1.
    check = []
    for n in sorted(summary[summary.config == "mpi R=2"]["N"].unique()):
        r1 = summary[(summary.N == n) & (summary.config == "mpi R=1")]
        r2 = summary[(summary.N == n) & (summary.config == "mpi R=2")]
        if r1.empty or r2.empty or "compute_s" not in r2:
            continue
        tc = r1["median"].iloc[0] * 1e-6
        lo, hi = tc * n / 2, tc * (n / 2 + r2["ghosts_mean"].iloc[0])
        got = r2["compute_s"].iloc[0]
        where = "between the bounds" if lo <= got <= hi else ("below κ = 0" if got < lo else f"{100 * (got / hi - 1):.0f} % above κ = 1")
        check.append(f"| {n} | {lo:.3e} | {hi:.3e} | {got:.3e} | {where} | {r2['communicate_s'].iloc[0]:.3e} |")
    md = ["# Modelled scaling of the mpi variant (analysis/mpi_scaling.py; the model in docs/scaling.md)", "",
          f"Inputs measured by scripts/run_mpi_bench.sh ({results.provenance_line(prov)}): t_c = {t_c * 1e6:.4f} µs per "
          f"particle-step (mpi R = 1, N = {big}); σ = {sigma:.4g} ghosts per m² of face, halo h = {h:.4g} m, "
          f"{p['bytes_per_ghost']:.1f} bytes per ghost sent (halo at R = 2, N = {int(h2['N'])}). Network: latency "
          f"{a.latency_us:g} µs per message, {a.bandwidth_gbs:g} GB/s per node shared by its {a.ranks_per_node} ranks.", "",
          "## Check against this machine (R = 2, seconds per step, slowest rank)", "",
          "| N | compute if a ghost costs nothing (κ = 0) | compute if a ghost costs an owned particle (κ = 1) | measured compute | "
          "measured against the model | measured communicate |",
          "|---|---|---|---|---|---|"] + check + ["",
          "## Weak and strong scaling", "",
          "| scaling | decomposition | N | nodes | ranks | particles per rank | ghosts per rank | step (s) | of it network (s) | efficiency | every brick at least h thick |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in df.iterrows():
        md.append(f"| {r.scaling} | {r.decomposition} | {r.N:.3g} | {r.nodes} | {r.ranks} | {r.per_rank:.3g} | {r.ghosts:.3g} | "
                  f"{r.step_s:.3e} | {r.comm_s:.3e} | {r.efficiency:.2f} | {'yes' if r.feasible else 'no'} |")
    write_text(os.path.join(a.out, "scaling.md"), "\n".join(md) + "\n")


if __name__ == "__main__":
    main()
