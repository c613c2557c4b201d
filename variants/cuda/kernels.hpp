#pragma once
// The cuda variant's kernels, written once for the GPU and the CPU. Each kernel is a functor: the data
// it works on (a View, pointers and per-run constants, copied by value into the launch) and a
// DEMMAT_HD body called for one thread of one block, body(block, thread, block_dim). The device backend
// launches it as a CUDA grid; the host backend (host_backend.hpp) runs the same body on the CPU, the
// blocks and the threads in a seeded shuffled order. No kernel depends on the order in which its
// threads run: each thread writes only its own particle's (or component's) values, and reads only
// values that no thread of the same launch writes. The force sums use no atomics: one thread per
// particle adds that particle's contributions in the canonical order of physics.md §6.
#include <cmath>
#include <cstdint>

#include "contact_rows.hpp"
#include "demmat/contact_law.hpp"
#include "demmat/gear.hpp"
#include "demmat/host_device.hpp"

namespace demmat::gpu {

inline constexpr int kMaxWalls = 32;   // walls of a scene the variant runs (a bit each in the wall mask)
inline constexpr int kGearArrays = 12;  // x v a b3 b4 b5, then the rotational six (physics.md §1)

// Status words the search reports (max-combined, so the result does not depend on thread order):
// the worst count and its lowest particle id as count << 32 | (2^32 − 1 − id); kRunaway: id + 1.
enum StatusWord { kAboveOverflow, kRowOverflow, kWallOverflow, kRunaway, kStatusWords };

// One buffer of the per-particle arrays, in cell order: (N, 3) arrays stored column by column, as the
// arrays variant does (component c of slot s at [c·N + s]).
struct Particles {
    double* gear[kGearArrays] = {};
    double* radius = nullptr;
    double* mass = nullptr;
    double* inertia = nullptr;
    std::uint32_t* id = nullptr;    // particle id of each slot
    std::uint64_t* cell = nullptr;  // packed cell of each slot
};

struct Walls {
    int count = 0;
    Vec3<double> point[kMaxWalls], normal[kMaxWalls], velocity[kMaxWalls];
};

struct View {
    std::uint32_t n = 0;
    Particles p;                                  // current order
    Particles q;                                  // the other buffer: the gather writes it
    double *force = nullptr, *torque = nullptr;   // (N, 3), slot order
    double *acc = nullptr, *alpha = nullptr;      // a = F/m + g, α = T/I, (N, 3)
    std::uint64_t* row = nullptr;                 // per slot: partners as id << 32 | slot, ascending
    std::uint32_t row_cap = 0;                    // entries per row (both sides of a particle)
    std::uint32_t* row_count = nullptr;
    std::uint32_t* wall_mask = nullptr;           // per slot: the walls it may touch
    std::uint32_t *candidates = nullptr, *contacts = nullptr, *wall_contacts = nullptr;  // per slot, pairs above it
    std::uint64_t* key = nullptr;                 // sort input: bucket << 32 | id, and the slot
    std::uint32_t* key_slot = nullptr;
    std::uint64_t* sorted_key = nullptr;          // sort output
    std::uint32_t* sorted_slot = nullptr;
    std::uint64_t* cell_tmp = nullptr;            // packed cell of each slot before the gather
    std::uint32_t *bucket_begin = nullptr, *bucket_end = nullptr;
    std::uint64_t bucket_mask = 0;                // buckets: a power of two ≥ 2N
    double cell = 0.0;                            // cell edge; 0: every pair is a candidate
    std::uint32_t cap_above = 0, cap_walls = 0;   // scene capacities
    unsigned long long* status = nullptr;         // kStatusWords words
    ContactParams<double> params;
    MemoryParams<double> memory;                  // a §9 law's constants (zero for the paper's law)
    StretchRows pairs_then, walls_then;           // a law with memory: the last evaluation's rows, at the slots of then
    StretchRows pairs_now, walls_now;             // this evaluation's, at the current slots (contact_rows.hpp)
    Coefficients<double> mono_pp, mono_pw;
    Vec3<double> gravity;
    GearCoefficients<double> gear;
    Walls walls;
};

// Kernels take their View by value, as launch parameters (CUDA's limit: 4 KB on every device).
static_assert(sizeof(View) <= 4096, "a kernel's View must fit CUDA's 4 KB of launch parameters");

// ---- small helpers -----------------------------------------------------------------------------------

DEMMAT_HD inline Vec3<double> get(const double* a, std::uint32_t n, std::uint32_t s) { return {a[s], a[n + s], a[2 * n + s]}; }
DEMMAT_HD inline void put(double* a, std::uint32_t n, std::uint32_t s, const Vec3<double>& v)
{
    a[s] = v.x;
    a[n + s] = v.y;
    a[2 * n + s] = v.z;
}

DEMMAT_HD inline void status_max(unsigned long long* word, unsigned long long v)
{
#if defined(__CUDA_ARCH__)
    atomicMax(word, v);  // integers only: an error report, never a force
#else
    if (v > *word) *word = v;  // the host backend runs one thread at a time
#endif
}

// A cell coordinate packed in 21 bits per axis (wrapping): two of a cell's 27 neighbours never share a
// packed value, and cells that do (2^21 cells apart) hold pairs that may_touch rejects.
inline constexpr std::uint64_t kAxisMask = (std::uint64_t(1) << 21) - 1;
DEMMAT_HD inline std::uint64_t pack_cell(std::int64_t cx, std::int64_t cy, std::int64_t cz)
{
    return (std::uint64_t(cx) & kAxisMask) | ((std::uint64_t(cy) & kAxisMask) << 21) | ((std::uint64_t(cz) & kAxisMask) << 42);
}
DEMMAT_HD inline std::uint64_t bucket_of(std::uint64_t cell, std::uint64_t mask)
{
    std::uint64_t h = cell * 0x9E3779B97F4A7C15ull;  // splitmix64's finaliser
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    return (h ^ (h >> 31)) & mask;
}

// Index of this thread's item, or false when it is past the end.
DEMMAT_HD inline bool item(unsigned block, unsigned thread, unsigned dim, std::uint64_t count, std::uint64_t& i)
{
    i = std::uint64_t(block) * dim + thread;
    return i < count;
}

// ---- predictor and corrector: one thread per component -------------------------------------------------

// Corrector = false: the predictor; true: the corrector, its Δa a value before a changes (as
// Gear5Scheme::correct, integrators.hpp).
template <class M, bool Corrector>
struct GearStep {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t e;
        if (!item(block, thread, dim, 3ull * v.n, e)) return;
        double* const* g = v.p.gear;
        for (int r = 0; r < (M::rotation ? 2 : 1); ++r) {  // translation; rotation (arrays 6..11)
            double* const* q = g + 6 * r;
            if constexpr (Corrector) {
                const double da = (r == 0 ? v.acc : v.alpha)[e] - q[2][e];
                gear_correct(q[0][e], q[1][e], q[2][e], q[3][e], q[4][e], q[5][e], da, v.gear);
            } else {
                gear_predict(q[0][e], q[1][e], q[2][e], q[3][e], q[4][e], q[5][e], v.gear);
            }
        }
    }
};
template <class M>
using Predict = GearStep<M, false>;
template <class M>
using Correct = GearStep<M, true>;

