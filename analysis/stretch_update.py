"""The stretch updates of physics.md section 9, integrated here independently of the suite's C++.

Two oblique impacts in the x-z plane, from the Chung & Ooi (2011) tests (docs/validation.md): test 4 (a
sphere onto the rigid plane at 3.9 m/s, incident angle 5-85 degrees) and test 8 (a spinning sphere onto a
larger one at rest). Each is stepped with the paper's gear5 predictor-corrector (physics.md section 3) and
one of the two stretch updates:
  first_order   LAMMPS's: xi <- rot(xi) + u_t*dt at each force evaluation, xi = 0 at the first touch;
  trapezoidal   the store holds zeta = xi + (dt/2)*u_t; xi = rot(zeta) + (dt/2)*u_t, and at a new contact
                (zeta exactly 0) xi = tau*u_t with tau = h/u_n when u_n*dt > h, else dt.
The contact starts at a fraction `phase` of a step (an arbitrary fraction of v*dt overlaps at the first
touch). The error of each rebound quantity is measured against the law integrated to convergence
(validation_reference.integrate, classical RK4 at t_c/per_tc_ref), in units of the quantity's largest
|reference| over the sweep, and its order of convergence fitted separately where the contact sticks (the
rigid-body theory's no-slip regime) and where it slides throughout.

Nothing here calls the C++: the test (tests/test_analysis.py) compares these with the suite's runs.
"""
import math

import validation_reference as ref

# The inputs of the two tests (docs/validation.md): a row as the suite's test<K>.csv holds it.
TESTS = {
    4: dict(test=4, radius1=2.5e-3, radius2=0.0, density=4000.0, young=380e9, poisson=0.23, mu=0.092, restitution=0.98,
            values=[5.0 * k for k in range(1, 18)], speed=3.9),
    8: dict(test=8, radius1=0.1, radius2=0.5, density=2700.0, young=70e9, poisson=0.33, mu=0.4, restitution=0.5,
            values=[0.2 * math.tan(math.radians(5.0 * k)) / 0.1 for k in range(1, 18)], speed=0.2),
}
QUANTITIES = ("tangential_velocity", "spin")
PHASES = tuple((k + 0.5) / 8 for k in range(8))  # where in its step the contact starts


def case_of(test, law, value, restitution=None):
    row = dict(TESTS[test], law=law, value=value)
    if restitution is not None:
        row["restitution"] = restitution
    return ref.Case(row)


class Gear5:
    """Physics.md section 3 for one degree of freedom: x, v, a, b3, b4, b5."""
    C = (3.0 / 16.0, 251.0 / 360.0, 1.0, 11.0 / 18.0, 1.0 / 6.0, 1.0 / 60.0)

    def __init__(self, x, v):
        self.y = [x, v, 0.0, 0.0, 0.0, 0.0]

    def predict(self, dt):
        x, v, a, b3, b4, b5 = self.y
        self.y = [x + dt * v + dt * dt / 2 * a + b3 + b4 + b5, v + dt * a + (3 * b3 + 4 * b4 + 5 * b5) / dt,
                  a + 2 / (dt * dt) * (3 * b3 + 6 * b4 + 10 * b5), b3 + 4 * b4 + 10 * b5, b4 + 5 * b5, b5]

    def correct(self, a_new, dt):
        da = a_new - self.y[2]
        c, h2 = self.C, dt * dt / 2
        x, v, a, b3, b4, b5 = self.y
        self.y = [x + c[0] * h2 * da, v + c[1] * dt / 2 * da, a + da, b3 + c[3] * h2 * da, b4 + c[4] * h2 * da,
                  b5 + c[5] * h2 * da]


