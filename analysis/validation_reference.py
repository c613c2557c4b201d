"""References for the Chung & Ooi (2011) tests that do not come from the suite's C++ (docs/validation.md).

Nothing here imports or calls the C++; from a run's row it takes only the inputs (material constants, radii,
speeds, the named e and mu, the law's name and its k_t choice) and derives everything else itself:
  hertz(...)            Hertz's closed forms: peak overlap, peak force, contact time (Johnson, Contact
                        Mechanics, 1985, section 11.4)
  limits(...)           rigid-body oblique impact with Coulomb friction (Maw, Barber & Fawcett, Wear 38 (1976)
                        101-114; Thornton, Cummins & Cleary, Powder Technol. 233 (2013) 30-46): the gross-slip
                        outcome (J_t = mu*J_n) and the no-slip one (the contact points leave with no slip)
  integrate(...)        an independent integration of the law (physics.md section 2 for "paper", section 9 for
                        the others) for the two bodies in the x-z plane: classical RK4 at a fixed step from the
                        first touch to separation, the stretch advanced as an ODE (d xi/dt = u_t) and capped at
                        the Coulomb force after each step (an operator split, not the suite's per-evaluation
                        update), its own solve of the damping for the named e.
"""
import math

GAMMA_INTEGRAL = 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)  # int_0^1 (1 - x^(5/2))^(-1/2) dx


def sphere(radius, density):
    m = density * 4.0 / 3.0 * math.pi * radius ** 3
    return m, 0.4 * m * radius * radius


def hertz(mstar, rstar, estar, v):
    """Elastic normal impact at relative speed v: (peak overlap, peak force, contact time)."""
    h = (15.0 * mstar * v * v / (16.0 * estar * math.sqrt(rstar))) ** 0.4
    return h, 4.0 / 3.0 * estar * math.sqrt(rstar) * h ** 1.5, 2.0 * h / v * GAMMA_INTEGRAL


# ---- damping for a named restitution ---------------------------------------------------------------------

def _rebound(acc, step=2e-4):
    """-h' at the end of h'' = acc(h, h'), h(0) = 0, h'(0) = 1 (RK4; a different step from the suite's)."""
    h, v = 0.0, 1.0
    for _ in range(int(400 / step)):
        k1h, k1v = v, acc(h, v)
        k2h, k2v = v + 0.5 * step * k1v, acc(h + 0.5 * step * k1h, v + 0.5 * step * k1v)
        k3h, k3v = v + 0.5 * step * k2v, acc(h + 0.5 * step * k2h, v + 0.5 * step * k2v)
        k4h, k4v = v + step * k3v, acc(h + step * k3h, v + step * k3v)
        h_new = h + step / 6.0 * (k1h + 2 * k2h + 2 * k3h + k4h)
        v_new = v + step / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if h_new <= 0.0 and v_new < 0.0:
            return -v_new
        h, v = h_new, v_new
    return 0.0


def _solve(rebound_of, e):
    if e >= 1.0:
        return 0.0
    lo, hi = 0.0, 1.0
    while rebound_of(hi) > e:
        lo, hi = hi, 2.0 * hi
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rebound_of(mid) > e else (lo, mid)
    return 0.5 * (lo + hi)


_cache = {}


def damping_constant(kind, e):
    """Dimensionless damping for e: g = gamma_n*t0 of the paper's viscous law (F_d = gamma_n*m*u_n), or alpha of
    eta_n = alpha*sqrt(m*k_n); in units h0 = (m* v^2/K)^(2/5), t0 = h0/v both laws lose every other constant."""
    key = (kind, e)
    if key not in _cache:
        if kind == "viscous":
            acc = lambda g: (lambda h, v: -max(0.0, max(h, 0.0) ** 1.5 + g * v))
        else:
            acc = lambda a: (lambda h, v: -max(0.0, max(h, 0.0) ** 1.5 + a * max(h, 0.0) ** 0.25 * v))
        _cache[key] = _solve(lambda c: _rebound(acc(c)), e)
    return _cache[key]


# ---- the two bodies -------------------------------------------------------------------------------------