// ---- search: keys, (sort), gather, buckets, candidates ---------------------------------------------------

// Per slot: its cell, and the sort key bucket << 32 | id. Keys are distinct, so every correct sort
// yields the same order: by bucket, and by id within one.
struct MakeKeys {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t s;
        if (!item(block, thread, dim, v.n, s)) return;
        std::uint64_t cell = 0;
        if (v.cell > 0.0) {
            const Vec3<double> x = get(v.p.gear[0], v.n, std::uint32_t(s));
            std::int64_t c[3];
            for (int k = 0; k < 3; ++k) {
                const double f = std::floor((k == 0 ? x.x : k == 1 ? x.y : x.z) / v.cell);
                if (!(std::fabs(f) < 1099511627776.0)) {  // non-finite or runaway: reported, and the run stops
                    status_max(&v.status[kRunaway], std::uint64_t(v.p.id[s]) + 1);
                    c[k] = 0;
                } else {
                    c[k] = std::int64_t(f);
                }
            }
            cell = pack_cell(c[0], c[1], c[2]);
        }
        v.cell_tmp[s] = cell;
        v.key[s] = (v.cell > 0.0 ? bucket_of(cell, v.bucket_mask) << 32 : 0) | v.p.id[s];
        v.key_slot[s] = std::uint32_t(s);
    }
};

