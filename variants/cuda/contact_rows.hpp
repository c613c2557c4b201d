#pragma once
// The cuda variant's contact law and contact memory (physics.md §9), for the kernels of kernels.hpp.
//
// The law: pair_law and wall_law below are the one place where a model picks its law, the paper's
// (contact_law.hpp) or a §9 law with the contact's stretches (contact_memory.hpp). A law added there under
// a new model flag joins through LawOf; a new spring in Stretch joins through for_each_spring (one line).
//
// The memory: each pair is computed by both of its particles' threads (kernels.hpp, Forces), so each
// side keeps its own copy of the pair's stretches in its own row and advances it: both threads evaluate
// the same law with the lower id as i on the same inputs, so the two copies are the same bits at every
// step, and no thread reads or writes another's row. A row holds the slot's live contacts of the last
// evaluation, keyed by the partner's id (or the wall index), ascending. Two sets of rows: the forces
// kernel reads the last evaluation's set at the slot the particle had then (the sort's permutation,
// sorted_slot, maps a new slot to its old one) and writes this evaluation's set at its new slot, so the
// stretches follow the particle through every re-sort, looked up by the pair of ids, never by a slot.
#include <cstdint>

#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/host_device.hpp"

namespace demmat::gpu {

// A model runs a law of physics.md §9 (with or without a stretch to carry).
template <class M>
inline constexpr bool LawOf = M::restitution_damping || M::history || M::rolling;

// The springs a model carries per contact, in the order the rows store them.
template <class M>
inline constexpr std::uint32_t kSprings = std::uint32_t(M::history) + std::uint32_t(M::rolling);
template <class M, class F>
DEMMAT_HD inline void for_each_spring(Stretch<double>& s, F&& f)
{
    if constexpr (M::history) f(s.t);
    if constexpr (M::rolling) f(s.r);
}

// One set of rows: per slot, its live contacts' keys (partner id or wall index, ascending) and springs.
// Entry k of slot s is at [k·N + s], component c of its springs (3 per spring) at [(c·cap + k)·N + s]:
// the threads of a warp, consecutive slots, read one entry of their rows side by side.
struct StretchRows {
    std::uint32_t* count = nullptr;  // per slot
    std::uint32_t* key = nullptr;
    double* spring = nullptr;
    std::uint32_t cap = 0;  // entries per row
};

// Writes entry k of slot s.
template <class M>
DEMMAT_HD inline void put_stretch(const StretchRows& r, std::uint32_t n, std::uint32_t s, std::uint32_t k, std::uint32_t key,
                                  Stretch<double> st)
{
    r.key[std::uint64_t(k) * n + s] = key;
    std::uint64_t c = 0;
    for_each_spring<M>(st, [&](const Vec3<double>& v) {
        r.spring[((c + 0) * r.cap + k) * n + s] = v.x;
        r.spring[((c + 1) * r.cap + k) * n + s] = v.y;
        r.spring[((c + 2) * r.cap + k) * n + s] = v.z;
        c += 3;
    });
}

// Reads a row by ascending key: take(key) for keys in ascending order gives each one's stretches, zero
// for a key the row does not hold (a contact that starts).
template <class M>
struct RowReader {
    const StretchRows& r;
    std::uint32_t n, s, k = 0, count;
    DEMMAT_HD RowReader(const StretchRows& rows, std::uint32_t n_, std::uint32_t slot)
        : r(rows), n(n_), s(slot), count(M::memory ? rows.count[slot] : 0) {}

    DEMMAT_HD Stretch<double> take(std::uint32_t key)
    {
        Stretch<double> st{};
        while (k < count && r.key[std::uint64_t(k) * n + s] < key) ++k;
        if (k == count || r.key[std::uint64_t(k) * n + s] != key) return st;
        std::uint64_t c = 0;
        for_each_spring<M>(st, [&](Vec3<double>& v) {
            v = {r.spring[((c + 0) * r.cap + k) * n + s], r.spring[((c + 1) * r.cap + k) * n + s], r.spring[((c + 2) * r.cap + k) * n + s]};
            c += 3;
        });
        return st;
    }
};

// ---- the law, in one place ---------------------------------------------------------------------------

// Particle–particle contact, i < j by id; `s` the pair's stretches, carried in and out (unused by the
// paper's law). False when h <= 0.
template <class M>
DEMMAT_HD inline bool pair_law(const Vec3<double>& xi, const Vec3<double>& xj, const Vec3<double>& vi, const Vec3<double>& vj,
                               const Vec3<double>& wi, const Vec3<double>& wj, double ri, double rj, double mi, double mj,
                               const ContactParams<double>& p, const MemoryParams<double>& q, const Coefficients<double>& mono,
                               Stretch<double>& s, ContactForce<double>& c)
{
    if constexpr (LawOf<M>) return particle_contact_memory<M>(xi, xj, vi, vj, wi, wj, ri, rj, mi, mj, p, q, s, true, c);
    else return particle_contact<M>(xi, xj, vi, vj, wi, wj, ri, rj, mi, mj, p, mono, c);
}

// Particle–wall contact; `s` the contact's stretches.
template <class M>
DEMMAT_HD inline bool wall_law(const Vec3<double>& xi, const Vec3<double>& vi, const Vec3<double>& wi, double ri, double mi,
                               const Vec3<double>& point, const Vec3<double>& normal, const Vec3<double>& vw,
                               const ContactParams<double>& p, const MemoryParams<double>& q, const Coefficients<double>& mono,
                               Stretch<double>& s, ContactForce<double>& c)
{
    if constexpr (LawOf<M>) return wall_contact_memory<M>(xi, vi, wi, ri, mi, point, normal, vw, p, q, s, true, c);
    else return wall_contact<M>(xi, vi, wi, ri, mi, point, normal, vw, p, mono, c);
}

} // namespace demmat::gpu