def simulate(case, per_tc, update, phase=0.5):
    """Gear5 with the named stretch update from a gap of (2 + phase) steps of approach to separation."""
    dt = case.tc / per_tc
    r1, r2 = case.r1, case.r2
    gap = case.vn * dt * (2.0 + phase)
    if case.wall:  # plane z = 0, normal +z
        dofs = [Gear5(0.0, case.v1[0]), Gear5(r1 + gap, case.v1[1]), Gear5(0.0, case.w1)]
    else:  # along x: body 1 left of body 2
        dofs = [Gear5(-(r1 + gap / 2), case.v1[0]), Gear5(0.0, case.v1[1]), Gear5(0.0, case.w1),
                Gear5(r2 + gap / 2, case.v2[0]), Gear5(0.0, case.v2[1]), Gear5(0.0, case.w2)]
    history = case.law in ("linear_history", "mindlin")
    store = [0.0, 0.0]  # the pair's stretch (first_order) or zeta (trapezoidal); forgotten when h <= 0

    def forces():
        x1, z1 = dofs[0].y[0], dofs[1].y[0]
        vx1, vz1, w1 = (d.y[1] for d in dofs[:3])
        if case.wall:
            n, h = (0.0, -1.0), r1 - z1
        else:
            dx, dz = dofs[3].y[0] - x1, dofs[4].y[0] - z1
            d = math.hypot(dx, dz)
            n, h = (dx / d, dz / d), r1 + r2 - d
        if h <= 0.0:
            store[0] = store[1] = 0.0
            return [0.0] * len(dofs), False
        d1 = ((r1 - h / 2) * n[0], (r1 - h / 2) * n[1])
        ux, uz = vx1 + w1 * d1[1], vz1 - w1 * d1[0]
        if not case.wall:
            d2 = (-(r2 - h / 2) * n[0], -(r2 - h / 2) * n[1])
            w2 = dofs[5].y[1]
            ux -= dofs[3].y[1] + w2 * d2[1]
            uz -= dofs[4].y[1] - w2 * d2[0]
        un = ux * n[0] + uz * n[1]
        ut = (ux - un * n[0], uz - un * n[1])
        a = math.sqrt(case.rstar * h)
        eta = case.alpha * math.sqrt(case.mstar * (case.K / math.sqrt(case.rstar) * a))
        fn = max(0.0, case.K * h * math.sqrt(h) + eta * un)
        cap = case.mu * fn
        ft = (0.0, 0.0)
        if history:
            kt = case.g8 * a if case.law == "mindlin" else case.kt
            xi = list(store)
            fresh = xi[0] == 0.0 and xi[1] == 0.0
            xn = xi[0] * n[0] + xi[1] * n[1]  # turned into the tangent plane, length kept
            if abs(xn) * kt > 1e-10 * cap:
                p = (xi[0] - xn * n[0], xi[1] - xn * n[1])
                length, plen = math.hypot(*xi), math.hypot(*p)
                xi = [p[0] * length / plen, p[1] * length / plen] if plen > 0 else [0.0, 0.0]
            if update == "first_order":
                w = dt
            elif fresh:
                w = h / un if un * dt > h else dt
            else:
                w = dt / 2
            xi = [xi[0] + w * ut[0], xi[1] + w * ut[1]]
            f0 = (-kt * xi[0], -kt * xi[1])
            f0_abs = math.hypot(*f0)
            ft = f0
            if f0_abs > cap:
                if xi[0] != 0.0 or xi[1] != 0.0:
                    ft = (cap / f0_abs * f0[0], cap / f0_abs * f0[1])
                    xi = [-ft[0] / kt, -ft[1] / kt]
                else:
                    ft = (0.0, 0.0)
            if update == "trapezoidal":
                xi = [xi[0] + dt / 2 * ut[0], xi[1] + dt / 2 * ut[1]]
            store[0], store[1] = xi
        fx, fz = -fn * n[0] + ft[0], -fn * n[1] + ft[1]
        acc = [fx / case.m1, fz / case.m1, (d1[1] * ft[0] - d1[0] * ft[1]) / case.i1]
        if not case.wall:
            acc += [-fx / case.m2, -fz / case.m2, (d2[1] * (-ft[0]) - d2[0] * (-ft[1])) / case.i2]
        return acc, True

    # Stop three steps after the last in contact, as the suite's run_impact does: Gear's higher derivatives
    # still move the velocities for a few steps after the force has gone.
    touched, apart = False, 0
    for _ in range(100 * per_tc):
        for d in dofs:
            d.predict(dt)
        acc, in_contact = forces()
        for d, a in zip(dofs, acc):
            d.correct(a, dt)
        touched = touched or in_contact
        apart = 0 if in_contact else apart + touched
        if apart == 3:
            break
    if case.wall:
        vn_out = dofs[1].y[1]
        return ref.outcome(case, [dofs[0].y[1], dofs[1].y[1]], dofs[2].y[1], [0.0, 0.0], 0.0, vn_out)
    v1, v2 = [dofs[0].y[1], dofs[1].y[1]], [dofs[3].y[1], dofs[4].y[1]]
    return ref.outcome(case, v1, dofs[2].y[1], v2, dofs[5].y[1], v2[0] - v1[0])


def regime(case):
    """'slip' where the rigid-body theory slides throughout (by a quarter at least, as validation.md judges
    gross slip), 'stick' where it sticks by a quarter at least, else None (near the transition)."""
    s0 = abs(case.slip(case.v1, case.w1, case.v2, case.w2))
    limit = case.mu * case.mstar * (1.0 + case.e) * case.vn * case.compliance()
    return "slip" if s0 > 1.25 * limit else ("stick" if s0 < limit / 1.25 else None)