// New slot s takes the particle that sorted to s: every per-particle array, from buffer p into q.
struct Gather {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t s;
        if (!item(block, thread, dim, v.n, s)) return;
        const std::uint32_t o = v.sorted_slot[s], n = v.n;
        for (int k = 0; k < kGearArrays; ++k)
            for (std::uint32_t c = 0; c < 3; ++c) v.q.gear[k][c * n + s] = v.p.gear[k][c * n + o];
        v.q.radius[s] = v.p.radius[o];
        v.q.mass[s] = v.p.mass[o];
        v.q.inertia[s] = v.p.inertia[o];
        v.q.id[s] = v.p.id[o];
        v.q.cell[s] = v.cell_tmp[o];
    }
};

struct ClearBuckets {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t b;
        if (!item(block, thread, dim, v.bucket_mask + 1, b)) return;
        v.bucket_begin[b] = 0;
        v.bucket_end[b] = 0;
    }
};

// Each bucket's range of slots, from the sorted keys: the first and last slot of a run write it.
struct FindBuckets {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t s;
        if (!item(block, thread, dim, v.n, s)) return;
        const std::uint64_t b = v.sorted_key[s] >> 32;
        if (s == 0 || (v.sorted_key[s - 1] >> 32) != b) v.bucket_begin[b] = std::uint32_t(s);
        if (s + 1 == v.n || (v.sorted_key[s + 1] >> 32) != b) v.bucket_end[b] = std::uint32_t(s + 1);
    }
};

// Per slot: every partner that may_touch accepts, on both sides, kept ascending by id (the canonical
// order), and the walls it may touch. The candidates of the partners above it are what the arrays
// variant stores, and what the scene's capacity bounds.
template <class M>
struct Search {
    View v;

    DEMMAT_HD void consider(std::uint32_t p, std::uint32_t q, std::uint32_t& total, std::uint32_t& above, std::uint64_t* row) const
    {
        const std::uint32_t n = v.n, ip = v.p.id[p], iq = v.p.id[q];
        const Vec3<double> xp = get(v.p.gear[0], n, p), xq = get(v.p.gear[0], n, q);
        const bool touch = ip < iq ? may_touch(xp, xq, v.p.radius[p], v.p.radius[q]) : may_touch(xq, xp, v.p.radius[q], v.p.radius[p]);
        if (!touch) return;
        if (iq > ip) ++above;
        if (total < v.row_cap) {  // insertion, ascending by id (the high half of an entry)
            const std::uint64_t e = std::uint64_t(iq) << 32 | q;
            std::uint32_t k = total;
            while (k > 0 && row[k - 1] > e) {
                row[k] = row[k - 1];
                --k;
            }
            row[k] = e;
        }
        ++total;
    }

    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t s;
        if (!item(block, thread, dim, v.n, s)) return;
        const std::uint32_t p = std::uint32_t(s);
        std::uint64_t* row = v.row + std::uint64_t(p) * v.row_cap;
        std::uint32_t total = 0, above = 0;
        if (v.cell > 0.0) {
            const std::uint64_t cp = v.p.cell[p];
            const std::int64_t c0 = std::int64_t(cp & kAxisMask), c1 = std::int64_t((cp >> 21) & kAxisMask),
                               c2 = std::int64_t((cp >> 42) & kAxisMask);
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const std::uint64_t c = pack_cell(c0 + dx, c1 + dy, c2 + dz);
                        const std::uint64_t b = bucket_of(c, v.bucket_mask);
                        for (std::uint32_t q = v.bucket_begin[b]; q < v.bucket_end[b]; ++q)
                            if (q != p && v.p.cell[q] == c) consider(p, q, total, above, row);
                    }
        } else {
            for (std::uint32_t q = 0; q < v.n; ++q)
                if (q != p) consider(p, q, total, above, row);
        }
        const std::uint64_t id = 0xffffffffu - v.p.id[p];  // ties of the count go to the lowest id, as in arrays
        if (above > v.cap_above) status_max(&v.status[kAboveOverflow], std::uint64_t(above) << 32 | id);
        if (total > v.row_cap) status_max(&v.status[kRowOverflow], std::uint64_t(total) << 32 | id);
        v.row_count[p] = total < v.row_cap ? total : v.row_cap;
        v.candidates[p] = above;
        if constexpr (M::walls) {
            const Vec3<double> x = get(v.p.gear[0], v.n, p);
            std::uint32_t mask = 0, count = 0;
            for (int w = 0; w < v.walls.count; ++w)
                if (may_touch_wall(x, v.p.radius[p], v.walls.point[w], v.walls.normal[w])) {
                    mask |= std::uint32_t(1) << w;
                    ++count;
                }
            if (count > v.cap_walls) status_max(&v.status[kWallOverflow], std::uint64_t(count) << 32 | id);
            v.wall_mask[p] = mask;
        }
    }
};