class Case:
    """One run's inputs (a row of test<K>.csv): bodies, law, initial velocities in the x-z plane."""

    def __init__(self, row):
        self.test = int(row["test"])
        self.law = row["law"]
        self.r1, self.r2 = float(row["radius1"]), float(row["radius2"])
        rho, self.E, self.nu = float(row["density"]), float(row["young"]), float(row["poisson"])
        self.mu, self.e = float(row["mu"]), float(row["restitution"])
        self.value = float(row["value"])
        self.wall = self.r2 == 0.0
        self.m1, self.i1 = sphere(self.r1, rho)
        one = (1.0 - self.nu ** 2) / self.E
        shear = 2.0 * (2.0 - self.nu) * (1.0 + self.nu) / self.E  # Mindlin: 1/G* = sum of these
        if self.wall:
            self.m2 = self.i2 = math.inf
            self.mstar, self.rstar, self.estar, self.g8 = self.m1, self.r1, 1.0 / one, 8.0 / shear  # rigid plane
        else:
            self.m2, self.i2 = sphere(self.r2, rho)
            self.mstar = self.m1 * self.m2 / (self.m1 + self.m2)
            self.rstar = self.r1 * self.r2 / (self.r1 + self.r2)
            self.estar, self.g8 = 1.0 / (2 * one), 8.0 / (2 * shear)
        speed = {1: 10.0, 2: 0.2, 3: 3.9, 4: 3.9, 5: 5.0, 6: 0.2, 7: 0.2, 8: 0.2}[self.test]
        # Body 1's velocity (x, z) and spin about y; body 2's (pairs). Plane: normal +z, body 1 moving down.
        self.v1, self.w1, self.v2, self.w2 = [0.0, 0.0], 0.0, [0.0, 0.0], 0.0
        if self.wall:
            vt = {4: speed * math.sin(math.radians(self.value)), 5: self.value}.get(self.test, 0.0)
            vn = speed * math.cos(math.radians(self.value)) if self.test == 4 else speed
            self.v1 = [vt, -vn]
            self.w1 = self.value if self.test == 6 else 0.0
            self.vn = vn
        else:
            self.v1 = [speed, 0.0]
            self.v2 = [0.0 if self.test == 8 else -speed, 0.0]
            self.w1 = self.value if self.test in (7, 8) else 0.0
            self.w2 = -self.value if self.test == 7 else 0.0
            self.vn = self.v1[0] - self.v2[0]
        self.hmax, self.fmax, self.tc = hertz(self.mstar, self.rstar, self.estar, self.vn)
        self.K = 4.0 / 3.0 * self.estar * math.sqrt(self.rstar)
        t0 = (self.mstar * self.vn ** 2 / self.K) ** 0.4 / self.vn
        self.gamma_t = 0.0  # the section 9 laws' scenes leave gamma_t at 0 (their tangential force is the spring's)
        if self.law == "paper":
            self.gamma_n = damping_constant("viscous", self.e) / t0
            self.gamma_t = 10.0 / self.tc if self.mu > 0 else 0.0  # the scene's choice (docs/validation.md)
        else:
            self.alpha = damping_constant("alpha", self.e)
        self.kt = self.g8 * math.sqrt(self.rstar * self.hmax)  # linear_history's choice: Mindlin's k_t at the peak

    # The initial slip of the contact points (tangential: x on the plane, z for a pair) and the compliance
    # B = sum of 1/m + R^2/I: a tangential impulse J changes the slip by -J*B.
    def slip(self, v1, w1, v2, w2):
        if self.wall:
            return v1[0] - self.r1 * w1
        return v1[1] - v2[1] - self.r1 * w1 - self.r2 * w2

    def compliance(self):
        b = 1.0 / self.m1 + self.r1 ** 2 / self.i1
        return b if self.wall else b + 1.0 / self.m2 + self.r2 ** 2 / self.i2


