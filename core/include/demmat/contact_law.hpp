#pragma once
// The contact law of physics.md §2, written once. Every variant (and every port to another language)
// computes a contact through these functions, operation for operation, so trajectories agree bit for
// bit. Changing an expression here changes every variant's trajectory at once, as it should.
#include <algorithm>
#include <cmath>

#include "demmat/host_device.hpp"
#include "demmat/lanes.hpp"
#include "demmat/model.hpp"
#include "demmat/vec3.hpp"

namespace demmat {

// The lever arms (physics.md §2): R − h/2 from each centre to the contact point, for the relative
// velocity there and for the torque. LAMMPS's granular styles use the full radii in that velocity, and
// fix wall/gran also puts a wall contact's torque at the full radius. A build configured with
// -DDEMMAT_LEVER_ARMS=lammps takes LAMMPS's arms instead, to show by experiment how much of the
// distance from LAMMPS they make (scripts/run_peers.sh --diagnose, docs/peers.md). It is not a law of
// the suite: its runs are not the suite's results, and the f90 and pascal ports keep §2's arms.
#ifdef DEMMAT_LAMMPS_LEVER_ARMS
inline constexpr bool kLammpsLeverArms = true;
#else
inline constexpr bool kLammpsLeverArms = false;
#endif

// Per-run constants of the contact law, derived once from the materials (see material.hpp).
template <class T>
struct ContactParams {
    T hertz_pp{};  // (4/3)·E* for particle–particle contacts
    T hertz_pw{};  // (4/3)·E* for particle–wall contacts
    T gamma_n{};   // normal damping, 1/s; the term is gamma_n·m*·u_n (Schäfer–Dippel–Wolf form)
    T gamma_t{};   // tangential viscous coefficient, 1/s
    T mu{};        // Coulomb friction coefficient

    // The effective moduli E* themselves (physics.md §2, §8: contact time, maximum overlap), derived here
    // only, from the stored (4/3)·E*.
    T estar_pp() const { return T(0.75) * hertz_pp; }
    T estar_pw() const { return T(0.75) * hertz_pw; }

