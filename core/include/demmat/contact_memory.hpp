#pragma once
// The contact laws of physics.md §9, written once: normal damping set by a coefficient of restitution
// (tsuji, restitution), a tangential spring whose stretch ξ is carried while a contact lasts
// (linear_history, mindlin), and rolling resistance with its own stretch (sds). A model (model.hpp)
// selects them with its flags restitution_damping, history and rolling, tested with `if constexpr`, so a
// law that is not asked for costs nothing; the paper's law stays in contact_law.hpp, untouched.
//
// A memory model always has the paper's other features on (rotation, friction, damping, walls, moving
// walls, polydisperse): R* and m* are computed per contact. Every branch of the law is a select, so
// the scalar form and the lanes form (lanes.hpp) are one text, bit for bit alike; the one skip (a
// spring that slides in no lane) is taken only where the selects it skips would change no lane.
#include <cmath>
#include <string>

#include "demmat/contact_law.hpp"
#include "demmat/contact_model.hpp"

namespace demmat {

struct Scene;

// Per-run constants of the §9 laws, derived once from the scene (memory_params) and used as they are.
template <class T>
struct MemoryParams {
    T alpha{};                   // η_n = α·sqrt(m*·k_n): tsuji's α(e), or α solved for e (restitution_alpha)
    T kt{};                      // linear_history: k_t, N/m
    T shear8_pp{}, shear8_pw{};  // mindlin: 8·G* (k_t = 8·G*·sqrt(R*·h)) of pairs and of wall contacts
    T ratio_t{};                 // x_γt: η_t = x_γt·η_n
    T kr{}, gamma_r{}, mu_r{};   // rolling sds: k_r (N/m), γ_r (N·s/m), μ_r
    T dt{};                      // the stretches advance by (velocity)·Δt at each force evaluation
    bool mindlin = false;        // k_t = 8·G*·a (mindlin) instead of the constant kt (linear_history)
    bool trapezoidal = false;    // the trapezoidal stretch update (physics.md §9) instead of LAMMPS's first-order one

