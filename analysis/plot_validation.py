"""The Chung & Ooi (2011) validation (docs/validation.md): the runs of demmat_validation against references
that do not come from the suite's C++ (analysis/validation_reference.py), as an error table and figures.

Usage: /usr/bin/python3 analysis/plot_validation.py results/validation/validation.json \
           [--out results/validation] [--reference-per-tc 4000]
Writes into --out: table.md (test x law x quantity: the suite's worst value, the reference, the error, the
tolerance, pass/fail), integrators.md (tests 1 and 4: the integrator's error beside the law's), energy.md
(kinetic energy out over in, tests 4 and 5), errors.csv (every run and quantity), reference_check.md (the
reference's own step error) and test<K>.png.
"""
import argparse
import math
import os
import sys

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import validation_reference as vr  # noqa: E402
from atomic_io import write_text  # noqa: E402
from results import load, footer, provenance_line, save_figure, style  # noqa: E402

# Tolerances, stated before the runs were judged (docs/validation.md says why each is what it is).
TOL_NORMAL = 1e-3       # relative: contact time, peak overlap, peak force against Hertz and against the law
TOL_RESTITUTION = 5e-3  # absolute: e_n against the named e and against the law
TOL_TANGENTIAL = 2e-2   # of the quantity's scale in the sweep: tangential velocity, spin, rebound angle
GROSS_MARGIN = 1.25     # a point counts as gross slip when its slip exceeds the slip friction can stop by this factor
QUANTITIES = {1: ["contact_time", "peak_overlap", "peak_force", "normal_restitution"],
              2: ["contact_time", "peak_overlap", "peak_force", "normal_restitution"],
              3: ["normal_restitution"]}
TANGENTIAL = ["tangential_velocity", "spin", "rebound_angle_deg", "normal_restitution", "energy_ratio"]
MAIN = dict(integrator="gear5", per_tc=200)


def kinetic(c, v1, w1, v2, w2):
    e = 0.5 * c.m1 * (v1[0] ** 2 + v1[1] ** 2) + 0.5 * c.i1 * w1 ** 2
    if not c.wall:
        e += 0.5 * c.m2 * (v2[0] ** 2 + v2[1] ** 2) + 0.5 * c.i2 * w2 ** 2
    return e


def suite_outcome(c, row):
    v1, v2 = [row.v1x, row.v1z], [row.v2x, row.v2z]
    o = vr.outcome(c, v1, row.w1y, v2, row.w2y, row.normal_restitution * c.vn)
    o.update(contact_time=row.contact_time, peak_overlap=row.peak_overlap, peak_force=row.peak_force,
             energy_ratio=kinetic(c, v1, row.w1y, v2, row.w2y) / kinetic(c, c.v1, c.w1, c.v2, c.w2))
    return o


def references(d, per_tc):
    """Per distinct (test, material, law, value): the law's integration, the limits, Hertz."""
    refs = {}
    for _, row in d.drop_duplicates(["test", "material", "law", "value"]).iterrows():
        c = vr.Case(row)
        law = vr.integrate(c, per_tc)
        gross, noslip, is_gross = vr.limits(c)
        refs[(row.test, row.material, row.law, row.value)] = dict(case=c, law=law, gross=gross, noslip=noslip, is_gross=is_gross,
                                                                  e_in=kinetic(c, c.v1, c.w1, c.v2, c.w2))
    return refs


