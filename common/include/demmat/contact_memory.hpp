#pragma once
// The contact laws of physics.md §9, written once: normal damping set by a coefficient of restitution
// (tsuji, restitution), a tangential spring whose stretch ξ is carried while a contact lasts
// (linear_history, mindlin), and rolling resistance with its own stretch (sds). A model (model.hpp)
// selects them with its flags restitution_damping, history and rolling, tested with `if constexpr`, so a
// law that is not asked for costs nothing; the paper's law stays in contact_law.hpp, untouched.
//
// A memory model always has the paper's other features on (rotation, friction, damping, walls, moving
// walls, polydisperse): R* and m* are computed per contact. Scalar form only for now; every step of
// the law is a select or a min, so a lanes form (lanes.hpp) can follow operation for operation.
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

    template <class U>
    MemoryParams<U> as() const
    {
        return {U(alpha), U(kt), U(shear8_pp), U(shear8_pw), U(ratio_t), U(kr), U(gamma_r), U(mu_r), U(dt), mindlin};
    }
};

// One contact's memory: the tangential stretch ξ and the rolling stretch ξ_r (metres), zero when the
// contact starts. Keyed by its pair (lower id, higher id) or (particle id, wall index), never by a slot.
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

// The law as `demmat run` prints it: ContactModel::describe() and the α the run derived.
std::string describe_law(const ContactModel& law, const MemoryParams<double>& q);

// Tsuji's fit α(e) (physics.md §9), as LAMMPS's `damping tsuji` computes it.
double tsuji_alpha(double e);

namespace detail {

// A stretch turned into the current tangent plane with its length kept (§9 step 1), when its normal
// part matters: |ξ·n|·k > 10⁻¹⁰·cap.
template <class T>
inline Vec3<T> to_tangent_plane(const Vec3<T>& xi, const Vec3<T>& n, T k, T cap)
{
    const T xn = dot(xi, n);
    if (!(std::abs(xn) * k > T(1e-10) * cap)) return xi;
    const T len = std::sqrt(dot(xi, xi));
    const Vec3<T> p = xi - xn * n;
    const T plen = std::sqrt(dot(p, p));
    if (!(plen > T(0))) return Vec3<T>{};
    return (len / plen) * p;
}

// §9 steps 1–3 for one spring (tangential or rolling): ξ turned into the plane, advanced by vel·Δt, the
// trial force −k·ξ − η·vel, capped at `cap` with ξ set back to the stretch of the capped force (the
// contact slides). Returns the force; `advance` false evaluates without moving the stretch on (t = 0).
template <class T>
inline Vec3<T> spring(Vec3<T>& xi, const Vec3<T>& n, const Vec3<T>& vel, T k, T eta, T cap, T dt, bool advance)
{
    xi = to_tangent_plane(xi, n, k, cap);
    if (advance) xi = xi + dt * vel;
    const Vec3<T> f0 = (-k) * xi - eta * vel;
    const T f0_abs = std::sqrt(dot(f0, f0));
    if (!(f0_abs > cap)) return f0;
    if (!(dot(xi, xi) > T(0))) return Vec3<T>{};
    const Vec3<T> f = (cap / f0_abs) * f0;
    xi = (-(f + eta * vel)) / k;
    return f;
}

// The §9 law once the geometry is known: normal direction n (from i towards the partner), overlap
// h > 0, relative velocity u at the contact point, relative spin ω_i − ω_j, R*, m*, the pair's (4/3)E*
// and 8·G*. Writes the force on i, its tangential part and the rolling torque on i (the partner's is
// minus it); advances the stretches in `s`.
template <class M, class T>
inline void memory_law(const Vec3<T>& n, T h, const Vec3<T>& u, const Vec3<T>& spin, T rstar, T mstar, T hertz, T shear8,
                       const ContactParams<T>& p, const MemoryParams<T>& q, Stretch<T>& s, bool advance, Vec3<T>& f_i,
                       Vec3<T>& f_t, Vec3<T>& t_roll)
{
    const Coefficients<T> k = coefficients(hertz, rstar, mstar, p);  // kn, γ_n·m*, γ_t·m*, as the paper's law
    T fn = k.kn * h * std::sqrt(h);                                  // F_ne, exactly as contact_law.hpp
    const T un = dot(u, n);
    T a{};  // the contact radius sqrt(R*·h): k_n = (4/3)E*·a, Mindlin's k_t = 8·G*·a
    if constexpr (M::restitution_damping || M::history) a = std::sqrt(rstar * h);
    T eta_n = k.cn;
    if constexpr (M::restitution_damping) eta_n = q.alpha * std::sqrt(mstar * (hertz * a));
    fn = fn + eta_n * un;
    fn = fn < T(0) ? T(0) : fn;  // choice (§2): no attraction; the cap below is μ times this clipped F_n
    const Vec3<T> ut = u - un * n;
    if constexpr (M::history) {
        const T kt = q.mindlin ? shear8 * a : q.kt;
        f_t = spring(s.t, n, ut, kt, q.ratio_t * eta_n, p.mu * fn, q.dt, advance);
    } else {
        f_t = viscous_friction(ut, fn, k.ct, p.mu);
    }
    f_i = (-fn) * n + f_t;
    if constexpr (M::rolling) {
        const Vec3<T> vr = (-rstar) * cross(spin, n);  // v_r = −R*·(ω_i − ω_j) × n
        const Vec3<T> fr = spring(s.r, n, vr, q.kr, q.gamma_r, q.mu_r * fn, q.dt, advance);
        t_roll = (-rstar) * cross(n, fr);  // T_i += −R*·(n × F_r), T_j −= the same
    }
}

} // namespace detail