def outcome(case, v1, w1, v2, w2, vn_out):
    """The quantities the figures and the table use, from the final velocities."""
    t = 0 if case.wall else 1  # tangential component index
    s = case.slip(v1, w1, v2, w2)
    vt0 = case.v1[t] - (case.v2[t] if not case.wall else 0.0)
    vt1 = v1[t] - (v2[t] if not case.wall else 0.0)
    return {"normal_restitution": vn_out / case.vn,
            "tangential_restitution": vt1 / vt0 if abs(vt0) > 0 else math.nan,
            "tangential_velocity": v1[t],
            "spin": w1,
            "rebound_angle_deg": math.degrees(math.atan2(s, vn_out))}


def limits(case):
    """Rigid-body outcomes: (gross slip, no slip), each a dict as outcome(), and whether gross slip holds."""
    t = 0 if case.wall else 1
    s0 = case.slip(case.v1, case.w1, case.v2, case.w2)
    jn = case.mstar * (1.0 + case.e) * case.vn
    sign = 1.0 if s0 >= 0 else -1.0
    out = []
    for jt in (case.mu * jn, abs(s0) / case.compliance()):
        v1, v2 = list(case.v1), list(case.v2)
        v1[t] -= sign * jt / case.m1
        w1 = case.w1 + sign * jt * case.r1 / case.i1
        w2 = case.w2
        if not case.wall:
            v2[t] += sign * jt / case.m2
            w2 = case.w2 + sign * jt * case.r2 / case.i2
        out.append(outcome(case, v1, w1, v2, w2, case.e * case.vn))
    gross = case.mu * jn * case.compliance() < abs(s0)
    return out[0], out[1], gross