def judge(d, refs):
    """One row per run and quantity: the suite's value, each reference that applies, error, tolerance."""
    out = []
    for _, row in d.iterrows():
        r = refs[(row.test, row.material, row.law, row.value)]
        c, s = r["case"], suite_outcome(r["case"], row)
        base = dict(test=row.test, material=row.material, law=row.law, variant=row.variant, integrator=row.integrator,
                    per_tc=row.per_tc, value=row.value)
        qs = QUANTITIES.get(row.test, TANGENTIAL)
        for q in qs:
            cands = []
            if q in ("contact_time", "peak_overlap", "peak_force"):
                h = dict(zip(["peak_overlap", "peak_force", "contact_time"], vr.hertz(c.mstar, c.rstar, c.estar, c.vn)))
                cands.append(("Hertz closed form", h[q], "rel", TOL_NORMAL))
                cands.append(("law, Python integration", r["law"][q], "rel", TOL_NORMAL))
            elif q == "normal_restitution":
                cands.append(("named e", c.e, "abs", TOL_RESTITUTION))
                cands.append(("law, Python integration", r["law"][q], "abs", TOL_RESTITUTION))
            elif q == "energy_ratio":
                cands.append(("none: kinetic energy out / in", None, "info", None))
            else:
                cands.append(("law, Python integration", r["law"][q], "scale", TOL_TANGENTIAL))
                if r["is_gross"] and abs(c.slip(c.v1, c.w1, c.v2, c.w2)) > GROSS_MARGIN * c.mu * c.mstar * (1 + c.e) * c.vn * c.compliance():
                    cands.append(("gross-slip limit (rigid body)", r["gross"][q], "scale", TOL_TANGENTIAL))
                elif not r["is_gross"]:
                    cands.append(("no-slip limit (rigid body)", r["noslip"][q], "scale-info", TOL_TANGENTIAL))
                    if row.law == "paper":  # the history-free law against a tangentially compliant one where it sticks
                        mind = refs.get((row.test, row.material, "mindlin", row.value))
                        if mind:
                            cands.append(("tangentially compliant law (Python mindlin)", mind["law"][q], "expected", TOL_TANGENTIAL))
            for ref, val, kind, tol in cands:
                out.append(dict(base, quantity=q, suite=s[q], reference=ref, ref_value=val, kind=kind, tol=tol))
    e = pd.DataFrame(out)
    # Scales: the largest |reference| of the quantity over the test, material and law (floor for angles near 0).
    e["scale"] = e.groupby(["test", "material", "law", "quantity"])["ref_value"].transform(lambda x: x.abs().max())
    def err(r):
        if r.kind == "info" or r.ref_value is None or (isinstance(r.ref_value, float) and math.isnan(r.ref_value)):
            return math.nan
        diff = abs(r.suite - r.ref_value)
        if r.kind == "rel":
            return diff / abs(r.ref_value)
        if r.kind == "abs":
            return diff
        return diff / r.scale if r.scale > 0 else diff
    e["error"] = e.apply(err, axis=1)
    e["pass"] = [("info" if k in ("info", "scale-info") else
                  (("differs (no tangential spring)" if er > t else "agrees") if k == "expected" else ("pass" if er <= t else "FAIL")))
                 for k, er, t in zip(e.kind, e.error, e.tol)]
    return e