// ---- forces: one thread per particle, its own sums in the canonical order --------------------------------

// Partners ascending by id (below it, then above it), each pair by the shared law with the lower id as
// i; the force on the higher one is +(−F_i) and its torque the law's t_j, as in the arrays variant's
// loop; then the walls in wall order; then a = F/m + g and α = T/I. Under a law with memory each contact
// takes its stretches from the particle's row of the last evaluation (at the slot it had then) by key,
// and a live one writes them, advanced, to its row of this evaluation (contact_rows.hpp).
template <class M>
struct Forces {
    View v;
    DEMMAT_HD void operator()(unsigned block, unsigned thread, unsigned dim) const
    {
        std::uint64_t s;
        if (!item(block, thread, dim, v.n, s)) return;
        const std::uint32_t n = v.n, p = std::uint32_t(s), ip = v.p.id[p];
        const Particles& P = v.p;
        const Vec3<double> xp = get(P.gear[0], n, p), vp = get(P.gear[1], n, p), wp = get(P.gear[7], n, p);
        const double rp = P.radius[p], mp = P.mass[p];
        Vec3<double> f{}, t{};
        std::uint32_t contacts = 0, wall_contacts = 0, live = 0;
        const std::uint32_t then = M::memory ? v.sorted_slot[p] : p;  // this particle's slot at the last evaluation
        RowReader<M> pairs_then(v.pairs_then, n, then);
        const std::uint64_t* row = v.row + std::uint64_t(p) * v.row_cap;
        for (std::uint32_t k = 0; k < v.row_count[p]; ++k) {
            const std::uint32_t q = std::uint32_t(row[k]), iq = std::uint32_t(row[k] >> 32);
            const Vec3<double> xq = get(P.gear[0], n, q), vq = get(P.gear[1], n, q), wq = get(P.gear[7], n, q);
            ContactForce<double> c;
            Stretch<double> s{};
            if constexpr (M::memory) s = pairs_then.take(iq);
            if (iq < ip) {
                if (!pair_law<M>(xq, xp, vq, vp, wq, wp, P.radius[q], rp, P.mass[q], mp, v.params, v.memory, v.mono_pp, s, c)) continue;
                f += -c.f_i;
                if constexpr (M::rotation) t += c.t_j;
            } else {
                if (!pair_law<M>(xp, xq, vp, vq, wp, wq, rp, P.radius[q], mp, P.mass[q], v.params, v.memory, v.mono_pp, s, c)) continue;
                f += c.f_i;
                if constexpr (M::rotation) t += c.t_i;
                ++contacts;
            }
            if constexpr (M::memory) put_stretch<M>(v.pairs_now, n, p, live++, iq, s);
        }
        if constexpr (M::memory) v.pairs_now.count[p] = live;
        if constexpr (M::walls) {
            const std::uint32_t mask = v.wall_mask[p];
            RowReader<M> walls_then(v.walls_then, n, then);
            for (int w = 0; w < v.walls.count; ++w) {
                if (!(mask >> w & 1u)) continue;
                ContactForce<double> c;
                Stretch<double> s{};
                if constexpr (M::memory) s = walls_then.take(std::uint32_t(w));
                if (!wall_law<M>(xp, vp, wp, rp, mp, v.walls.point[w], v.walls.normal[w], v.walls.velocity[w], v.params, v.memory,
                                 v.mono_pw, s, c))
                    continue;
                f += c.f_i;
                if constexpr (M::rotation) t += c.t_i;
                if constexpr (M::memory) put_stretch<M>(v.walls_now, n, p, wall_contacts, std::uint32_t(w), s);
                ++wall_contacts;
            }
            if constexpr (M::memory) v.walls_now.count[p] = wall_contacts;
        }
        put(v.force, n, p, f);
        put(v.torque, n, p, t);
        put(v.acc, n, p, {acceleration(f.x, mp, v.gravity.x), acceleration(f.y, mp, v.gravity.y), acceleration(f.z, mp, v.gravity.z)});
        if constexpr (M::rotation) {
            const double I = P.inertia[p];
            put(v.alpha, n, p, {t.x / I, t.y / I, t.z / I});
        }
        v.contacts[p] = contacts;
        v.wall_contacts[p] = wall_contacts;
    }
};

} // namespace demmat::gpu