// Particle–particle contact under a §9 law, i < j by id: as particle_contact (contact_law.hpp), and the
// pair's stretches `s` carried in and out. Returns false (and leaves `s` alone) when h <= 0.
template <class M, class T>
inline bool particle_contact_memory(const Vec3<T>& xi, const Vec3<T>& xj, const Vec3<T>& vi, const Vec3<T>& vj,
                                    const Vec3<T>& wi, const Vec3<T>& wj, T ri, T rj, T mi, T mj, const ContactParams<T>& p,
                                    const MemoryParams<T>& q, Stretch<T>& s, bool advance, ContactForce<T>& out)
{
    static_assert(M::rotation && M::friction && M::polydisperse, "a §9 law runs on the full model (with_law_model)");
    Vec3<T> dx;
    T d;
    const T h = detail::pair_overlap(xi, xj, ri, rj, dx, d);
    if (!(h > T(0))) return false;
    const Vec3<T> n = dx / d;
    const Vec3<T> di = (ri - h * T(0.5)) * n;
    const Vec3<T> dj = -((rj - h * T(0.5)) * n);
    Vec3<T> u = vi - vj;
    u = u + cross(wi, di) - cross(wj, dj);
    Vec3<T> ft, troll;
    detail::memory_law<M>(n, h, u, wi - wj, ri * rj / (ri + rj), mi * mj / (mi + mj), p.hertz_pp, q.shear8_pp, p, q, s, advance,
                          out.f_i, ft, troll);
    out.t_i = cross(di, ft);
    out.t_j = cross(dj, -ft);
    if constexpr (M::rolling) {
        out.t_i = out.t_i + troll;
        out.t_j = out.t_j - troll;
    }
    out.overlap = h;
    return true;
}

// Particle–wall contact under a §9 law: as wall_contact (contact_law.hpp), with the contact's stretches.
template <class M, class T>
inline bool wall_contact_memory(const Vec3<T>& xi, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi, const Vec3<T>& point,
                                const Vec3<T>& normal, const Vec3<T>& vw, const ContactParams<T>& p, const MemoryParams<T>& q,
                                Stretch<T>& s, bool advance, ContactForce<T>& out)
{
    static_assert(M::rotation && M::friction && M::moving_walls, "a §9 law runs on the full model (with_law_model)");
    const T sd = dot(xi - point, normal);
    const T h = ri - sd;
    if (!(h > T(0))) return false;
    const Vec3<T> n = -normal;
    const Vec3<T> di = (ri - h * T(0.5)) * n;
    Vec3<T> u = vi - vw;
    u = u + cross(wi, di);
    Vec3<T> ft, troll;
    detail::memory_law<M>(n, h, u, wi, ri, mi, p.hertz_pw, q.shear8_pw, p, q, s, advance, out.f_i, ft, troll);
    out.t_i = cross(di, ft);
    if constexpr (M::rolling) out.t_i = out.t_i + troll;
    out.overlap = h;
    return true;
}

} // namespace demmat