    template <class U>
    MemoryParams<U> as() const
    {
        return {U(alpha), U(kt), U(shear8_pp), U(shear8_pw), U(ratio_t), U(kr), U(gamma_r), U(mu_r), U(dt), mindlin, trapezoidal};
    }
};

// One contact's memory: the tangential stretch ξ and the rolling stretch ξ_r (metres), zero when the
// contact starts. Keyed by its pair (lower id, higher id) or (particle id, wall index), never by a slot.
// Under the trapezoidal update each holds ζ = ξ + (Δt/2)·u, the stretch half a step on (physics.md §9).
template <class T>
struct Stretch {
    Vec3<T> t, r;
};

// The scene's constants: α (tsuji's fit, or solved for restitution), 8·G* from E and ν of particles and
// walls, the spring constants and Δt. All zero for the paper's law.
MemoryParams<double> memory_params(const Scene& scene);

// α with which a head-on Hertz impact under η_n = α·sqrt(m*·k_n) (the clip F_n >= 0 included) rebounds
// at exactly e: the rebound of this form does not depend on the impact speed, so one dimensionless
// collision fixes it (contact_memory.cpp says how it is solved and to what tolerance).
double restitution_alpha(double e);
// The rebound (outgoing over incoming normal speed) of that dimensionless collision for a given α.
double dimensionless_rebound(double alpha);
// The rebound −h' of a dimensionless head-on collision h'' = acc(h, h'), h(0) = 0, h'(0) = 1, integrated
// with classical RK4 at a fixed `step` until h returns to 0 on the way out; 0 when the contact is still
// closed at t = max_time (an overdamped creep). Shared by the restitution solve and the stability study.
template <class Acc>
double head_on_rebound(Acc&& acc, double step, double max_time = 200.0)
{
    double h = 0.0, v = 1.0;
    const auto steps = static_cast<long long>(max_time / step);
    for (long long k = 0; k < steps; ++k) {
        const double k1h = v, k1v = acc(h, v);
        const double k2h = v + 0.5 * step * k1v, k2v = acc(h + 0.5 * step * k1h, v + 0.5 * step * k1v);
        const double k3h = v + 0.5 * step * k2v, k3v = acc(h + 0.5 * step * k2h, v + 0.5 * step * k2v);
        const double k4h = v + step * k3v, k4v = acc(h + step * k3h, v + step * k3v);
        h += step / 6.0 * (k1h + 2.0 * k2h + 2.0 * k3h + k4h);
        v += step / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if (h <= 0.0 && v < 0.0) return -v;
    }
    return 0.0;
}

// Where a rebound that falls monotonically with its damping coefficient, rebound(c), reaches e: c is
// bracketed by doubling from 1 (up to 10³) and bisected until the bracket is narrower than 10⁻¹⁰·c. Solves
// restitution_alpha and the Chung & Ooi scenes' viscous γ_n alike.
template <class Rebound>
double damping_for_rebound(Rebound&& rebound, double e)
{
    double lo = 0.0, hi = 1.0;
    while (rebound(hi) > e && hi < 1e3) {
        lo = hi;
        hi *= 2.0;
    }
    while (hi - lo > 1e-10 * hi) {
        const double mid = 0.5 * (lo + hi);
        (rebound(mid) > e ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// The law as `demmat run` prints it: ContactModel::describe() and the α the run derived.
std::string describe_law(const ContactModel& law, const MemoryParams<double>& q);

// Tsuji's fit α(e) (physics.md §9), as LAMMPS's `damping tsuji` computes it.
double tsuji_alpha(double e);

namespace detail {

// The branches of the law below are selects (`cond ? a : b`, lane by lane for a pack of lanes,
// lanes.hpp), so one text serves a scalar T and a pack; S is T's scalar, the parameters' type.
template <class T>
DEMMAT_HD inline Vec3<T> select(const auto& cond, const Vec3<T>& a, const Vec3<T>& b)
{
    return {cond ? a.x : b.x, cond ? a.y : b.y, cond ? a.z : b.z};
}

// A stretch turned into the current tangent plane with its length kept (§9 step 1), when its normal
// part matters: |ξ·n|·k > 10⁻¹⁰·cap; ξ ← 0 when its projection vanishes.
template <class T, class S>
DEMMAT_HD inline Vec3<T> to_tangent_plane(const Vec3<T>& xi, const Vec3<T>& n, T k, T cap)
{
    const T zero{};
    const T xn = dot(xi, n);
    const T xn_abs = xn < zero ? -xn : xn;
    const auto turn = xn_abs * k > S(1e-10) * cap;
    const T len = lane_sqrt(dot(xi, xi));
    const Vec3<T> p = xi - xn * n;
    const T plen = lane_sqrt(dot(p, p));
    const auto some = plen > zero;
    const Vec3<T> turned = (len / (some ? plen : splat<T>(S(1)))) * p;  // the divisor 1 keeps a lane finite
    return select(turn, select(some, turned, Vec3<T>{}), xi);
}

// §9 step 3: the trial force f0 = −k·ξ − η·vel capped at `cap`, ξ set back to the stretch of the capped
// force where the contact slides (and kept where |ξ| = 0, with no force).
template <class T, class S>
DEMMAT_HD inline Vec3<T> capped(Vec3<T>& xi, const Vec3<T>& vel, T k, T eta, T cap)
{
    const T zero{};
    const Vec3<T> f0 = (-k) * xi - eta * vel;
    const T f0_abs = lane_sqrt(dot(f0, f0));
    const auto slides = f0_abs > cap;
    if (!lane_any(slides)) return f0;  // the selects below would keep ξ and f0 in every lane
    const auto stretched = dot(xi, xi) > zero;
    const Vec3<T> f = (cap / (slides ? f0_abs : splat<T>(S(1)))) * f0;
    const Vec3<T> xi_slid = (-(f + eta * vel)) / k;
    xi = select(slides, select(stretched, xi_slid, xi), xi);
    return select(slides, select(stretched, f, Vec3<T>{}), f0);
}

// §9 steps 1–3 for one spring (tangential or rolling) under LAMMPS's first-order update: ξ turned into the
// plane, advanced by vel·Δt, the force capped. Returns the force; `advance` false evaluates without moving
// the stretch on (t = 0).
template <class T, class S>
DEMMAT_HD inline Vec3<T> spring(Vec3<T>& xi, const Vec3<T>& n, const Vec3<T>& vel, T k, T eta, T cap, S dt, bool advance)
{
    xi = to_tangent_plane<T, S>(xi, n, k, cap);
    if (advance) xi = xi + splat<T>(dt) * vel;
    return capped<T, S>(xi, vel, k, eta, cap);
}

// The same spring under the trapezoidal update (physics.md §9): the store holds ζ = ξ + (Δt/2)·vel of the
// last evaluation, so ξ = ζ + (Δt/2)·vel is the trapezoidal rule; a store of exact zeros is a new contact,
// whose stretch is vel·τ, τ the time since its onset within this step (`onset`).
template <class T, class S>
DEMMAT_HD inline Vec3<T> spring_trapezoidal(Vec3<T>& zeta, const Vec3<T>& n, const Vec3<T>& vel, T k, T eta, T cap, S dt, T onset,
                                            bool advance)
{
    const T zero{};
    const T half = splat<T>(S(0.5) * dt);
    const auto fresh = (zeta.x == zero) & (zeta.y == zero) & (zeta.z == zero);
    Vec3<T> xi = to_tangent_plane<T, S>(zeta, n, k, cap);
    if (advance) xi = xi + (fresh ? onset : half) * vel;
    const Vec3<T> f = capped<T, S>(xi, vel, k, eta, cap);
    zeta = advance ? xi + half * vel : xi;
    return f;
}

// The §9 law once the geometry is known: normal direction n (from i towards the partner), overlap
// h > 0, relative velocity u at the contact point, relative spin ω_i − ω_j, R*, m*, the pair's (4/3)E*
// and 8·G*. Writes the force on i, its tangential part and the rolling torque on i (the partner's is
// minus it); advances the stretches in `s`.
template <class M, class T, class S>
DEMMAT_HD inline void memory_law(const Vec3<T>& n, T h, const Vec3<T>& u, const Vec3<T>& spin, T rstar, T mstar, S hertz, S shear8,
                       const ContactParams<S>& p, const MemoryParams<S>& q, Stretch<T>& s, bool advance, Vec3<T>& f_i,
                       Vec3<T>& f_t, Vec3<T>& t_roll)
{
    const T zero{};
    const Coefficients<T> k = coefficients(hertz, rstar, mstar, p);  // kn, γ_n·m*, γ_t·m*, as the paper's law
    T fn = k.kn * h * lane_sqrt(h);                                  // F_ne, exactly as contact_law.hpp
    const T un = dot(u, n);
    T a{};  // the contact radius sqrt(R*·h): k_n = (4/3)E*·a, Mindlin's k_t = 8·G*·a
    if constexpr (M::restitution_damping || M::history) a = lane_sqrt(rstar * h);
    T eta_n = k.cn;
    if constexpr (M::restitution_damping) eta_n = q.alpha * lane_sqrt(mstar * (hertz * a));
    fn = fn + eta_n * un;
    fn = fn < zero ? zero : fn;  // choice (§2): no attraction; the cap below is μ times this clipped F_n
    const Vec3<T> ut = u - un * n;
    // The trapezoidal update's onset: the time since h crossed zero along its tangent, τ = h/u_n, where
    // that lies within this step, else Δt (only a new contact's first evaluation uses it).
    T onset{};
    if constexpr (M::history || M::rolling)
        if (q.trapezoidal) {
            const T dt = splat<T>(q.dt);
            const auto within = un * dt > h;
            onset = within ? h / (within ? un : splat<T>(S(1))) : dt;
        }
    if constexpr (M::history) {
        const T kt = q.mindlin ? shear8 * a : splat<T>(q.kt);
        const T eta_t = q.ratio_t * eta_n, cap = p.mu * fn;
        f_t = q.trapezoidal ? spring_trapezoidal<T, S>(s.t, n, ut, kt, eta_t, cap, q.dt, onset, advance)
                            : spring<T, S>(s.t, n, ut, kt, eta_t, cap, q.dt, advance);
    } else {
        f_t = viscous_friction(ut, fn, k.ct, p.mu);
    }
    f_i = (-fn) * n + f_t;
    if constexpr (M::rolling) {
        const Vec3<T> vr = (-rstar) * cross(spin, n);  // v_r = −R*·(ω_i − ω_j) × n
        const T kr = splat<T>(q.kr), gamma_r = splat<T>(q.gamma_r), cap_r = q.mu_r * fn;
        const Vec3<T> fr = q.trapezoidal ? spring_trapezoidal<T, S>(s.r, n, vr, kr, gamma_r, cap_r, q.dt, onset, advance)
                                         : spring<T, S>(s.r, n, vr, kr, gamma_r, cap_r, q.dt, advance);
        t_roll = (-rstar) * cross(n, fr);  // T_i += −R*·(n × F_r), T_j −= the same
    }
}

// The pair law once h is known (in every lane whose result is kept).
template <class M, class T, class S>
DEMMAT_HD inline void pair_memory_law(const Vec3<T>& dx, T d, T h, const Vec3<T>& vi, const Vec3<T>& vj, const Vec3<T>& wi, const Vec3<T>& wj,
                            T ri, T rj, T mi, T mj, const ContactParams<S>& p, const MemoryParams<S>& q, Stretch<T>& s, bool advance,
                            ContactForce<T>& out)
{
    static_assert(M::rotation && M::friction && M::polydisperse, "a §9 law runs on the full model (with_law_model)");
    const Vec3<T> n = dx / d;
    const Vec3<T> di = (ri - h * S(0.5)) * n;
    const Vec3<T> dj = -((rj - h * S(0.5)) * n);
    Vec3<T> u = vi - vj;
    if constexpr (kLammpsLeverArms) u = u + cross(wi, ri * n) - cross(wj, -(rj * n));
    else u = u + cross(wi, di) - cross(wj, dj);
    Vec3<T> ft, troll;
    memory_law<M>(n, h, u, wi - wj, ri * rj / (ri + rj), mi * mj / (mi + mj), p.hertz_pp, q.shear8_pp, p, q, s, advance, out.f_i, ft,
                  troll);
    out.t_i = cross(di, ft);
    out.t_j = cross(dj, -ft);
    if constexpr (M::rolling) {
        out.t_i = out.t_i + troll;
        out.t_j = out.t_j - troll;
    }
    out.overlap = h;
}

// The wall law once h is known.
template <class M, class T, class S>
DEMMAT_HD inline void wall_memory_law(T h, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi, const Vec3<T>& normal, const Vec3<T>& vw,
                            const ContactParams<S>& p, const MemoryParams<S>& q, Stretch<T>& s, bool advance, ContactForce<T>& out)
{
    static_assert(M::rotation && M::friction && M::moving_walls, "a §9 law runs on the full model (with_law_model)");
    const Vec3<T> n = -normal;
    const Vec3<T> di = wall_lever_arm<S>(ri, h) * n;
    Vec3<T> u = vi - vw;
    u = u + cross(wi, di);
    Vec3<T> ft, troll;
    memory_law<M>(n, h, u, wi, ri, mi, p.hertz_pw, q.shear8_pw, p, q, s, advance, out.f_i, ft, troll);
    out.t_i = cross(di, ft);
    if constexpr (M::rolling) out.t_i = out.t_i + troll;
    out.overlap = h;
}

} // namespace detail

// Particle–particle contact under a §9 law, i < j by id: as particle_contact (contact_law.hpp), and the
// pair's stretches `s` carried in and out. Returns false (and leaves `s` alone) when h <= 0.
template <class M, class T>
DEMMAT_HD inline bool particle_contact_memory(const Vec3<T>& xi, const Vec3<T>& xj, const Vec3<T>& vi, const Vec3<T>& vj,
                                    const Vec3<T>& wi, const Vec3<T>& wj, T ri, T rj, T mi, T mj, const ContactParams<T>& p,
                                    const MemoryParams<T>& q, Stretch<T>& s, bool advance, ContactForce<T>& out)
{
    Vec3<T> dx;
    T d;
    const T h = detail::pair_overlap(xi, xj, ri, rj, dx, d);
    if (!(h > T(0))) return false;
    detail::pair_memory_law<M>(dx, d, h, vi, vj, wi, wj, ri, rj, mi, mj, p, q, s, advance, out);
    return true;
}

// Particle–wall contact under a §9 law: as wall_contact (contact_law.hpp), with the contact's stretches.
template <class M, class T>
DEMMAT_HD inline bool wall_contact_memory(const Vec3<T>& xi, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi, const Vec3<T>& point,
                                const Vec3<T>& normal, const Vec3<T>& vw, const ContactParams<T>& p, const MemoryParams<T>& q,
                                Stretch<T>& s, bool advance, ContactForce<T>& out)
{
    const T h = ri - dot(xi - point, normal);
    if (!(h > T(0))) return false;
    detail::wall_memory_law<M>(h, vi, wi, ri, mi, normal, vw, p, q, s, advance, out);
    return true;
}

namespace detail {
// Lanes out of contact keep their stretches and hold zeros in the force and torques (they add nothing).
template <class M, class V>
inline void keep_touching(const auto& touch, const Stretch<V>& before, Stretch<V>& s, ContactForce<V>& out)
{
    s.t = select(touch, s.t, before.t);
    s.r = select(touch, s.r, before.r);
    out.f_i = select(touch, out.f_i, Vec3<V>{});
    out.t_i = select(touch, out.t_i, Vec3<V>{});
    out.t_j = select(touch, out.t_j, Vec3<V>{});
}
} // namespace detail

// W pairs at once, one per lane of the pack V (lanes.hpp): the same law, operation for operation, so each
// lane holds the bits particle_contact_memory gives for its pair, stretches included. Returns the lanes
// in contact (h > 0); the others keep their stretches and hold zeros in f_i, t_i and t_j.
template <class M, LanePack V>
inline auto particle_contact_memory_lanes(const Vec3<V>& xi, const Vec3<V>& xj, const Vec3<V>& vi, const Vec3<V>& vj,
                                          const Vec3<V>& wi, const Vec3<V>& wj, V ri, V rj, V mi, V mj,
                                          const ContactParams<LaneScalar<V>>& p, const MemoryParams<LaneScalar<V>>& q,
                                          Stretch<V>& s, bool advance, ContactForce<V>& out)
{
    Vec3<V> dx;
    V d;
    const V h = detail::pair_overlap(xi, xj, ri, rj, dx, d);
    const auto touch = h > V{};
    const Stretch<V> before = s;
    detail::pair_memory_law<M>(dx, d, h, vi, vj, wi, wj, ri, rj, mi, mj, p, q, s, advance, out);
    detail::keep_touching<M>(touch, before, s, out);
    return touch;
}

// W particle–wall contacts at once (each lane its own particle and wall), as particle_contact_memory_lanes.
template <class M, LanePack V>
inline auto wall_contact_memory_lanes(const Vec3<V>& xi, const Vec3<V>& vi, const Vec3<V>& wi, V ri, V mi, const Vec3<V>& point,
                                      const Vec3<V>& normal, const Vec3<V>& vw, const ContactParams<LaneScalar<V>>& p,
                                      const MemoryParams<LaneScalar<V>>& q, Stretch<V>& s, bool advance, ContactForce<V>& out)
{
    const V h = ri - dot(xi - point, normal);
    const auto touch = h > V{};
    const Stretch<V> before = s;
    detail::wall_memory_law<M>(h, vi, wi, ri, mi, normal, vw, p, q, s, advance, out);
    detail::keep_touching<M>(touch, before, s, out);
    return touch;
}

} // namespace demmat