def table(e, prov):
    m = e[(e.integrator == MAIN["integrator"]) & (e.per_tc == MAIN["per_tc"])]
    lines = ["# Chung & Ooi (2011) tests 1–8: the suite against independent references",
             "", "Generated by analysis/plot_validation.py from results/validation/validation.json; "
             f"{provenance_line(prov)}. Δt = t_c/{MAIN['per_tc']}, {MAIN['integrator']}. Each line is the worst run of the "
             "sweep (both materials, every variant that ran); errors: 'rel' relative, 'abs' absolute, 'scale' over the "
             "largest |reference| of the sweep. 'info': shown, not judged (docs/validation.md says why).", "",
             "| test | law | quantity | reference | runs | worst: suite | reference | error | tolerance | result |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for (t, law, q, ref), g in m.groupby(["test", "law", "quantity", "reference"], sort=False):
        if g.error.notna().any():
            w = g.loc[g.error.idxmax()]
            res = g["pass"].iloc[0] if g["pass"].nunique() == 1 else f"FAIL ({(g['pass'] == 'FAIL').sum()} of {len(g)})"
            tol = f"{w.tol:g} ({w.kind})" if w.tol == w.tol and w.tol is not None else ""
            lines.append(f"| {t} | {law} | {q} | {ref} | {len(g)} | {w.suite:.6g} | {w.ref_value:.6g} | {w.error:.2e} | {tol} | {res} |")
        else:
            lines.append(f"| {t} | {law} | {q} | {ref} | {len(g)} | max {g.suite.max():.6g}, min {g.suite.min():.6g} | | | | info |")
    return "\n".join(lines) + "\n"


def energy_table(e, refs, prov):
    """Kinetic energy out over in for the elastic oblique tests: what the tangential spring keeps or loses."""
    m = e[(e.quantity == "energy_ratio") & (e.integrator == MAIN["integrator"]) & (e.per_tc == MAIN["per_tc"]) & (e.variant == "arrays")]
    lines = ["# Kinetic energy out over in (tests 4 and 5)", "", f"Generated by analysis/plot_validation.py; {provenance_line(prov)}. "
             "Test 5 is elastic (e = 1) and test 4 nearly (e = 0.98, so at most e² of the normal part survives); the tangential "
             "springs are undamped. Δt = t_c/200, gear5, arrays.", ""]
    lines += ["The last column is a property of the mindlin law itself (from the Python integration): the energy that a held "
              "stretch gains while k_t = 8G*a grows on loading and loses while it shrinks on unloading, the integral of "
              "|ξ|²/2·dk_t over the contact, over the kinetic energy in (zero for linear_history, whose k_t is constant).", ""]
    for (t, mat), g in m[m.test.isin([4, 5])].groupby(["test", "material"]):
        w = g.pivot_table(index="value", columns="law", values="suite")
        w["mindlin ∫|ξ|²/2·dk_t / E_in"] = [refs[(t, mat, "mindlin", v)]["law"]["stiffness_work"] / refs[(t, mat, "mindlin", v)]["e_in"]
                                          for v in w.index]
        lines += [f"## test {t}, {mat}", "", "| " + " | ".join(["value"] + list(w.columns)) + " |", "|" + "---|" * (len(w.columns) + 1)]
        lines += ["| " + " | ".join([f"{v:.4g}"] + [f"{x:.6g}" for x in w.loc[v]]) + " |" for v in w.index]
        lines.append("")
    return "\n".join(lines)


def integrator_table(e, prov):
    m = e[e.test.isin([1, 4]) & e.variant.eq("arrays") & e.reference.isin(["law, Python integration", "Hertz closed form",
                                                                          "gross-slip limit (rigid body)"])]
    lines = ["# The integrator's error beside the law's (tests 1 and 4)", "",
             f"Generated by analysis/plot_validation.py; {provenance_line(prov)}. Integrator error: the suite against the "
             "Python integration of the same law. Law error: the Python integration of the law against the physical "
             "reference (Hertz for test 1; the rigid-body gross-slip limit for test 4, at the points well inside it). "
             "Worst over the sweep and both materials; errors as in table.md.", "",
             "| test | law | integrator | Δt | quantity | integrator error | law error |", "|---|---|---|---|---|---|---|"]
    for (t, law, integ, per_tc, q), g in m.groupby(["test", "law", "integrator", "per_tc", "quantity"]):
        ie = g[g.reference == "law, Python integration"].error.max()
        phys = g[g.reference != "law, Python integration"]
        if phys.empty or not (ie == ie):
            continue
        # The law's own error: its integration (the reference) against the physical reference, same points.
        le = phys.apply(lambda r: abs(r.law_value - r.ref_value) / (abs(r.ref_value) if r.kind == "rel" else r.scale), axis=1).max()
        lines.append(f"| {t} | {law} | {integ} | t_c/{per_tc:g} | {q} | {ie:.2e} | {le:.2e} |")
    return "\n".join(lines) + "\n"


# ---- figures ---------------------------------------------------------------------------------------------

LAW_COLOUR = {"paper": "#d62728", "linear_history": "#1f77b4", "mindlin": "#2ca02c", "restitution": "#9467bd"}
X_LABEL = {4: "incident angle (degrees)", 5: "tangential speed (m/s)", 6: "initial spin (rad/s)", 7: "initial spin (rad/s)",
           8: "initial spin of the small sphere (rad/s)"}


def figures(res, refs, out, prov):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = res.table
    main = d[(d.integrator == MAIN["integrator"]) & (d.per_tc == MAIN["per_tc"])]
    foot = footer(prov, "Chung & Ooi (2011); references: analysis/validation_reference.py")
    for k in (1, 2):
        cur = res.meta["curves"].get(f"test{k}_curves.csv")
        if cur is None:
            continue
        mats = list(dict.fromkeys(main[main.test == k].material))
        fig, axes = plt.subplots(1, len(mats), figsize=(4.2 * len(mats), 3.4), squeeze=False)
        for ax, mat in zip(axes[0], mats):
            row = main[(main.test == k) & (main.material == mat)].iloc[0]
            c = refs[(row.test, row.material, row.law, row.value)]["case"]
            h, f, tc = vr.hertz(c.mstar, c.rstar, c.estar, c.vn)
            for law in dict.fromkeys(cur.law):
                s = cur[(cur.material == mat) & (cur.law == law) & (cur.variant == "arrays") & (cur.integrator == "gear5") & (cur.per_tc == 200)]
                t_touch = -s.overlap.iloc[0] / c.vn  # the straight approach from the first sample
                s = s[s.overlap > 0]
                ax.plot((s.t - t_touch) * 1e6, s.normal_force / 1e3, ".", ms=2.5, color=LAW_COLOUR.get(law), label=f"suite, {law}")
            ref = vr.integrate(c, 4000, keep=True)["samples"]
            ax.plot([x[0] * 1e6 for x in ref], [x[2] / 1e3 for x in ref], "k-", lw=0.8, label="Python integration of Hertz's law")
            ax.axhline(f / 1e3, color="k", lw=0.6, ls=":", label="Hertz F_max")
            ax.axvline(tc * 1e6, color="k", lw=0.6, ls="--", label="Hertz t_c")
            ax.set_title(f"test {k}: {mat}, Hertz t_c = {tc * 1e6:.4g} µs", fontsize=8)
            ax.set_xlabel("time (µs)")
            ax.set_ylabel("normal force (kN)")
            ax.legend(fontsize=6)
        save_figure(fig, os.path.join(out, f"test{k}.png"), foot)
    # Test 3: rebound against the named e.
    g3 = main[main.test == 3]
    if not g3.empty:
        fig, ax = plt.subplots(figsize=(4.5, 3.6))
        for (mat, law), g in g3.groupby(["material", "law"]):
            ax.plot(g.value, g.normal_restitution, "o" if mat == g3.material.iloc[0] else "s", ms=4, mfc="none",
                    color=LAW_COLOUR.get(law), label=f"{law}, {mat}")
        ax.plot([0, 1], [0, 1], "k-", lw=0.7, label="reference: the named e")
        ax.set_xlabel("named restitution e")
        ax.set_ylabel("rebound −v'_n / v_n")
        ax.legend(fontsize=6)
        save_figure(fig, os.path.join(out, "test3.png"), foot)
    for k in range(4, 9):
        gk = main[(main.test == k) & (main.variant == "arrays")]
        if gk.empty:
            continue
        panels = ["rebound_angle_deg", "tangential_velocity", "spin", "energy_ratio"]
        labels = ["contact-point rebound angle (°)", "tangential velocity after (m/s)", "spin after (rad/s)", "kinetic energy out / in"]
        if k in (4, 5):
            panels[1], labels[1] = "tangential_restitution", "tangential restitution v't / v_t"
        mats = list(dict.fromkeys(gk.material))
        fig, axes = plt.subplots(len(mats), 4, figsize=(13, 3.0 * len(mats)), squeeze=False)
        for i, mat in enumerate(mats):
            for j, (q, lab) in enumerate(zip(panels, labels)):
                ax = axes[i][j]
                for law, g in gk[gk.material == mat].groupby("law"):
                    xs, ys, ls, gs, ns = [], [], [], [], []
                    for _, row in g.iterrows():
                        r = refs[(row.test, row.material, row.law, row.value)]
                        s = suite_outcome(r["case"], row)
                        xs.append(row.value)
                        ys.append(s[q])
                        ls.append(r["law"].get(q, math.nan))
                        gs.append(r["gross"].get(q, math.nan) if r["is_gross"] else math.nan)  # each limit where it holds
                        ns.append(math.nan if r["is_gross"] else r["noslip"].get(q, math.nan))
                    ax.plot(xs, ys, "o", ms=3.5, mfc="none", color=LAW_COLOUR.get(law), label=f"suite, {law}")
                    if q != "energy_ratio":
                        ax.plot(xs, ls, "-", lw=0.8, color=LAW_COLOUR.get(law), label=f"Python, {law}")
                if q not in ("energy_ratio",):
                    ax.plot(xs, gs, "k--", lw=0.7, label="gross slip (rigid)")
                    ax.plot(xs, ns, "k:", lw=0.9, label="no slip (rigid)")
                ax.set_xlabel(X_LABEL[k])
                ax.set_ylabel(lab, fontsize=7)
                ax.set_title(f"test {k}: {mat}", fontsize=8)
                if i == 0 and j == 0:
                    ax.legend(fontsize=5.5)
        save_figure(fig, os.path.join(out, f"test{k}.png"), foot)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json")
    ap.add_argument("--out", default=None)
    ap.add_argument("--reference-per-tc", type=int, default=4000)
    a = ap.parse_args()
    res = load(a.json)
    if res.kind != "validation":
        sys.exit(f"{a.json}: not a validation.json of demmat_validation")
    out = a.out or os.path.dirname(a.json)
    d = res.table
    refs = references(d, a.reference_per_tc)
    e = judge(d, refs)
    e["law_value"] = [refs[(r.test, r.material, r.law, r.value)]["law"].get(r.quantity, math.nan) for r in e.itertuples()]
    # Every judged value of the main runs (the integrator study's are in integrators.md).
    main_rows = e[(e.integrator == MAIN["integrator"]) & (e.per_tc == MAIN["per_tc"])]
    write_text(os.path.join(out, "errors.csv"), main_rows.drop(columns=["law_value"]).to_csv(index=False, float_format="%.8g"))
    write_text(os.path.join(out, "table.md"), table(e, res.provenance))
    write_text(os.path.join(out, "integrators.md"), integrator_table(e, res.provenance))
    write_text(os.path.join(out, "energy.md"), energy_table(e, refs, res.provenance))
    # The reference's own step error: the first point of each test and law at twice the step.
    lines = ["# The Python reference's own step error", "", f"RK4 at t_c/{a.reference_per_tc} against t_c/{2 * a.reference_per_tc}, "
             "the first point of each test, material and law; largest difference over the quantities, over their scale.", "",
             "| test | material | law | largest difference |", "|---|---|---|---|"]
    seen = set()
    for key, r in refs.items():
        if key[:3] in seen:
            continue
        seen.add(key[:3])
        fine = vr.integrate(r["case"], 2 * a.reference_per_tc)
        diffs = [abs(fine[q] - r["law"][q]) / max(abs(fine[q]), 1e-300) for q in ("contact_time", "normal_restitution", "peak_overlap")]
        for q in ("tangential_velocity", "spin", "rebound_angle_deg"):
            scale = max(abs(refs[k]["law"][q]) for k in refs if k[:3] == key[:3]) or 1.0
            diffs.append(abs(fine[q] - r["law"][q]) / scale)
        lines.append(f"| {key[0]} | {key[1]} | {key[2]} | {max(diffs):.1e} |")
    write_text(os.path.join(out, "reference_check.md"), "\n".join(lines) + "\n")
    figures(res, refs, out, res.provenance)
    fails = e[e["pass"] == "FAIL"]
    print(f"{len(e)} judged values, {len(fails)} outside tolerance; wrote {out}/table.md, integrators.md, errors.csv, figures")


if __name__ == "__main__":
    main()