    template <class U>
    ContactParams<U> as() const
    {
        return {U(hertz_pp), U(hertz_pw), U(gamma_n), U(gamma_t), U(mu)};
    }
};

// What one contact contributes: force on i (the force on j is exactly -f_i), torque on i and on j.
template <class T>
struct ContactForce {
    Vec3<T> f_i;
    Vec3<T> t_i;
    Vec3<T> t_j;
    T overlap{};
};

// Cheap, conservative pre-test used by contact searches: true for every pair the law can find in
// contact (h > 0), and for a few that it will reject. The relative margin 1e-9 covers the rounding of
// d2 and sqrt (about 1e-16 relative), so any search that keeps the pairs this accepts hands the law a
// superset of the contact set, and the law alone decides; the trajectory then cannot depend on the
// search method.
inline constexpr double kMayTouchMargin = 1.000000001;  // the relative margin, 1 + 1e-9 (also passed to the ports)

template <class T>
DEMMAT_HD inline bool may_touch(const Vec3<T>& xi, const Vec3<T>& xj, T ri, T rj)
{
    const Vec3<T> dx = xj - xi;
    const T d2 = dot(dx, dx);
    const T s = ri + rj;
    return d2 < s * s * T(kMayTouchMargin);
}

// The same test on W pairs at once (lanes.hpp), the same operations lane by lane: nonzero in the lanes
// may_touch accepts.
template <LanePack V>
inline auto may_touch_lanes(const Vec3<V>& xi, const Vec3<V>& xj, V ri, V rj)
{
    const Vec3<V> dx = xj - xi;
    const V d2 = dot(dx, dx);
    const V s = ri + rj;
    return d2 < s * s * LaneScalar<V>(kMayTouchMargin);
}
template <class T>
DEMMAT_HD inline bool may_touch_wall(const Vec3<T>& xi, T ri, const Vec3<T>& point, const Vec3<T>& normal)
{
    // The law tests ri - s > 0 with exactly this s; the margin only makes the list a superset.
    return dot(xi - point, normal) < ri * T(kMayTouchMargin);
}

// The contact's effective coefficients (physics.md §2): kn = (4/3)E*·sqrt(R*) multiplies h·sqrt(h),
// cn = γ_n·m* multiplies u_n, ct = γ_t·m* multiplies |u_t|. A pair enters the law only through R* and m*,
// so a polydisperse model computes these per contact and a monodisperse one once per run, for the one
// radius and mass (pair_coefficients / wall_coefficients): the same operations, hence the same bits.
// T is a scalar or a pack of lanes (lanes.hpp); S, the parameters' type, is T's scalar.
template <class T>
struct Coefficients {
    T kn{}, cn{}, ct{};
};

template <class T, class S>
DEMMAT_HD inline Coefficients<T> coefficients(S hertz, T rstar, T mstar, const ContactParams<S>& p)
{
    return {hertz * lane_sqrt(rstar), p.gamma_n * mstar, p.gamma_t * mstar};
}
template <class T, class S>
DEMMAT_HD inline Coefficients<T> pair_coefficients(T ri, T rj, T mi, T mj, const ContactParams<S>& p)
{
    return coefficients(p.hertz_pp, ri * rj / (ri + rj), mi * mj / (mi + mj), p);
}
template <class T, class S>
DEMMAT_HD inline Coefficients<T> wall_coefficients(T ri, T mi, const ContactParams<S>& p)
{
    return coefficients(p.hertz_pw, ri, mi, p);  // R* = R_i, m* = m_i
}

namespace detail {

// The paper's tangential force from the tangential relative velocity u_t and the clipped F_n:
// −min(μ·F_n, γ_t·m*·|u_t|)·u_t/|u_t| (ct = γ_t·m*), zero when |u_t| = 0.
template <class T, class S>
DEMMAT_HD inline Vec3<T> viscous_friction(const Vec3<T>& ut, T fn, T ct, S mu)
{
    const T zero{};
    const T ut_abs = lane_sqrt(dot(ut, ut));
    // No tangential force without tangential motion; the divisor 1 there keeps a lane finite.
    const auto sliding = ut_abs > zero;
    const T ft = lane_min(mu * fn, ct * ut_abs);
    const Vec3<T> t = (-ft) * (ut / (sliding ? ut_abs : splat<T>(S(1))));
    return {sliding ? t.x : zero, sliding ? t.y : zero, sliding ? t.z : zero};
}

// Normal and tangential force from the contact geometry (n from i towards the partner, overlap h > 0,
// relative velocity u of i with respect to the partner at the contact point). The two branches of the
// law (the clip and a zero tangential speed) are selects, so a pack of lanes runs the same code.
template <class M, class T, class S>
DEMMAT_HD inline void contact_force(const Vec3<T>& n, T h, const Vec3<T>& u, const Coefficients<T>& k, const ContactParams<S>& p,
                          Vec3<T>& f_i, Vec3<T>& f_t)
{
    const T zero{};
    // h^(3/2) as h·sqrt(h): sqrt is correctly rounded in every language, pow is not (physics.md §6).
    // kn·h·sqrt(h) is (4/3)E*·sqrt(R*)·h·sqrt(h) evaluated left to right, as the ports write it.
    T fn = k.kn * h * lane_sqrt(h);
    T un{};
    if constexpr (M::damping || M::friction) un = dot(u, n);
    if constexpr (M::damping) fn = fn + k.cn * un;
    fn = fn < zero ? zero : fn;  // choice: no attraction at the end of a contact
    f_t = Vec3<T>{};
    if constexpr (M::friction) f_t = viscous_friction(u - un * n, fn, k.ct, p.mu);
    f_i = (-fn) * n + f_t;
}

// The centre-to-centre vector, its length and the overlap h = R_i + R_j − d of a pair.
template <class T>
DEMMAT_HD inline T pair_overlap(const Vec3<T>& xi, const Vec3<T>& xj, T ri, T rj, Vec3<T>& dx, T& d)
{
    dx = xj - xi;
    d = lane_sqrt(dot(dx, dx));
    return ri + rj - d;
}

// The particle–particle law once the overlap h > 0 is known (in every lane whose result is kept).
template <class M, class T, class S>
DEMMAT_HD inline void pair_law(const Vec3<T>& dx, T d, T h, const Vec3<T>& vi, const Vec3<T>& vj, const Vec3<T>& wi, const Vec3<T>& wj,
                     T ri, T rj, T mi, T mj, const ContactParams<S>& p, const Coefficients<T>& mono, ContactForce<T>& out)
{
    const Vec3<T> n = dx / d;
    const Vec3<T> di = (ri - h * S(0.5)) * n;
    const Vec3<T> dj = -((rj - h * S(0.5)) * n);
    Vec3<T> u = vi - vj;
    if constexpr (M::rotation) {
        if constexpr (kLammpsLeverArms) u = u + cross(wi, ri * n) - cross(wj, -(rj * n));
        else u = u + cross(wi, di) - cross(wj, dj);
    }
    Vec3<T> ft;
    if constexpr (M::polydisperse) contact_force<M>(n, h, u, pair_coefficients(ri, rj, mi, mj, p), p, out.f_i, ft);
    else contact_force<M>(n, h, u, mono, p, out.f_i, ft);
    if constexpr (M::rotation) {
        out.t_i = cross(di, ft);
        out.t_j = cross(dj, -ft);
    }
    out.overlap = h;
}

} // namespace detail

// Particle–particle contact, i < j by id. Returns false (and writes nothing) when h <= 0. `mono` holds
// pair_coefficients of the scene's one radius and mass; only a model with !M::polydisperse reads it, a
// polydisperse one computes the pair's own from r_i, r_j, m_i, m_j.
template <class M, class T>
DEMMAT_HD inline bool particle_contact(const Vec3<T>& xi, const Vec3<T>& xj, const Vec3<T>& vi, const Vec3<T>& vj,
                             const Vec3<T>& wi, const Vec3<T>& wj, T ri, T rj, T mi, T mj,
                             const ContactParams<T>& p, const Coefficients<T>& mono, ContactForce<T>& out)
{
    Vec3<T> dx;
    T d;
    const T h = detail::pair_overlap(xi, xj, ri, rj, dx, d);
    if (!(h > T(0))) return false;
    detail::pair_law<M>(dx, d, h, vi, vj, wi, wj, ri, rj, mi, mj, p, mono, out);
    return true;
}

// The same for a polydisperse model, whose callers hold no monodisperse coefficients.
template <class M, class T>
DEMMAT_HD inline bool particle_contact(const Vec3<T>& xi, const Vec3<T>& xj, const Vec3<T>& vi, const Vec3<T>& vj,
                             const Vec3<T>& wi, const Vec3<T>& wj, T ri, T rj, T mi, T mj,
                             const ContactParams<T>& p, ContactForce<T>& out)
{
    static_assert(M::polydisperse, "a monodisperse model needs the run's pair coefficients");
    return particle_contact<M>(xi, xj, vi, vj, wi, wj, ri, rj, mi, mj, p, Coefficients<T>{}, out);
}

// W pairs at once, one per lane of the pack V (lanes.hpp): the same law, operation for operation, so
// each lane holds the bits particle_contact gives for its pair. Returns the lanes in contact (h > 0);
// the others hold zeros in f_i, t_i and t_j, which add nothing to a sum (see the fast variant).
template <class M, LanePack V>
inline auto particle_contact_lanes(const Vec3<V>& xi, const Vec3<V>& xj, const Vec3<V>& vi, const Vec3<V>& vj,
                                   const Vec3<V>& wi, const Vec3<V>& wj, V ri, V rj, V mi, V mj,
                                   const ContactParams<LaneScalar<V>>& p, const Coefficients<V>& mono, ContactForce<V>& out)
{
    Vec3<V> dx;
    V d;
    const V h = detail::pair_overlap(xi, xj, ri, rj, dx, d);
    const auto touch = h > V{};
    detail::pair_law<M>(dx, d, h, vi, vj, wi, wj, ri, rj, mi, mj, p, mono, out);
    auto keep = [&](Vec3<V>& a) { a = {touch ? a.x : V{}, touch ? a.y : V{}, touch ? a.z : V{}}; };
    keep(out.f_i);
    if constexpr (M::rotation) {
        keep(out.t_i);
        keep(out.t_j);
    }
    return touch;
}

namespace detail {
// A wall contact's lever arm, for its velocity and its torque alike (see kLammpsLeverArms).
template <class S, class T>
DEMMAT_HD inline T wall_lever_arm(T ri, T h)
{
    if constexpr (kLammpsLeverArms) return ri;
    else return ri - h * S(0.5);
}

// The particle–wall law once the overlap h > 0 is known (in every lane whose result is kept).
template <class M, class T, class S>
DEMMAT_HD inline void wall_law(T h, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi, const Vec3<T>& normal, const Vec3<T>& vw,
                     const ContactParams<S>& p, const Coefficients<T>& mono, ContactForce<T>& out)
{
    const Vec3<T> n = -normal;
    const Vec3<T> di = wall_lever_arm<S>(ri, h) * n;
    Vec3<T> u = vi;
    if constexpr (M::moving_walls) u = vi - vw;
    if constexpr (M::rotation) u = u + cross(wi, di);
    Vec3<T> ft;
    if constexpr (M::polydisperse) contact_force<M>(n, h, u, wall_coefficients(ri, mi, p), p, out.f_i, ft);
    else contact_force<M>(n, h, u, mono, p, out.f_i, ft);
    if constexpr (M::rotation) out.t_i = cross(di, ft);
    out.overlap = h;
}
} // namespace detail

// Particle–wall contact: the wall is a plane through `point` with unit normal `normal` pointing into
// the domain, moving with velocity `vw` (read only by a model with moving walls; a fixed wall's is
// zero, and v_i − 0 = v_i exactly); R* = R_i, m* = m_i, E* from the particle and wall materials. `mono`
// as for particle_contact, from wall_coefficients.
template <class M, class T>
DEMMAT_HD inline bool wall_contact(const Vec3<T>& xi, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi,
                         const Vec3<T>& point, const Vec3<T>& normal, const Vec3<T>& vw,
                         const ContactParams<T>& p, const Coefficients<T>& mono, ContactForce<T>& out)
{
    const T s = dot(xi - point, normal);
    const T h = ri - s;
    if (!(h > T(0))) return false;
    detail::wall_law<M>(h, vi, wi, ri, mi, normal, vw, p, mono, out);
    return true;
}

// W particle–wall pairs at once, one per lane (each lane its own particle and wall): the same law,
// operation for operation, as particle_contact_lanes is for pairs. Returns the lanes in contact; the
// others hold zeros in f_i and t_i.
template <class M, LanePack V>
inline auto wall_contact_lanes(const Vec3<V>& xi, const Vec3<V>& vi, const Vec3<V>& wi, V ri, V mi, const Vec3<V>& point,
                               const Vec3<V>& normal, const Vec3<V>& vw, const ContactParams<LaneScalar<V>>& p,
                               const Coefficients<V>& mono, ContactForce<V>& out)
{
    const V s = dot(xi - point, normal);
    const V h = ri - s;
    const auto touch = h > V{};
    detail::wall_law<M>(h, vi, wi, ri, mi, normal, vw, p, mono, out);
    auto keep = [&](Vec3<V>& a) { a = {touch ? a.x : V{}, touch ? a.y : V{}, touch ? a.z : V{}}; };
    keep(out.f_i);
    if constexpr (M::rotation) keep(out.t_i);
    return touch;
}

template <class M, class T>
DEMMAT_HD inline bool wall_contact(const Vec3<T>& xi, const Vec3<T>& vi, const Vec3<T>& wi, T ri, T mi,
                         const Vec3<T>& point, const Vec3<T>& normal, const Vec3<T>& vw,
                         const ContactParams<T>& p, ContactForce<T>& out)
{
    static_assert(M::polydisperse, "a monodisperse model needs the run's wall coefficients");
    return wall_contact<M>(xi, vi, wi, ri, mi, point, normal, vw, p, Coefficients<T>{}, out);
}

// Newton's second law with gravity (physics.md §4 step 7): a = F/m + g, α = T/I.
template <class T>
DEMMAT_HD inline T acceleration(T force, T mass, T gravity) { return force / mass + gravity; }

} // namespace demmat