def integrate(case, per_tc=4000, keep=False):
    """The law for the two bodies from first touch to separation. Returns outcome() plus contact_time,
    peak_overlap, peak_force (and samples: (t, h, F_n) from the touch, when keep)."""
    dt = case.tc / per_tc
    r1, r2 = case.r1, case.r2
    # State: body 1 (x, z, vx, vz, w), body 2 (x, z, vx, vz, w), stretch (xi_x, xi_z). Start at touch.
    if case.wall:
        y = [0.0, r1, case.v1[0], case.v1[1], case.w1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    else:
        y = [-r1, 0.0, case.v1[0], case.v1[1], case.w1, r2, 0.0, case.v2[0], case.v2[1], case.w2, 0.0, 0.0]
    history = case.law in ("linear_history", "mindlin")

    def contact(y):
        """Force on body 1 (fx, fz), torques on 1 and 2, F_n, h, u_t, n, cap, kt."""
        if case.wall:
            n = (0.0, -1.0)
            h = r1 - y[1]
        else:
            dx, dz = y[5] - y[0], y[6] - y[1]
            d = math.hypot(dx, dz)
            n = (dx / d, dz / d)
            h = r1 + r2 - d
        if h <= 0.0:
            return None
        d1 = ((r1 - h / 2) * n[0], (r1 - h / 2) * n[1])
        # omega (about y) x r in the x-z plane: w*(r_z, -r_x)
        ux = y[2] + y[4] * d1[1]
        uz = y[3] - y[4] * d1[0]
        if not case.wall:
            d2 = (-(r2 - h / 2) * n[0], -(r2 - h / 2) * n[1])
            ux -= y[7] + y[9] * d2[1]
            uz -= y[8] - y[9] * d2[0]
        un = ux * n[0] + uz * n[1]
        utx, utz = ux - un * n[0], uz - un * n[1]
        a = math.sqrt(case.rstar * h)
        if case.law == "paper":
            eta = case.gamma_n * case.mstar
        else:
            eta = case.alpha * math.sqrt(case.mstar * case.K / math.sqrt(case.rstar) * a)  # k_n = (4/3)E* a
        fn = max(0.0, case.K * h ** 1.5 + eta * un)
        cap = case.mu * fn
        kt = case.g8 * a if case.law == "mindlin" else case.kt
        if history:
            ftx, ftz = -kt * y[10], -kt * y[11]
            f = math.hypot(ftx, ftz)
            if f > cap:
                ftx, ftz = ftx * cap / f, ftz * cap / f
        else:
            ut = math.hypot(utx, utz)
            ft = min(cap, case.gamma_t * case.mstar * ut)
            ftx, ftz = (-ft * utx / ut, -ft * utz / ut) if ut > 0 else (0.0, 0.0)
        fx, fz = -fn * n[0] + ftx, -fn * n[1] + ftz
        t1 = d1[1] * ftx - d1[0] * ftz  # (r x F)_y = r_z F_x - r_x F_z
        t2 = 0.0 if case.wall else (d2[1] * (-ftx) - d2[0] * (-ftz))
        return fx, fz, t1, t2, fn, h, (utx, utz), n, cap, kt

    def rhs(y):
        c = contact(y)
        dy = [y[2], y[3], 0.0, 0.0, 0.0, y[7], y[8], 0.0, 0.0, 0.0, 0.0, 0.0]
        if c is None:
            return dy
        fx, fz, t1, t2, _, _, ut, _, _, _ = c
        dy[2], dy[3], dy[4] = fx / case.m1, fz / case.m1, t1 / case.i1
        if not case.wall:
            dy[7], dy[8], dy[9] = -fx / case.m2, -fz / case.m2, t2 / case.i2
        if history:
            dy[10], dy[11] = ut
        return dy

    t, peak_h, peak_f, touched = 0.0, 0.0, 0.0, False
    samples = []
    # The energy a held stretch gains or loses when its stiffness changes (mindlin's k_t = 8G*a follows the
    # overlap; the stretch is not rescaled): the integral of |xi|^2/2 dk_t over the contact.
    stiffness_work, kt_prev = 0.0, 0.0
    for _ in range(100 * per_tc):
        k1 = rhs(y)
        k2 = rhs([a + 0.5 * dt * b for a, b in zip(y, k1)])
        k3 = rhs([a + 0.5 * dt * b for a, b in zip(y, k2)])
        k4 = rhs([a + dt * b for a, b in zip(y, k3)])
        y = [a + dt / 6.0 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(y, k1, k2, k3, k4)]
        t += dt
        c = contact(y)
        if c is None:
            if touched:
                break
            continue
        touched = True
        _, _, _, _, fn, h, _, n, cap, kt = c
        samples.append((t, h, fn))
        if history:
            stiffness_work += 0.5 * (y[10] ** 2 + y[11] ** 2) * (kt - kt_prev)
            kt_prev = kt
        if history:  # the stretch kept in the tangent plane (length kept) and at the Coulomb cap
            xn = y[10] * n[0] + y[11] * n[1]
            px, pz = y[10] - xn * n[0], y[11] - xn * n[1]
            length, plen = math.hypot(y[10], y[11]), math.hypot(px, pz)
            y[10], y[11] = (px * length / plen, pz * length / plen) if plen > 0 else (0.0, 0.0)
            f = kt * math.hypot(y[10], y[11])
            if f > cap and f > 0:
                y[10], y[11] = y[10] * cap / f, y[11] * cap / f
    # Separation: back along the straight flight to h = 0.
    if case.wall:
        h_end, hd_end = r1 - y[1], -y[3]
    else:
        dx, dz = y[5] - y[0], y[6] - y[1]
        d = math.hypot(dx, dz)
        h_end, hd_end = r1 + r2 - d, -((y[7] - y[2]) * dx + (y[8] - y[3]) * dz) / d
    res = outcome(case, [y[2], y[3]], y[4], [y[7], y[8]], y[9], -hd_end)
    res["contact_time"] = t - h_end / hd_end
    res["stiffness_work"] = stiffness_work
    peak_h, peak_f = _peak([s[1] for s in samples]), _peak([s[2] for s in samples])
    res.update(peak_overlap=peak_h, peak_force=peak_f)
    if keep:
        res["samples"] = samples
    return res


def _peak(ys):
    k = max(range(len(ys)), key=lambda i: ys[i])
    if 0 < k < len(ys) - 1:
        y0, y1, y2 = ys[k - 1], ys[k], ys[k + 1]
        c = y2 - 2 * y1 + y0
        if c < 0:
            return y1 - (y2 - y0) ** 2 / (8 * c)
    return ys[k]