def references(test, law, per_tc_ref=4000, restitution=None, values=None):
    """The law integrated to convergence at every value of the test's sweep (or those given), and its own
    step error (the largest change from per_tc_ref/2, over the scale)."""
    rows, check = [], 0.0
    for value in values or TESTS[test]["values"]:
        case = case_of(test, law, value, restitution)
        fine, coarse = ref.integrate(case, per_tc_ref), ref.integrate(case, per_tc_ref // 2)
        rows.append((case, fine, coarse))
    scale = {q: max(abs(f[q]) for _, f, _ in rows) for q in QUANTITIES}
    for _, fine, coarse in rows:
        check = max(check, *(abs(fine[q] - coarse[q]) / scale[q] for q in QUANTITIES))
    return rows, scale, check


def sweep_errors(test, law, update, per_tc, refs, phases=PHASES):
    """Per value of the sweep: (value, regime, [the error of each quantity at each phase, in units of scale])."""
    rows, scale, _ = refs
    out = []
    for case, fine, _ in rows:
        errors = []
        for phase in phases:
            got = simulate(case, per_tc, update, phase)
            errors += [abs(got[q] - fine[q]) / scale[q] for q in QUANTITIES]
        out.append((case.value, regime(case), errors))
    return out


def worst(errors, regime_name):
    """The largest error over the sweep's values in the regime (nan where none is)."""
    return max((max(e) for _, r, e in errors if r == regime_name), default=math.nan)


def rms(errors, regime_name):
    """The root mean square of the errors over the values in the regime, the starts and the quantities."""
    xs = [x for _, r, e in errors if r == regime_name for x in e]
    return math.sqrt(sum(x * x for x in xs) / len(xs)) if xs else math.nan


def order(per_tcs, errors):
    """Least-squares slope of log(error) against log(dt)."""
    xs = [-math.log(p) for p in per_tcs]
    ys = [math.log(max(e, 1e-300)) for e in errors]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def study(per_tcs, per_tc_ref=8000):
    """Every test x law x update x dt: the worst and the RMS error per regime."""
    rows, checks = [], []
    for test, e in CONFIGS:
        for law in ("mindlin", "linear_history"):
            refs = references(test, law, per_tc_ref, restitution=e)
            checks.append((label(test, e), law, refs[2]))
            for update in ("first_order", "trapezoidal"):
                for n in per_tcs:
                    errors = sweep_errors(test, law, update, n, refs)
                    for reg in ("stick", "slip"):
                        rows.append(dict(test=label(test, e), law=law, update=update, per_tc=n, regime=reg,
                                         worst=worst(errors, reg), rms=rms(errors, reg)))
    return rows, checks


# The tests as defined, and test 8 undamped: its e = 0.5 damping, eta_n ~ h^(1/4) at the touch, is a kink
# of the law that no stretch update removes, so the undamped run shows the update's own order.
CONFIGS = ((4, None), (8, None), (8, 1.0))


def label(test, e):
    return f"{test}" if e is None else f"{test}, e = {e:g}"


def write(out_dir, rows, checks, per_tcs):
    import csv
    import os
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "stretch_update.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fit = [n for n in per_tcs if n >= 50]
    lines = ["# The stretch updates against the law integrated to convergence", "",
             "Generated by analysis/stretch_update.py (pure Python; it never calls the suite's C++): Chung & Ooi test 4 "
             "(alumina onto the rigid plane, 5-85 degrees) and test 8 (Al alloy, a spinning sphere onto a larger one at "
             "rest; also undamped, e = 1), gear5 with each stretch update (physics.md section 9), the contact starting at 8 places within a "
             "step. Errors of the rebound tangential velocity and spin against RK4 at t_c/8000, over the quantity's "
             "largest |reference| over the sweep; worst: the largest over the regime's values, the starts and the two "
             "quantities; order: least-squares slope of log(RMS error) against log(dt) over t_c/" + str(min(fit))
             + " ... t_c/" + str(max(fit)) + ". Regimes by the rigid-body theory (docs/validation.md): stick where the "
             "slip would stop with a quarter to spare, slip where it would not; points near the transition are in neither.",
             "", "| test | law | update | regime | " + " | ".join(f"worst t_c/{n}" for n in per_tcs) + " | order (RMS) |",
             "|---|---|---|---|" + "---|" * len(per_tcs) + "---|"]
    for test in [label(t, e) for t, e in CONFIGS]:
        for law in ("mindlin", "linear_history"):
            for update in ("first_order", "trapezoidal"):
                for reg in ("stick", "slip"):
                    mine = {r["per_tc"]: r for r in rows if (r["test"], r["law"], r["update"], r["regime"]) == (test, law, update, reg)}
                    if any(math.isnan(mine[n]["worst"]) for n in per_tcs):
                        continue
                    p = order(fit, [mine[n]["rms"] for n in fit])
                    lines.append(f"| {test} | {law} | {update} | {reg} | " + " | ".join(f"{mine[n]['worst']:.2e}" for n in per_tcs)
                                 + f" | {p:.2f} |")
    lines += ["", "The reference's own step error (RK4 at t_c/8000 against t_c/4000, largest over the sweep and the "
              "quantities, over the scale):", "", "| test | law | step error |", "|---|---|---|"]
    lines += [f"| {t} | {law} | {c:.1e} |" for t, law, c in checks]
    with open(os.path.join(out_dir, "stretch_update.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    import sys
    PER_TCS = (25, 50, 100, 200, 400)
    study_rows, study_checks = study(PER_TCS)
    write(sys.argv[1] if len(sys.argv) > 1 else "results/accuracy", study_rows, study_checks, PER_TCS)
