// The fast variant: data-oriented, vectorised, OpenMP multi-threaded, and still bit-identical to arrays
// for any number of threads (docs/variants.md, "fast").
//
// - Particles live in cell order (re-sorted at every neighbour-list rebuild, the box's shortest axis
//   fastest) with their ids kept; the state is a structure of arrays, each vector quantity three
//   contiguous component blocks (x then y then z) as in arrays, so the Gear scheme runs as vectorised
//   streams. Between two force passes one pass over the particles does the corrector of one step fused
//   with the predictor of the next, the displacement check, the kernel's records and the wall
//   candidates (predict()).
// - The contact candidates come from a neighbour list with a skin, rebuilt only when a displacement
//   check says it must be. The list is a superset of the contact set and the shared law alone decides
//   h > 0, so the contacts, and with the canonical order the trajectory, are those of a search every step.
// - The list holds each pair once, under its lower-id particle (the law's i), partners sorted by id. The
//   pair kernel writes each contact's force and torques into its slot; each particle then gathers, in
//   the canonical order of physics.md §6, the slots where it is j (partners of lower id, ascending; a
//   list kept across steps), then its own slots (partners of higher id, ascending, contiguous), then its
//   walls; Newton's law comes with the corrector in the next pass. Kernel and sums go in one sweep over
//   the storage order, a chunk of particles at a time, and the sums read the slots from a small ring
//   that stays in cache (see forces_canonical). No sum depends on which thread did what, so the bits do
//   not depend on the thread count.
// - The kernel reads each particle's position, radius, velocity and angular velocity from one record
//   (Kin, written by predict()'s pass) and moves a pack's worth between records and lanes by transposes
//   of whole vectors.
// - FastOptions::canonical = false drops the canonical order: each pair's force is added to both
//   particles as it is computed, into per-thread loads summed after a barrier, which is what an
//   unordered code does; it keeps no slots.
#include "fast.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include <fmt/format.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "demmat/contact_law.hpp"
#include "demmat/error.hpp"
#include "demmat/gear.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"

namespace demmat {
namespace {

#ifdef _OPENMP
int thread_index() { return omp_get_thread_num(); }
int thread_count() { return omp_get_num_threads(); }
int thread_limit() { return omp_get_max_threads(); }
#else
int thread_index() { return 0; }
int thread_count() { return 1; }
int thread_limit() { return 1; }
#endif

using Index = std::int32_t;

// One contact's result, kept in list order: force on i (on j it is -f), torque on i and on j.
template <class T>
struct Slot {
    Vec3<T> f, ti, tj;
};

// Where the canonical kernel puts slot k: ring[k & mask], a thread's ring of the slots its sweep has yet
// to sum, and, where `all` is set, all[k] too (the whole list, for the sums that straddle two pieces).
template <class T>
struct SlotSink {
    Slot<T>* ring = nullptr;
    std::size_t mask = 0;
    Slot<T>* all = nullptr;
    void put(std::size_t k, const Slot<T>& v) const
    {
        ring[k & mask] = v;
        if (all) all[k] = v;
    }
};

// Where a sum reads slot k: lo[k & mask] below `split`, hi[k & mask] from it on (a ring: mask + 1 slots,
// plus one; the whole list: mask all ones).
template <class T>
struct SlotSource {
    const Slot<T>* lo;
    const Slot<T>* hi;
    std::size_t mask, split;
};

// Four values loaded and stored as one vector (32 bytes for double): the unit of the kernel's transposes.
template <class T>
using Quad = Pack<T, 4>;

// Quads go by reference, never by value: built for the baseline (DEMMAT_FAST_NATIVE off), a 32-byte
// vector passed or returned by value changes the calling convention (GCC's -Wpsabi notes).
template <class T>
[[gnu::always_inline]] inline void load_quad(Quad<T>& q, const T* p)
{
    std::memcpy(&q, p, sizeof(q));
}

// A particle's kinematics as the pair kernel reads them, one record per particle (written by predict()'s
// pass, and by a rebuild): position and radius, velocity, angular velocity, a quad each, so that a
// lane's particle is three loads of one record, not ten from ten arrays.
template <class T>
struct alignas(sizeof(Quad<T>)) Kin {
    Quad<T> xr;  // x, y, z, R
    Quad<T> v;   // vx, vy, vz, m (the mass: the law's coefficients)
    Quad<T> w;   // wx, wy, wz, 0
};

// A wall as the wall kernel reads it: point (where it is this step), unit normal, velocity.
template <class T>
struct alignas(sizeof(Quad<T>)) WallRecord {
    Quad<T> p, n, v;  // (x, y, z, 0) each
};

// A particle–wall pair that may touch this step.
struct WallCandidate {
    std::int32_t s, w;  // storage slot of the particle, wall index
};

// A particle's force and torque summed in storage order (unordered mode), one cache line for double.
template <class T>
struct alignas(2 * sizeof(Quad<T>)) Load {
    Quad<T> f;  // fx, fy, fz, (unused)
    Quad<T> t;  // tx, ty, tz, (unused)
};

// In-place transpose of a 4×4 block: afterwards a[c] holds what was lane c of the four, and so on.
template <class T>
[[gnu::always_inline]] inline void transpose4(Quad<T>& a, Quad<T>& b, Quad<T>& c, Quad<T>& d)
{
    const Quad<T> t0 = __builtin_shufflevector(a, b, 0, 4, 2, 6), t1 = __builtin_shufflevector(a, b, 1, 5, 3, 7);
    const Quad<T> t2 = __builtin_shufflevector(c, d, 0, 4, 2, 6), t3 = __builtin_shufflevector(c, d, 1, 5, 3, 7);
    a = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    b = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    c = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    d = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

// rows[l] is lane l's quad; out[c][l] = rows[l][c]. A transpose of whole vectors (a few shuffles per
// pack) instead of one scalar load and one lane insert per value. Moves bits, computes nothing. (Always
// inlined: called out of line, as GCC chose once the kernel had a few callers, the vectors go through
// memory and the step took 20 % longer.)
template <class V>
[[gnu::always_inline]] inline void rows_to_lanes(const Quad<LaneScalar<V>>* rows, V out[4])
{
    using T = LaneScalar<V>;
    constexpr int W = lane_count<V>;
    if constexpr (W == 8 || W == 4) {
        Quad<T> r[W];
        for (int l = 0; l < W; ++l) r[l] = rows[l];
        transpose4<T>(r[0], r[1], r[2], r[3]);
        if constexpr (W == 8) {
            transpose4<T>(r[4], r[5], r[6], r[7]);
            for (int c = 0; c < 4; ++c) out[c] = __builtin_shufflevector(r[c], r[4 + c], 0, 1, 2, 3, 4, 5, 6, 7);
        } else {
            for (int c = 0; c < 4; ++c) out[c] = r[c];
        }
    } else if constexpr (W == 2) {
        out[0] = __builtin_shufflevector(rows[0], rows[1], 0, 4);
        out[1] = __builtin_shufflevector(rows[0], rows[1], 1, 5);
        out[2] = __builtin_shufflevector(rows[0], rows[1], 2, 6);
        out[3] = __builtin_shufflevector(rows[0], rows[1], 3, 7);
    } else {
        for (int c = 0; c < 4; ++c)
            for (int l = 0; l < W; ++l) out[c][l] = rows[l][c];
    }
}

// The inverse: rows[l] = {in[0][l], in[1][l], in[2][l], in[3][l]}.
template <class V>
[[gnu::always_inline]] inline void lanes_to_rows(const V in[4], Quad<LaneScalar<V>>* rows)
{
    using T = LaneScalar<V>;
    constexpr int W = lane_count<V>;
    if constexpr (W == 8) {
        Quad<T> lo[4], hi[4];
        for (int c = 0; c < 4; ++c) {
            lo[c] = __builtin_shufflevector(in[c], in[c], 0, 1, 2, 3);
            hi[c] = __builtin_shufflevector(in[c], in[c], 4, 5, 6, 7);
        }
        transpose4<T>(lo[0], lo[1], lo[2], lo[3]);
        transpose4<T>(hi[0], hi[1], hi[2], hi[3]);
        for (int l = 0; l < 4; ++l) {
            rows[l] = lo[l];
            rows[4 + l] = hi[l];
        }
    } else if constexpr (W == 4) {
        Quad<T> r[4] = {in[0], in[1], in[2], in[3]};
        transpose4<T>(r[0], r[1], r[2], r[3]);
        for (int l = 0; l < 4; ++l) rows[l] = r[l];
    } else {
        for (int l = 0; l < W; ++l) rows[l] = Quad<T>{in[0][l], in[1][l], in[2][l], in[3][l]};
    }
}

template <class T, class M>
class Fast final : public FastVariant {
public:
    explicit Fast(const FastOptions& o) : opt_(o) {}

    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = s.size();
        step_ = s.step;
        dt_ = scene.dt;
        gear_ = GearCoefficients<T>::make(scene.dt);
        params_ = setup.contact.template as<T>();
        g_ = cast<T>(scene.gravity);
        walls_ = s.walls;
        nw_ = walls_.size();
        // (min_parallel's default: on the settled beds, 2 threads against 1 took 0.083 against 0.080 µs
        // per particle-step at N = 2000, 0.055 against 0.080 at 4000.)
        par_ = n_ >= opt_.min_parallel;
        prefetch_ = n_ >= opt_.prefetch_from;
        skin_ = T(opt_.skin * setup.radius_max);
        // Cells at least as wide as the longest listed pair; a wider scene cell is honoured (it only
        // changes the candidates, never the contact set).
        cell_ = T(std::max(setup.cell_size, 2.0 * setup.radius_max)) + skin_;
        load_gear_columns<T>(s, {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_});
        for (auto* arr : {&f_, &t_, &xref_, &tmp_}) arr->assign(3 * n_, T(0));
        r_.resize(n_); m_.resize(n_); I_.resize(n_); id_.resize(n_); pos_.resize(n_); tmp1_.resize(n_);
        for (std::size_t i = 0; i < n_; ++i) {
            r_[i] = T(s.radius[i]);
            m_[i] = T(setup.mass[i]);
            I_[i] = T(setup.inertia[i]);
            id_[i] = Index(i);
        }
        wall_rec_.assign(nw_, WallRecord<T>{});
        for (std::size_t w = 0; w < nw_; ++w)
            for (int c = 0; c < 3; ++c) {
                wall_rec_[w].n[c] = T(component(walls_[w].normal, c));
                wall_rec_[w].v[c] = T(component(walls_[w].velocity, c));
            }
        place_walls(step_);
        pstart_.assign(n_ + 1, 0);
        near_wall_.assign(n_, 0);
        wall_first_.assign(n_, 0);
        kin_.resize(n_);
        lstart_.assign(n_ + 1, 0);
        key_.resize(n_);
        rebuilds_ = 0;
        rebuild();
    }

    // One pass over the particles between two force passes, timed as the predictor (docs/variants.md,
    // "fast"): everything that streams the per-particle arrays, done a block at a time while the block
    // is in cache, instead of a pass each.
    // - The corrector of step n fused into the predictor of step n + 1: the Gear arrays read once and
    //   written once (624 B per particle-step; a corrector pass and a predictor pass moved 1152). Between
    //   the two the arrays hold the predicted state and f_/t_ the forces of step n (corrector_pending_);
    //   the corrector's accelerations come from them here, by the same acceleration() as arrays' Newton,
    //   and snapshot() and save() apply the corrector to what they read, so they see the corrected bits.
    // - The displacement check for the neighbour list (search() only reads its answer), the kernel's
    //   records and the particles' wall bits and wall candidates, from the predicted positions.
    // The driver finds correct() empty and search() a rebuild or nothing.
    void predict(std::int64_t step) override
    {
        step_ = step;
        place_walls(step);
        const bool fused = corrector_pending_;
        corrector_pending_ = false;
        per_thread_walls();
        // Rebuild when a pair may have closed by more than the skin since the last rebuild:
        // |Δx_i| + |Δx_j| ≤ 2·max|Δx|. 0.9 leaves room for rounding; a NaN fails the test and goes to
        // the rebuild, whose cell search reports it. (Walls need no list: see mark_walls.)
        const T half = T(0.9) * skin_ * T(0.5);
        int over = !(half > T(0));
        std::size_t listing_team = 1;
#pragma omp parallel reduction(| : over) if (par_)
        {
            const auto [lo, hi] = thread_range(n_);
            const std::size_t t = std::size_t(thread_index());
            if (t == 0) listing_team = std::size_t(thread_count());
            wall_cand_[t].clear();
            for (std::size_t b0 = lo; b0 < hi; b0 += kPassBlock) {
                const std::size_t b1 = std::min(hi, b0 + kPassBlock);
                integrate(b0, b1, fused);
                over |= moved_too_far(b0, b1, half * half);
                refresh_kin(b0, b1);
                mark_walls(b0, b1);
                list_walls(b0, b1, t);
            }
            wall_res_[t].resize(wall_cand_[t].size());
        }
        wall_lists_listed(listing_team);
        rebuild_due_ = over != 0;
    }

    void search() override
    {
        if (rebuild_due_) rebuild();
    }

    void forces() override
    {
        if (opt_.canonical) forces_canonical();
        else forces_unordered();
    }

    // Deferred to the next predict() (fused with its predictor), or applied by snapshot() and save() to
    // what they read.
    void correct() override { corrector_pending_ = true; }

    void snapshot(Snapshot& out) const override
    {
        out.resize(n_);
        out.step = step_;
        for (std::size_t i = 0; i < n_; ++i) {
            const std::size_t s = std::size_t(pos_[i]);
            const std::array<Vec3<T>, 6> trans = gear_state(false, s);
            out.position[i] = cast<double>(trans[0]);
            out.velocity[i] = cast<double>(trans[1]);
            out.angular_velocity[i] = cast<double>(gear_state(true, s)[1]);
            out.force[i] = cast<double>(get(f_, s));
            out.torque[i] = cast<double>(get(t_, s));
        }
    }

    void save(State& out) const override
    {
        out.resize(n_);
        out.step = step_;
        out.walls = walls_;
        std::vector<Vec3d>* dst[2][6] = {{&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5},
                                         {&out.rot.x, &out.rot.v, &out.rot.a, &out.rot.b3, &out.rot.b4, &out.rot.b5}};
        for (int rot = 0; rot < 2; ++rot)
            for (std::size_t i = 0; i < n_; ++i) {
                const std::array<Vec3<T>, 6> g = gear_state(rot == 1, std::size_t(pos_[i]));
                for (int k = 0; k < 6; ++k) (*dst[rot][k])[i] = cast<double>(g[std::size_t(k)]);
            }
        for (std::size_t i = 0; i < n_; ++i) out.radius[i] = double(r_[std::size_t(pos_[i])]);
    }

    ContactCounts counts() const override { return {pp_, pw_, std::int64_t(partner_.size())}; }
    std::int64_t rebuilds() const override { return rebuilds_; }
    // The team of the last force pass; before one, the team it will get (one below min_parallel).
    int threads_used() const override { return team_ > 0 ? int(team_) : par_ ? thread_limit() : 1; }

    std::size_t memory_bytes() const override
    {
        std::size_t b = 0;
        for (const auto* arr : {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_, &f_, &t_, &xref_, &tmp_,
                                &r_, &m_, &I_, &tmp1_})
            b += arr->capacity() * sizeof(T);
        for (const auto* arr : {&id_, &pos_, &pstart_, &partner_, &owner_, &lstart_, &lslot_, &cstart_, &wall_first_, &first_chunk_,
                                &last_chunk_, &last_start_, &by_last_, &first_start_, &by_first_, &group_last_start_,
                                &group_first_start_, &bucket_})
            b += arr->capacity() * sizeof(Index);
        b += (groups_last_.capacity() + groups_first_.capacity()) * sizeof(SumGroup) + group_table_.capacity() * sizeof(std::uint32_t);
        b += slot_.capacity() * sizeof(Slot<T>) + near_wall_.capacity();
        for (const auto& r : rings_) b += r.capacity() * sizeof(Slot<T>);
        b += kin_.capacity() * sizeof(Kin<T>);
        b += (key_.capacity() + keytmp_.capacity()) * sizeof(Key) + cell3_.capacity() * sizeof(std::int64_t);
        for (const auto& l : loads_) b += l.capacity() * sizeof(Load<T>);
        for (const auto& l : wall_res_) b += l.capacity() * sizeof(Load<T>);
        for (const auto& l : wall_cand_) b += l.capacity() * sizeof(WallCandidate);
        for (const auto& v : scan_) b += v.capacity() * sizeof(Index);
        b += (piece_chunk_.capacity() + wall_range_end_.capacity()) * sizeof(std::size_t);
        b += nclaims_ * sizeof(Claim);
        return b;
    }

private:
    Vec3<T> get(const std::vector<T>& a, std::size_t s) const { return {a[s], a[n_ + s], a[2 * n_ + s]}; }
    void put(std::vector<T>& a, std::size_t s, const Vec3<T>& v)
    {
        a[s] = v.x;
        a[n_ + s] = v.y;
        a[2 * n_ + s] = v.z;
    }
    // The corrector and then the predictor on one component of one degree of freedom (integrate()).
    [[gnu::always_inline]] static void correct_predict(T& x, T& v, T& a, T& b3, T& b4, T& b5, T accel, const GearCoefficients<T>& k)
    {
        T x1 = x, v1 = v, a1 = a, b31 = b3, b41 = b4, b51 = b5;
        const T da = accel - a1;
        gear_correct(x1, v1, a1, b31, b41, b51, da, k);
        gear_predict(x1, v1, a1, b31, b41, b51, k);
        x = x1; v = v1; a = a1; b3 = b31; b4 = b41; b5 = b51;
    }

    // The Gear step of particles [b0, b1): the pending corrector (accelerations from the last force
    // pass, a = F/m + g and α = T/I, as Newton's law in arrays) fused with the predictor, or the
    // predictor alone after init. A component block at a time: seven streams in, six out, vectorised.
    void integrate(std::size_t b0, std::size_t b1, bool fused)
    {
        const std::size_t n = n_;
        const GearCoefficients<T> k = gear_;
        const T* __restrict m = m_.data();
        const T* __restrict inertia = I_.data();
        for (int c = 0; c < 3; ++c) {
            const std::size_t o = std::size_t(c) * n;
            T* __restrict x = x_.data() + o; T* __restrict v = v_.data() + o; T* __restrict a = a_.data() + o;
            T* __restrict b3 = b3_.data() + o; T* __restrict b4 = b4_.data() + o; T* __restrict b5 = b5_.data() + o;
            T* __restrict th = th_.data() + o; T* __restrict w = w_.data() + o; T* __restrict al = al_.data() + o;
            T* __restrict r3 = r3_.data() + o; T* __restrict r4 = r4_.data() + o; T* __restrict r5 = r5_.data() + o;
            const T* __restrict f = f_.data() + o;
            const T* __restrict tq = t_.data() + o;
            const T g = component(g_, c);
            if (fused) {
#pragma omp simd
                for (std::size_t s = b0; s < b1; ++s) correct_predict(x[s], v[s], a[s], b3[s], b4[s], b5[s], acceleration(f[s], m[s], g), k);
                if constexpr (M::rotation) {
#pragma omp simd
                    for (std::size_t s = b0; s < b1; ++s) correct_predict(th[s], w[s], al[s], r3[s], r4[s], r5[s], tq[s] / inertia[s], k);
                }
            } else {
#pragma omp simd
                for (std::size_t s = b0; s < b1; ++s) gear_predict(x[s], v[s], a[s], b3[s], b4[s], b5[s], k);
                if constexpr (M::rotation) {
#pragma omp simd
                    for (std::size_t s = b0; s < b1; ++s) gear_predict(th[s], w[s], al[s], r3[s], r4[s], r5[s], k);
                }
            }
        }
    }

    // Has a particle of [b0, b1) moved farther than sqrt(lim2) since the last rebuild (or is its
    // position not finite)? 1 if so.
    int moved_too_far(std::size_t b0, std::size_t b1, T lim2) const
    {
        const std::size_t n = n_;
        const T* __restrict x = x_.data();
        const T* __restrict xr = xref_.data();
        int over = 0;
#pragma omp simd reduction(| : over)
        for (std::size_t s = b0; s < b1; ++s) {
            const T dx = x[s] - xr[s], dy = x[n + s] - xr[n + s], dz = x[2 * n + s] - xr[2 * n + s];
            over |= int(!(dx * dx + dy * dy + dz * dz <= lim2));
        }
        return over;
    }

    // Particle s's six Gear values (x, v, a, b3, b4, b5) for translation or rotation, as the step's
    // corrector leaves them: the arrays' own while no corrector is pending, else the corrector applied to
    // them here, by the same acceleration() and gear_correct as the fused pass (integrate()).
    std::array<Vec3<T>, 6> gear_state(bool rotation, std::size_t s) const
    {
        const std::vector<T>* src[6] = {&x_, &v_, &a_, &b3_, &b4_, &b5_};
        if (rotation) {
            const std::vector<T>* rot[6] = {&th_, &w_, &al_, &r3_, &r4_, &r5_};
            std::copy(rot, rot + 6, src);
        }
        std::array<Vec3<T>, 6> g;
        for (int c = 0; c < 3; ++c) {
            const std::size_t e = std::size_t(c) * n_ + s;
            T q[6];
            for (int k = 0; k < 6; ++k) q[k] = (*src[k])[e];
            if (corrector_pending_ && (M::rotation || !rotation)) {
                const T da = (rotation ? t_[e] / I_[s] : acceleration(f_[e], m_[s], component(g_, c))) - q[2];
                gear_correct(q[0], q[1], q[2], q[3], q[4], q[5], da, gear_);
            }
            for (int k = 0; k < 6; ++k) component(g[std::size_t(k)], c) = q[k];
        }
        return g;
    }

    Vec3<T> wall_point(std::size_t w) const { return {wall_rec_[w].p[0], wall_rec_[w].p[1], wall_rec_[w].p[2]}; }
    Vec3<T> wall_normal(std::size_t w) const { return {wall_rec_[w].n[0], wall_rec_[w].n[1], wall_rec_[w].n[2]}; }

    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < nw_; ++w) {
            const Vec3d p = walls_[w].point_at(step, dt_);
            for (int c = 0; c < 3; ++c) wall_rec_[w].p[c] = T(component(p, c));
        }
    }

    // The law runs on packs of kLanes candidates (the widest vector the target has), sorted kBlock
    // candidates at a time (slots_of).
    using Lanes = Pack<T, native_lanes<T>>;
    static constexpr int kLanes = native_lanes<T>;
    static constexpr std::size_t kBlock = 1024;
    static constexpr std::size_t kWallBits = 8;  // near_wall_ holds a bit per wall up to this many walls
    static constexpr std::size_t kChunk = 128;  // particles per chunk of the canonical sweep (forces_canonical)
    // The kernel prefetches its partners' records kPrefetch candidates ahead from FastOptions::prefetch_from
    // particles on (8000), where the records (96 bytes each) no longer stay in the caches between force
    // passes. Measured on the settled beds, one thread, interleaved in one run (20–24 repetitions), the
    // force pass with and without: +1 % at 2000 grains, +2 % at 4000, -0.5 % at 8000, -10 % at 16000,
    // -21 % at 32000; -16 % at 10⁵ on two threads (prefetching 384 ahead: -6 % at 16000, -19 % at 32000).
    // fast_unordered's loads besides: -3 % at 16000, -19 % at 32000, -17 % at 64000, -20 % at 10⁵ on two.
    static constexpr std::size_t kPrefetch = 128;
    static constexpr int kGroup = 4;            // particles per sum group (sum_group)
    // Particles per block of predict()'s pass, whose arrays stay in cache from one step of the pass to the
    // next (settled bed of 10⁵, interleaved in one process, 16 repetitions: 256, 1024 and 4096 within 1 %
    // on one thread; on two, 1024 took 8 % less than 256 and 3 % less than 4096).
    static constexpr std::size_t kPassBlock = 1024;

    // A group of the canonical sums (sum_group): its particles (-1: none), the longest of their lists as
    // j and as i, and where its table starts in group_table_.
    struct SumGroup {
        Index grain[kGroup] = {};
        std::int32_t count = 0, as_j = 0, as_i = 0;
        std::uint32_t table = 0;
    };

    // Slots [k0, k1) (owner s, partner q): the contacts among them, each into its slot (canonical mode,
    // through `sink`) or added to the loads `load` of both particles (unordered mode). A canonical sum
    // reads every slot of a particle, so there a pair out of contact holds zeros, which add nothing (a sum
    // that starts at +0 is never -0, and x + ±0 = x for every other x), so the bits are those of arrays,
    // which skips the pair; reading zeros costs less than a branch that is taken at random (a dropped
    // pair's slot is zeroed every step: the ring's slot k & mask held another pair's). may_touch first, a
    // cheap and conservative test (the law rejects every pair it rejects), so the skin's extra candidates
    // cost a distance, not a pass through the law; the rest go through the law kLanes at a time. The test
    // sorts the slots into kept and dropped without a branch (a third are dropped, in no pattern a
    // predictor learns). Returns the contacts found.
    template <bool Canonical>
    std::int64_t slots_of(std::size_t k0, std::size_t k1, Load<T>* load, const SlotSink<T>& sink = {})
    {
        const Index* owner = owner_.data();
        const Index* partner = partner_.data();
        const Kin<T>* kin = kin_.data();
        std::size_t kept[kBlock], dropped[kBlock];
        std::int64_t found = 0;
        for (std::size_t c0 = k0; c0 < k1; c0 += kBlock) {
            const std::size_t c1 = std::min(k1, c0 + kBlock);
            std::size_t nk = 0, nd = 0;
            std::size_t k = c0;
            // kLanes candidates at a time: both records transposed into lanes, the test on the lanes
            // (the remainder one by one).
            for (; k + kLanes <= c1; k += kLanes) {
                if (prefetch_) {
                    // The partners' records kPrefetch candidates ahead (both cache lines of each), and in
                    // unordered mode their loads: owners come in storage order, which the hardware
                    // prefetches, partners from anywhere in the sweep's reach, which it does not.
                    const std::size_t ahead = std::min(k + kPrefetch, partner_.size() - kLanes);
                    for (int l = 0; l < kLanes; ++l) {
                        const char* rec = reinterpret_cast<const char*>(&kin[partner[ahead + std::size_t(l)]]);
                        __builtin_prefetch(rec);
                        __builtin_prefetch(rec + 64);
                        if constexpr (!Canonical) __builtin_prefetch(&load[partner[ahead + std::size_t(l)]], 1);
                    }
                }
                Quad<T> rows[kLanes];
                Lanes a[4], b[4];
                for (int l = 0; l < kLanes; ++l) rows[l] = kin[owner[k + std::size_t(l)]].xr;
                rows_to_lanes<Lanes>(rows, a);
                for (int l = 0; l < kLanes; ++l) rows[l] = kin[partner[k + std::size_t(l)]].xr;
                rows_to_lanes<Lanes>(rows, b);
                const auto t = may_touch_lanes(Vec3<Lanes>{a[0], a[1], a[2]}, Vec3<Lanes>{b[0], b[1], b[2]}, a[3], b[3]);
                for (int l = 0; l < kLanes; ++l) {
                    kept[nk] = k + std::size_t(l);
                    dropped[nd] = k + std::size_t(l);
                    nk += std::size_t(t[l] != 0);
                    nd += std::size_t(t[l] == 0);
                }
            }
            for (; k < c1; ++k) {
                const Quad<T> a = kin[owner[k]].xr, b = kin[partner[k]].xr;
                const bool t = may_touch(Vec3<T>{a[0], a[1], a[2]}, Vec3<T>{b[0], b[1], b[2]}, a[3], b[3]);
                kept[nk] = k;
                dropped[nd] = k;
                nk += std::size_t(t);
                nd += std::size_t(!t);
            }
            if constexpr (Canonical)
                for (std::size_t e = 0; e < nd; ++e) sink.put(dropped[e], Slot<T>{});
            for (std::size_t e = 0; e < nk; e += kLanes)
                found += pack_of_slots<Canonical>(kept + e, int(std::min<std::size_t>(kLanes, nk - e)), load, sink);
        }
        return found;
    }

    // The law for up to kLanes slots at once (unused lanes repeat the last slot and are not stored):
    // both particles' records and the pair's coefficients (computed when it was listed) transposed into
    // the lanes, particle_contact_lanes, and the lanes transposed back into the slots (zeros where
    // h <= 0) or added to the loads. Each lane's bits are those particle_contact gives for its slot's pair.
    template <bool Canonical>
    int pack_of_slots(const std::size_t* ks, int count, Load<T>* load, const SlotSink<T>& sink)
    {
        std::size_t k[kLanes], s[kLanes], q[kLanes];
        for (int l = 0; l < kLanes; ++l) {
            k[l] = ks[l < count ? l : count - 1];
            s[l] = std::size_t(owner_[k[l]]);
            q[l] = std::size_t(partner_[k[l]]);
        }
        Quad<T> rows[kLanes];
        Lanes xi[4]{}, xj[4]{}, vi[4]{}, vj[4]{}, wi[4]{}, wj[4]{};
        const Kin<T>* kin = kin_.data();
        auto lanes = [&](auto&& row, Lanes* out) {
            for (int l = 0; l < kLanes; ++l) rows[l] = row(l);
            rows_to_lanes<Lanes>(rows, out);
        };
        lanes([&](int l) -> const Quad<T>& { return kin[s[l]].xr; }, xi);
        lanes([&](int l) -> const Quad<T>& { return kin[q[l]].xr; }, xj);
        lanes([&](int l) -> const Quad<T>& { return kin[s[l]].v; }, vi);
        lanes([&](int l) -> const Quad<T>& { return kin[q[l]].v; }, vj);
        if constexpr (M::rotation) {
            lanes([&](int l) -> const Quad<T>& { return kin[s[l]].w; }, wi);
            lanes([&](int l) -> const Quad<T>& { return kin[q[l]].w; }, wj);
        }
        ContactForce<Lanes> c;
        // The pair's coefficients from R and m in the lanes (computing them costs less than reading
        // them from a per-pair array: measured, settled beds of 2000–32000, one thread).
        const auto touch = particle_contact_lanes<M>(
            Vec3<Lanes>{xi[0], xi[1], xi[2]}, Vec3<Lanes>{xj[0], xj[1], xj[2]}, Vec3<Lanes>{vi[0], vi[1], vi[2]},
            Vec3<Lanes>{vj[0], vj[1], vj[2]}, Vec3<Lanes>{wi[0], wi[1], wi[2]}, Vec3<Lanes>{wj[0], wj[1], wj[2]}, xi[3], xj[3], vi[3],
            vj[3], params_, Coefficients<Lanes>{}, c);
        int found = 0;
        for (int l = 0; l < count; ++l) found += int(touch[l] != 0);
        if constexpr (Canonical) {
            // A slot is nine values: f, t_i, t_j; the first eight go as two quads, the ninth alone.
            static_assert(sizeof(Slot<T>) == 9 * sizeof(T));
            const Lanes g0[4] = {c.f_i.x, c.f_i.y, c.f_i.z, c.t_i.x}, g1[4] = {c.t_i.y, c.t_i.z, c.t_j.x, c.t_j.y};
            Quad<T> r0[kLanes], r1[kLanes];
            lanes_to_rows<Lanes>(g0, r0);
            lanes_to_rows<Lanes>(g1, r1);
            for (int l = 0; l < count; ++l) {
                Slot<T> out;
                char* bytes = reinterpret_cast<char*>(&out);
                std::memcpy(bytes, &r0[l], sizeof(Quad<T>));
                std::memcpy(bytes + sizeof(Quad<T>), &r1[l], sizeof(Quad<T>));
                out.tj.z = c.t_j.z[l];
                sink.put(k[l], out);
            }
        } else {
            // Added as they come, lane by lane (a particle may sit in several lanes).
            const Lanes zero{};
            const Lanes gf[4] = {c.f_i.x, c.f_i.y, c.f_i.z, zero}, gi[4] = {c.t_i.x, c.t_i.y, c.t_i.z, zero},
                        gj[4] = {c.t_j.x, c.t_j.y, c.t_j.z, zero};
            Quad<T> f[kLanes], ti[kLanes], tj[kLanes];
            lanes_to_rows<Lanes>(gf, f);
            if constexpr (M::rotation) {
                lanes_to_rows<Lanes>(gi, ti);
                lanes_to_rows<Lanes>(gj, tj);
            }
            for (int l = 0; l < count; ++l) {
                load[s[l]].f += f[l];
                load[q[l]].f -= f[l];
                if constexpr (M::rotation) {
                    load[s[l]].t += ti[l];
                    load[q[l]].t += tj[l];
                }
            }
        }
        return found;
    }

    // The kernel's per-particle records for [lo, hi), from the state arrays: four particles at a time, a
    // quad of each array transposed into their four records (against a record at a time from scalar
    // loads, interleaved in one run: force pass -5 % at 16000 grains, -4 % at 32000), the rest one by one.
    void refresh_kin(std::size_t lo, std::size_t hi)
    {
        const std::size_t n = n_;
        const T* __restrict x = x_.data();
        const T* __restrict v = v_.data();
        const T* __restrict w = w_.data();
        const T* __restrict r = r_.data();
        const T* __restrict m = m_.data();
        Kin<T>* __restrict kin = kin_.data();
        auto records = [&](std::size_t s, const T* c, const Quad<T>& fourth, Quad<T> Kin<T>::*field) {
            Quad<T> a, b, d, e = fourth;
            load_quad(a, c + s);
            load_quad(b, c + n + s);
            load_quad(d, c + 2 * n + s);
            transpose4<T>(a, b, d, e);
            kin[s].*field = a;
            kin[s + 1].*field = b;
            kin[s + 2].*field = d;
            kin[s + 3].*field = e;
        };
        std::size_t s = lo;
        for (; s + 4 <= hi; s += 4) {
            Quad<T> radii, masses;
            load_quad(radii, r + s);
            load_quad(masses, m + s);
            records(s, x, radii, &Kin<T>::xr);
            records(s, v, masses, &Kin<T>::v);
            records(s, w, Quad<T>{}, &Kin<T>::w);
        }
        for (; s < hi; ++s) {
            kin[s].xr = Quad<T>{x[s], x[n + s], x[2 * n + s], r[s]};
            kin[s].v = Quad<T>{v[s], v[n + s], v[2 * n + s], m[s]};
            kin[s].w = Quad<T>{w[s], w[n + s], w[2 * n + s], T(0)};
        }
    }

    void forces_canonical()
    {
        const std::size_t n = n_;
        std::int64_t pp = 0, pw = 0;
        const Index* pstart = pstart_.data();
        const Index* by_last = by_last_.data();
        const Index* last_start = last_start_.data();
        const Index* first_chunk = first_chunk_.data();
        const Index* last_chunk = last_chunk_.data();
        const std::size_t chunks = (n + kChunk - 1) / kChunk, span = span_chunks_;
        const std::size_t limit = std::size_t(thread_limit());
        per_thread_claims();
        std::size_t team = 1;
        if (rings_.size() < limit) rings_.resize(limit);
#pragma omp parallel reduction(+ : pp, pw) if (par_)
        {
            const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
            if (t == 0) team = nt;
            // Two threads to a piece, one from each end; an odd thread count leaves the last piece one.
            const std::size_t pieces = (nt + 1) / 2, p = t / 2;
            const bool down = t % 2 == 1;
#pragma omp single
            {
                cut_pieces(pieces, chunks);
                for (std::size_t q = 0; q < pieces; ++q)
                    claims_[q].v.store(std::uint64_t(piece_chunk_[q + 1]) << 32 | std::uint64_t(piece_chunk_[q]), std::memory_order_relaxed);
                if (pieces > 1) slot_.resize(partner_.size() + 1);  // + 1: a sum reads a quad from the last slot's t_j
            }
            std::vector<Slot<T>>& ring = rings_[t];
            // + 2: the slot of zeros at ring_slots_ (the groups' padding), and the quad the sums read from
            // the last value of a slot (its fourth lane, unused), past the end.
            if (ring.size() < ring_slots_ + 2) ring.assign(ring_slots_ + 2, Slot<T>{});
            ring[ring_slots_] = ring[ring_slots_ + 1] = Slot<T>{};  // a larger ring from before may hold slots there
            // The kernel's records and every thread's wall candidates are ready (predict(), or a rebuild).
            pw += wall_contacts();
#pragma omp barrier
            // The pair kernel and the canonical sums in one sweep over the storage order, so that each
            // particle's slots are summed from a ring that stays in cache, not from a list of them all
            // (at 32000 grains, 10 MB written and read back every step). A piece of the storage is swept
            // by two threads, chunk by chunk, one upwards from its start and one downwards from its end,
            // until they meet (wherever the machine lets them: neither waits for the other). After each
            // chunk, the upward thread sums the particles whose last slot (as i or as j) was in it, the
            // downward one those whose first was, when all their slots are in its ring. The others straddle
            // the meeting point or the end of a piece; they are summed after the sweep (straddlers). Which
            // thread sums a particle, and when, changes no bit of its sum.
            const std::size_t c0 = piece_chunk_[p], c1 = piece_chunk_[p + 1];
            const SlotSink<T> in_ring{ring.data(), ring_slots_ - 1, nullptr};
            for (std::size_t ch; down ? claim_down(claims_[p], ch) : claim_up(claims_[p], ch);) {
                // Slots near the end of a piece are also kept in slot_, for the sums that straddle two pieces.
                const bool edge = (p > 0 && ch < c0 + span) || (p + 1 < pieces && ch + span >= c1);
                const SlotSink<T> sink{in_ring.ring, in_ring.mask, edge ? slot_.data() : nullptr};
                pp += slots_of<true>(std::size_t(pstart[ch * kChunk]), std::size_t(pstart[std::min(n, (ch + 1) * kChunk)]), nullptr, sink);
                // The groups of this chunk's schedule; a group with a particle that straddles the end of
                // the piece (three threads or more) goes a particle at a time, without that one.
                const SlotSource<T> from{in_ring.ring, in_ring.ring, in_ring.mask, 0};
                const std::vector<SumGroup>& groups = down ? groups_first_ : groups_last_;
                const Index* group_start = down ? group_first_start_.data() : group_last_start_.data();
                for (Index q = group_start[ch]; q < group_start[ch + 1]; ++q) {
                    const SumGroup& g = groups[std::size_t(q)];
                    auto inside = [&](Index s) {
                        return down ? std::size_t(last_chunk[s]) < c1 : std::size_t(first_chunk[s]) >= c0;
                    };
                    bool all = true;
                    for (int l = 0; l < g.count; ++l) all = all && inside(g.grain[l]);
                    if (all) {
                        sum_group(g, in_ring.ring);
                        continue;
                    }
                    for (int l = 0; l < g.count; ++l)
                        if (inside(g.grain[l])) sum_particle(std::size_t(g.grain[l]), from);
                }
            }
#pragma omp barrier
            {
                // The particles of this piece that straddle its meeting point m (their last chunk is one of
                // m … m + span, shared out between the piece's two threads): their slots below m are in the
                // upward thread's ring, those from m on in the downward one's (each holds the last
                // ring_slots_ it wrote, and no sum reaches over more). A piece of one thread met at its end.
                const std::size_t m = std::size_t(claims_[p].v.load(std::memory_order_relaxed) & 0xffffffffu);
                const std::size_t up = down ? t - 1 : t, other = !down && t + 1 == nt ? t : up + 1;
                const SlotSource<T> split{rings_[up].data(), rings_[other].data(), ring_slots_ - 1, std::size_t(pstart[std::min(n, m * kChunk)])};
                const std::size_t e1 = std::min(c1, m + span + 1), mid = m + (e1 - m) / 2;
                for (std::size_t ch = down ? mid : m; ch < (down ? e1 : mid); ++ch)
                    for (Index e = last_start[ch]; e < last_start[ch + 1]; ++e) {
                        const std::size_t s = std::size_t(by_last[e]), f = std::size_t(first_chunk[s]);
                        if (f >= c0 && f < m) sum_particle(s, split);
                    }
            }
            if (!down) {
                // Those whose first slot is in the piece before (slot_ holds all the slots they read).
                if (p > 0) {
                    const SlotSource<T> all{slot_.data(), slot_.data(), ~std::size_t(0), 0};
                    const std::size_t b0 = piece_chunk_[p - 1];
                    for (std::size_t ch = c0; ch < std::min(chunks, c0 + span + 1); ++ch)
                        for (Index e = last_start[ch]; e < last_start[ch + 1]; ++e) {
                            const std::size_t s = std::size_t(by_last[e]), f = std::size_t(first_chunk[s]);
                            if (f >= b0 && f < c0) sum_particle(s, all);
                        }
                }
            }
        }
        pp_ = pp;
        pw_ = pw;
        team_ = team;
    }

    // A piece's claims: the next chunk up (low 32 bits) and one past the next chunk down (high 32 bits);
    // the sweep ends where they meet. One cache line each.
    struct alignas(64) Claim {
        std::atomic<std::uint64_t> v{0};
    };
    static bool claim_up(Claim& c, std::size_t& ch)
    {
        std::uint64_t v = c.v.load(std::memory_order_relaxed);
        for (;;) {
            const std::uint64_t up = v & 0xffffffffu, down = v >> 32;
            if (up >= down) return false;
            if (c.v.compare_exchange_weak(v, down << 32 | (up + 1), std::memory_order_relaxed)) {
                ch = std::size_t(up);
                return true;
            }
        }
    }
    static bool claim_down(Claim& c, std::size_t& ch)
    {
        std::uint64_t v = c.v.load(std::memory_order_relaxed);
        for (;;) {
            const std::uint64_t up = v & 0xffffffffu, down = v >> 32;
            if (up >= down) return false;
            if (c.v.compare_exchange_weak(v, (down - 1) << 32 | up, std::memory_order_relaxed)) {
                ch = std::size_t(down - 1);
                return true;
            }
        }
    }
    void per_thread_claims()
    {
        const std::size_t limit = std::size_t(thread_limit());
        if (nclaims_ < limit) {
            claims_ = std::make_unique<Claim[]>(limit);
            nclaims_ = limit;
        }
    }

    // piece_chunk_[p], p = 0 … pieces: where each piece of the sweep starts, in chunks, cut so that the
    // pieces hold about as many slots each.
    void cut_pieces(std::size_t pieces, std::size_t chunks)
    {
        piece_chunk_.resize(pieces + 1);
        const std::size_t total = partner_.size();
        std::size_t ch = 0;
        piece_chunk_[0] = 0;
        for (std::size_t p = 1; p < pieces; ++p) {
            const std::size_t want = total * p / pieces;
            while (ch < chunks && std::size_t(pstart_[ch * kChunk]) < want) ++ch;
            piece_chunk_[p] = ch;
        }
        piece_chunk_[pieces] = chunks;
    }

    // Particle s's sum in the canonical order: as j (partners of lower id, ascending), as i (partners of
    // higher id, ascending), its walls in wall order, into f_ and t_ (Newton's law comes in the next
    // step's pass, vectorised, with the corrector: done here, a grain at a time, its six scalar divisions
    // made the force pass 5 % longer, measured at 16000 grains on one thread and at 10⁵ on two). The
    // slots from `from`.
    // The three components of a sum go as lanes of one quad (lane by lane, the scalar additions; x - y is
    // x + (-y)), each read as the quad that starts at it in the slot: f, t_i and t_j are three consecutive
    // values, and the fourth lane, the next value along, is not used.
    void sum_particle(std::size_t s, const SlotSource<T>& from)
    {
        const T* lo = reinterpret_cast<const T*>(from.lo);
        const T* hi = reinterpret_cast<const T*>(from.hi);
        const std::size_t mask = from.mask, split = from.split;
        auto at = [=](std::size_t k, std::size_t offset) { return (k < split ? lo : hi) + 9 * (k & mask) + offset; };
        const Index* lslot = lslot_.data();
        Quad<T> f{}, tq{};
        for (Index e = lstart_[s]; e < lstart_[s + 1]; ++e) {
            const std::size_t k = std::size_t(lslot[e]);
            Quad<T> q;
            load_quad(q, at(k, 0));
            f -= q;
            if constexpr (M::rotation) {
                load_quad(q, at(k, 6));
                tq += q;
            }
        }
        for (Index k = pstart_[s]; k < pstart_[s + 1]; ++k) {
            Quad<T> q;
            load_quad(q, at(std::size_t(k), 0));
            f += q;
            if constexpr (M::rotation) {
                load_quad(q, at(std::size_t(k), 3));
                tq += q;
            }
        }
        finish_sum(s, f, tq);
    }

    // The sums of a group of up to kGroup particles of one chunk's schedule, side by side: a chain of
    // additions per particle, all from the ring. One particle's sum alone (sum_particle) is a chain of
    // dependent additions ended by two loop exits whose trip counts no predictor learns; here the chains
    // overlap and a group has two exits (measured against sum_particle for every particle, interleaved in
    // one run: the force pass 10 % shorter at 16000 grains, 6 % at 32000, 5 % at 10⁵ on two threads, 1 %
    // at 4000). The group's table (build_groups) holds the ring offsets in the canonical order, as j then
    // as i, a row of kGroup a step; a particle's list that ends before the group's longest goes on with
    // the ring's slot of zeros, which adds nothing (the sum starts at +0 and is never -0, and x + ±0 = x
    // for every other x), so each particle's bits are those of sum_particle (the same order, kept there for
    // the sums that read two rings or the list of all slots, which the tables' ring offsets cannot name).
    void sum_group(const SumGroup& g, const Slot<T>* ring)
    {
        const char* base = reinterpret_cast<const char*>(ring);
        const char* ti = base + 3 * sizeof(T);  // where the torques start, for a slot at offset 0
        const char* tj = base + 6 * sizeof(T);
        auto add = [](Quad<T>& sum, const char* at) {
            Quad<T> q;
            std::memcpy(&q, at, sizeof(q));
            sum += q;
        };
        auto subtract = [](Quad<T>& sum, const char* at) {
            Quad<T> q;
            std::memcpy(&q, at, sizeof(q));
            sum -= q;
        };
        const std::uint32_t* row = group_table_.data() + g.table;
        Quad<T> f[kGroup]{}, tq[kGroup]{};
        for (std::int32_t e = 0; e < g.as_j; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) {
                subtract(f[l], base + row[l]);
                if constexpr (M::rotation) add(tq[l], tj + row[l]);
            }
        for (std::int32_t e = 0; e < g.as_i; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) {
                add(f[l], base + row[l]);
                if constexpr (M::rotation) add(tq[l], ti + row[l]);
            }
        for (int l = 0; l < g.count; ++l) finish_sum(std::size_t(g.grain[l]), f[l], tq[l]);
    }

    // Particle s's walls added to its sum (f, tq), in wall order (zeros for a pair out of contact add
    // nothing).
    void add_walls(std::size_t s, Quad<T>& f, Quad<T>& tq) const
    {
        if (!near_wall_[s]) return;
        std::size_t u = 0;  // the list that holds s: its range among the listing team's (a loop, not a division: cheaper)
        while (s >= wall_range_end_[u]) ++u;
        const std::vector<WallCandidate>& cand = wall_cand_[u];
        const Load<T>* res = wall_res_[u].data();
        for (std::size_t e = std::size_t(wall_first_[s]); e < cand.size() && std::size_t(cand[e].s) == s; ++e) {
            f += res[e].f;
            if constexpr (M::rotation) tq += res[e].t;
        }
    }

    // The wall candidates were listed by a team of `team` threads, each its range of the particles
    // (thread_range), into wall_cand_[0 … team): the force pass, whatever its own team (OpenMP's dynamic
    // teams may give it another), reads those lists and finds a particle's by these ranges.
    void wall_lists_listed(std::size_t team)
    {
        wall_lists_ = team;
        wall_range_end_.resize(team);
        for (std::size_t u = 0; u < team; ++u) wall_range_end_[u] = n_ * (u + 1) / team;  // thread_range's ends
    }

    // Particle s's walls added to its sum (f, tq), and the sum stored in f_ and t_.
    void finish_sum(std::size_t s, Quad<T>& f, Quad<T>& tq)
    {
        add_walls(s, f, tq);
        const std::size_t n = n_;
        for (int c = 0; c < 3; ++c) {
            f_[std::size_t(c) * n + s] = f[c];
            t_[std::size_t(c) * n + s] = tq[c];
        }
    }

    // This thread's share of the particles, [lo, hi) (inside a parallel region; all of them outside).
    static std::pair<std::size_t, std::size_t> thread_range(std::size_t n)
    {
        const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
        return {n * t / nt, n * (t + 1) / nt};
    }

    // near_wall[s] for s in [lo, hi): which walls may s touch (may_touch_wall, vectorised over the
    // particles, a wall at a time)? Bit w for wall w in a scene of at most kWallBits walls; beyond, one
    // bit for any, and the candidates test each wall again for the particles marked (in a bed most touch
    // none). A scene has a handful of walls: testing each every step costs less than a wall list, and
    // keeps the moving wall out of the rebuild criterion.
    void mark_walls(std::size_t lo, std::size_t hi)
    {
        const std::size_t n = n_;
        const T* __restrict x = x_.data();
        const T* __restrict r = r_.data();
        std::uint8_t* __restrict near = near_wall_.data();
        std::fill(near + lo, near + hi, std::uint8_t(0));
        // A chunk of particles at a time, every wall over it, so that the chunk's positions are read
        // from memory once, not once per wall.
        constexpr std::size_t chunk = 512;
        for (std::size_t c0 = lo; c0 < hi; c0 += chunk) {
            const std::size_t c1 = std::min(hi, c0 + chunk);
            for (std::size_t w = 0; w < nw_; ++w) {
                const Vec3<T> p = wall_point(w), nrm = wall_normal(w);
                const int bit = nw_ <= kWallBits ? int(w) : 0;
#pragma omp simd
                for (std::size_t s = c0; s < c1; ++s)
                    near[s] |= std::uint8_t(std::uint8_t(may_touch_wall(Vec3<T>{x[s], x[n + s], x[2 * n + s]}, r[s], p, nrm)) << bit);
            }
        }
    }

    void per_thread_walls()
    {
        const std::size_t limit = std::size_t(thread_limit());
        if (wall_cand_.size() < limit) {
            wall_cand_.resize(limit);
            wall_res_.resize(limit);
        }
    }

    // Appends the particle–wall pairs of [lo, hi), in thread t's range, that may touch (by particle, then
    // wall order; from the bits of mark_walls) to wall_cand_[t].
    void list_walls(std::size_t lo, std::size_t hi, std::size_t t)
    {
        std::vector<WallCandidate>& cand = wall_cand_[t];
        const std::uint8_t* near = near_wall_.data();
        for (std::size_t s = lo; s < hi; ++s) {
            if (!near[s]) continue;
            wall_first_[s] = Index(cand.size());
            if (nw_ <= kWallBits) {  // the walls are the bits, ascending
                for (unsigned m = near[s]; m != 0; m &= m - 1) cand.push_back({Index(s), Index(__builtin_ctz(m))});
                continue;
            }
            const Quad<T> xr = kin_[s].xr;
            for (std::size_t w = 0; w < nw_; ++w)
                if (may_touch_wall(Vec3<T>{xr[0], xr[1], xr[2]}, xr[3], wall_point(w), wall_normal(w))) cand.push_back({Index(s), Index(w)});
        }
    }

    // The law on every thread's wall candidates, kLanes pairs at a time, the packs shared out among the
    // threads whoever's particles they are (a wall's grains may all fall in one thread's range of storage:
    // the floor's did while the cell key put z slowest), into wall_res_ (zeros where h <= 0); no barrier
    // at the end. Inside a parallel region, after the candidates of every thread are listed. Returns the
    // contacts found.
    std::int64_t wall_contacts()
    {
        const std::size_t nt = wall_lists_;
        auto packs_of = [this](std::size_t u) { return (wall_cand_[u].size() + kLanes - 1) / kLanes; };
        std::size_t packs = 0;
        for (std::size_t u = 0; u < nt; ++u) packs += packs_of(u);
        std::int64_t found = 0;
#pragma omp for schedule(static) nowait
        for (std::size_t p = 0; p < packs; ++p) {
            std::size_t u = 0, first = 0;  // the list that pack p falls in, and its first pack
            while (p >= first + packs_of(u)) first += packs_of(u++);
            const std::size_t e = (p - first) * kLanes, count = std::min<std::size_t>(kLanes, wall_cand_[u].size() - e);
            found += pack_of_walls(wall_cand_[u].data() + e, int(count), wall_res_[u].data() + e);
        }
        return found;
    }

    // The wall law for up to kLanes particle–wall pairs, as pack_of_slots for pairs; each lane's bits
    // are those wall_contact gives.
    int pack_of_walls(const WallCandidate* cand, int count, Load<T>* out) const
    {
        std::size_t s[kLanes], w[kLanes];
        for (int l = 0; l < kLanes; ++l) {
            s[l] = std::size_t(cand[l < count ? l : count - 1].s);
            w[l] = std::size_t(cand[l < count ? l : count - 1].w);
        }
        Quad<T> rows[kLanes];
        Lanes xr[4]{}, v[4]{}, om[4]{}, p[4]{}, nrm[4]{}, vw[4]{};
        auto lanes = [&](auto&& row, Lanes* to) {
            for (int l = 0; l < kLanes; ++l) rows[l] = row(l);
            rows_to_lanes<Lanes>(rows, to);
        };
        lanes([&](int l) -> const Quad<T>& { return kin_[s[l]].xr; }, xr);
        lanes([&](int l) -> const Quad<T>& { return kin_[s[l]].v; }, v);
        if constexpr (M::rotation) lanes([&](int l) -> const Quad<T>& { return kin_[s[l]].w; }, om);
        lanes([&](int l) -> const Quad<T>& { return wall_rec_[w[l]].p; }, p);
        lanes([&](int l) -> const Quad<T>& { return wall_rec_[w[l]].n; }, nrm);
        if constexpr (M::moving_walls) lanes([&](int l) -> const Quad<T>& { return wall_rec_[w[l]].v; }, vw);
        ContactForce<Lanes> c;
        auto vec = [](const Lanes* a) { return Vec3<Lanes>{a[0], a[1], a[2]}; };
        static_assert(M::polydisperse, "the wall kernel computes each particle's coefficients");
        const auto touch = wall_contact_lanes<M>(vec(xr), vec(v), vec(om), xr[3], v[3], vec(p), vec(nrm), vec(vw), params_,
                                                 Coefficients<Lanes>{}, c);
        const Lanes zero{};
        const Lanes gf[4] = {c.f_i.x, c.f_i.y, c.f_i.z, zero}, gt[4] = {c.t_i.x, c.t_i.y, c.t_i.z, zero};
        Quad<T> f[kLanes], tq[kLanes];
        lanes_to_rows<Lanes>(gf, f);
        if constexpr (M::rotation) lanes_to_rows<Lanes>(gt, tq);
        int found = 0;
        for (int l = 0; l < count; ++l) {
            out[l].f = f[l];
            if constexpr (M::rotation) out[l].t = tq[l];
            found += int(touch[l] != 0);
        }
        return found;
    }

    // Unordered: each pair's force added to both particles as the pack computes it, into loads of the
    // thread's own (zeroed over the span of particles its slots reach, set at the rebuild), then each
    // particle's loads summed over the threads whose span holds it, in thread order, and its walls.
    void forces_unordered()
    {
        const std::size_t n = n_;
        const std::size_t limit = std::size_t(thread_limit());
        if (loads_.size() < limit) loads_.resize(limit);
        std::int64_t pp = 0, pw = 0;
        std::size_t team = 1;
#pragma omp parallel reduction(+ : pp, pw) if (par_)
        {
            const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
            if (t == 0) team = nt;
            const auto [lo, hi] = thread_range(n);
            // A thread count other than the rebuild's (no rebuild since it changed): every thread zeroes all.
            const bool spans_known = span_threads_ == nt;
            std::vector<Load<T>>& mine = loads_[t];
            if (mine.size() != n) mine.resize(n);
            const auto [z0, z1] = spans_known ? spans_[t] : std::pair<std::size_t, std::size_t>{0, n};
            std::fill(mine.begin() + std::ptrdiff_t(z0), mine.begin() + std::ptrdiff_t(z1), Load<T>{});
            pw += wall_contacts();
            pp += slots_of<false>(std::size_t(pstart_[lo]), std::size_t(pstart_[hi]), mine.data());
#pragma omp barrier
            for (std::size_t s = lo; s < hi; ++s) {
                Quad<T> f{}, tq{};
                for (std::size_t u = 0; u < nt; ++u) {
                    const auto [u0, u1] = spans_known ? spans_[u] : std::pair<std::size_t, std::size_t>{0, n};
                    if (s < u0 || s >= u1) continue;
                    f += loads_[u][s].f;
                    tq += loads_[u][s].t;
                }
                add_walls(s, f, tq);
                put(f_, s, Vec3<T>{f[0], f[1], f[2]});
                put(t_, s, Vec3<T>{tq[0], tq[1], tq[2]});
            }
        }
        pp_ = pp;
        pw_ = pw;
        team_ = team;
    }

    // ---- the neighbour list ---------------------------------------------------------------------

    // Re-sorts the particles into cell order and lists, for each particle, its partners of higher id
    // closer than R_i + R_j + skin (ascending id) and the slots where it is the partner (ascending id
    // of the owner).
    void rebuild()
    {
        ++rebuilds_;
        const std::size_t n = n_;
        if (n == 0) return;
        // Cells over the bounding box, padded by one empty layer so that cx ± 1 stays inside; key =
        // linear cell index, x fastest, so the three cells of a row are one key range.
        cell3_.resize(3 * n);
        T lo[3];
        std::int64_t dims[3];
        std::size_t ends[3][2];  // slots of the lowest and highest particle on each axis
        for (int c = 0; c < 3; ++c) {
            const T* xc = x_.data() + std::size_t(c) * n;
            std::int64_t* qc = cell3_.data() + std::size_t(c) * n;
            ends[c][0] = std::size_t(std::min_element(xc, xc + n) - xc);
            ends[c][1] = ends[c][0];
            lo[c] = xc[ends[c][0]];
            std::int64_t hi = 0;
            for (std::size_t s = 0; s < n; ++s) {
                qc[s] = cell_coordinate((xc[s] - lo[c]) / cell_, std::size_t(id_[s])) + 1;
                if (qc[s] > hi) {
                    hi = qc[s];
                    ends[c][1] = s;
                }
            }
            dims[c] = hi + 2;
        }
        const double cells = double(dims[0]) * double(dims[1]) * double(dims[2]);
        if (cells > 0x1p62) {
            // Finite but runaway positions: name the end of the widest axis farther from the mean.
            const int c = int(std::max_element(dims, dims + 3) - dims);
            const T* xc = x_.data() + std::size_t(c) * n;
            double mean = 0.0;
            for (std::size_t s = 0; s < n; ++s) mean += double(xc[s]) / double(n);
            const std::size_t far = std::abs(double(xc[ends[c][1]]) - mean) > std::abs(double(xc[ends[c][0]]) - mean) ? ends[c][1] : ends[c][0];
            throw InstabilityError(fmt::format("particle {} has a runaway position (found by the fast variant's cell search)", id_[far]), -1,
                                   std::int64_t(id_[far]));
        }
        // The axes in the key by extent, the shortest fastest, so that the particles a pair can join (the
        // 27 cells around) lie as close in storage as the box allows: in a flat bed, a slice across its
        // longest axis, not a horizontal layer.
        int ax[3] = {0, 1, 2};
        std::sort(ax, ax + 3, [&](int a, int b) { return dims[a] < dims[b]; });
        dims_[0] = dims[ax[0]];
        dims_[1] = dims[ax[1]];
        const std::int64_t* q0 = cell3_.data() + std::size_t(ax[0]) * n;
        const std::int64_t* q1 = cell3_.data() + std::size_t(ax[1]) * n;
        const std::int64_t* q2 = cell3_.data() + std::size_t(ax[2]) * n;
        for (std::size_t s = 0; s < n; ++s)
            key_[s] = {std::uint64_t(q0[s] + dims_[0] * (q1[s] + dims_[1] * q2[s])), id_[s], Index(s)};
        // A compact box (the usual case) gets a table of cell starts and a stable counting sort, O(N);
        // a huge sparse box (the paper's literal 2 m box) a comparison sort and binary searches.
        dense_ = cells <= double(8 * n + 4096);
        if (dense_) {
            const std::size_t nc = std::size_t(cells);
            cstart_.assign(nc + 1, 0);
            for (std::size_t s = 0; s < n; ++s) ++cstart_[key_[s].cell + 1];
            for (std::size_t c = 0; c < nc; ++c) cstart_[c + 1] += cstart_[c];
            keytmp_.resize(n);
            for (std::size_t s = 0; s < n; ++s) keytmp_[std::size_t(cstart_[key_[s].cell]++)] = key_[s];
            for (std::size_t c = nc; c > 0; --c) cstart_[c] = cstart_[c - 1];  // back to starts
            cstart_[0] = 0;
            key_.swap(keytmp_);
        } else {
            std::sort(key_.begin(), key_.end(), [](const Key& a, const Key& b) { return a.cell != b.cell ? a.cell < b.cell : a.id < b.id; });
        }
        permute();
        list_pairs();
        xref_ = x_;
        // The new storage order's kernel records, wall bits and wall candidates (predict() made them for
        // the old one).
        per_thread_walls();
        std::size_t listing_team = 1;
#pragma omp parallel if (par_)
        {
            const auto [lo, hi] = thread_range(n);
            const std::size_t t = std::size_t(thread_index());
            if (t == 0) listing_team = std::size_t(thread_count());
            refresh_kin(lo, hi);
            mark_walls(lo, hi);
            wall_cand_[t].clear();
            list_walls(lo, hi, t);
            wall_res_[t].resize(wall_cand_[t].size());
        }
        wall_lists_listed(listing_team);
    }

    struct Key {
        std::uint64_t cell;
        Index id, from;
    };

    // New storage order: slot s takes the particle that was at key_[s].from.
    void permute()
    {
        const std::size_t n = n_;
        for (auto* arr : {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_}) {
            std::vector<T>& a = *arr;
            T* dst = tmp_.data();
            const T* src = a.data();
#pragma omp parallel for schedule(static) if (par_)
            for (std::size_t s = 0; s < n; ++s) {
                const std::size_t from = std::size_t(key_[s].from);
                dst[s] = src[from];
                dst[n + s] = src[n + from];
                dst[2 * n + s] = src[2 * n + from];
            }
            a.swap(tmp_);
        }
        for (auto* arr : {&r_, &m_, &I_}) {
            for (std::size_t s = 0; s < n; ++s) tmp1_[s] = (*arr)[std::size_t(key_[s].from)];
            arr->swap(tmp1_);
        }
        for (std::size_t s = 0; s < n; ++s) {
            id_[s] = key_[s].id;
            pos_[std::size_t(key_[s].id)] = Index(s);
        }
    }

    // Calls f(q) for every particle q in the 27 cells around s's cell (s itself included).
    template <class F>
    void for_each_near(std::size_t s, F&& f) const
    {
        const std::uint64_t k = key_[s].cell;
        const auto dx = std::uint64_t(dims_[0]), dxy = dx * std::uint64_t(dims_[1]);
        auto below = [](const Key& e, std::uint64_t v) { return e.cell < v; };
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy) {
                const std::uint64_t row = k + std::uint64_t(std::int64_t(dz) * std::int64_t(dxy) + std::int64_t(dy) * std::int64_t(dx));
                if (dense_) {
                    for (Index t = cstart_[row - 1]; t < cstart_[row + 2]; ++t) f(std::size_t(t));
                    continue;
                }
                const auto b = std::lower_bound(key_.begin(), key_.end(), row - 1, below);
                const auto e = std::lower_bound(b, key_.end(), row + 2, below);
                for (auto it = b; it != e; ++it) f(std::size_t(it - key_.begin()));
            }
    }

    void list_pairs()
    {
        const std::size_t n = n_;
        const T half_skin = skin_ * T(0.5);
        // may_touch with each radius grown by skin/2: pairs closer than R_i + R_j + skin, with the law's margin.
        auto near = [&](std::size_t s, std::size_t q) {
            return id_[q] > id_[s] && may_touch(get(x_, s), get(x_, q), r_[s] + half_skin, r_[q] + half_skin);
        };
        // One scan of the cells: each thread lists its particles' partners in a buffer of its own, then
        // (after the counts' prefix sum) copies them into place.
        Index* pstart = pstart_.data();
        if (scan_.size() < std::size_t(thread_limit())) scan_.resize(std::size_t(thread_limit()));
        const bool canonical = opt_.canonical;
        std::size_t total = 0;
#pragma omp parallel if (par_)
        {
            const auto [lo, hi] = thread_range(n);
            std::vector<Index>& mine = scan_[std::size_t(thread_index())];
            mine.clear();
            for (std::size_t s = lo; s < hi; ++s) {
                const std::size_t before = mine.size();
                for_each_near(s, [&](std::size_t q) {
                    if (near(s, q)) mine.push_back(Index(q));
                });
                pstart[s + 1] = Index(mine.size() - before);
            }
#pragma omp barrier
#pragma omp single
            {
                pstart[0] = 0;
                for (std::size_t s = 0; s < n; ++s) pstart[s + 1] += pstart[s];
                total = std::size_t(pstart[n]);
                partner_.resize(total);
                owner_.resize(total);
                spans_.resize(std::size_t(thread_count()));
                span_threads_ = std::size_t(thread_count());
            }
            Index* partner = partner_.data();
            Index* owner = owner_.data();
            std::copy(mine.begin(), mine.end(), partner + pstart[lo]);
            // The particles this thread's slots reach (unordered mode's loads): its own and its partners.
            std::size_t span_lo = lo, span_hi = hi;
            for (const Index q : mine) {
                span_lo = std::min(span_lo, std::size_t(q));
                span_hi = std::max(span_hi, std::size_t(q) + 1);
            }
            spans_[std::size_t(thread_index())] = {span_lo, span_hi};
            for (std::size_t s = lo; s < hi; ++s) {
                std::fill(owner + pstart[s], owner + pstart[s + 1], Index(s));
                // Canonical: partners by ascending id. Unordered: the scan's order (ascending storage).
                if (canonical)
                    std::sort(partner + pstart[s], partner + pstart[s + 1], [this](Index a, Index b) { return id_[a] < id_[b]; });
            }
        }
        if (!canonical) return;
        Index* owner = owner_.data();
        // The slots where each particle is the partner, by ascending id of the owner.
        bucket_sort(partner_, n, lstart_, lslot_);
        const Index* lstart = lstart_.data();
        Index* lslot = lslot_.data();
#pragma omp parallel for schedule(static) if (par_)
        for (std::size_t s = 0; s < n; ++s)
            std::sort(lslot + lstart[s], lslot + lstart[s + 1], [&](Index a, Index b) { return id_[owner[a]] < id_[owner[b]]; });
        // The canonical sweep's schedule: a particle's sum needs the slots of the chunks from that of the
        // first owner of its slots to that of the last (itself for its own, its partners of lower id for
        // the others).
        const std::size_t chunks = (n + kChunk - 1) / kChunk;
        first_chunk_.resize(n);
        last_chunk_.resize(n);
        span_chunks_ = 0;
        std::size_t reach = 0;  // the most slots from the start of a particle's first chunk to the end of its last
        for (std::size_t s = 0; s < n; ++s) {
            std::size_t first = s, last = s;
            for (Index e = lstart[s]; e < lstart[s + 1]; ++e) {
                const std::size_t o = std::size_t(owner[lslot[e]]);
                first = std::min(first, o);
                last = std::max(last, o);
            }
            first /= kChunk;
            last /= kChunk;
            first_chunk_[s] = Index(first);
            last_chunk_[s] = Index(last);
            span_chunks_ = std::max(span_chunks_, last - first);
            reach = std::max(reach, std::size_t(pstart[std::min(n, (last + 1) * kChunk)] - pstart[first * kChunk]));
        }
        ring_slots_ = std::bit_ceil(std::max<std::size_t>(reach, 1));
        // The sums' tables hold byte offsets into a ring as 32-bit words.
        if ((ring_slots_ + 2) * sizeof(Slot<T>) > std::size_t(UINT32_MAX))
            throw CapacityError(fmt::format("the fast variant's canonical sweep needs a ring of {} slots, more than its 32-bit offsets "
                                            "reach (a particle's partners are {} slots apart in storage)", ring_slots_, reach));
        bucket_sort(last_chunk_, chunks, last_start_, by_last_);
        bucket_sort(first_chunk_, chunks, first_start_, by_first_);
        group_table_.clear();
        build_groups(by_last_, last_start_, chunks, group_last_start_, groups_last_);
        build_groups(by_first_, first_start_, chunks, group_first_start_, groups_first_);
    }

    // The sum groups of each chunk's schedule (the particles order[start[c] … start[c + 1]), sorted by
    // their counts of slots as j, so that a group's lists are near one length), kGroup particles a group,
    // and their tables in group_table_: a row of ring offsets a step, the lists as j to the group's
    // longest, then as i, padded with the offset of the ring's slot of zeros (ring_slots_).
    void build_groups(const std::vector<Index>& order, const std::vector<Index>& start, std::size_t chunks, std::vector<Index>& group_start,
                      std::vector<SumGroup>& groups)
    {
        const Index* lstart = lstart_.data();
        const Index* lslot = lslot_.data();
        const Index* pstart = pstart_.data();
        const std::size_t mask = ring_slots_ - 1;
        auto offset = [mask](Index k) { return std::uint32_t((std::size_t(k) & mask) * sizeof(Slot<T>)); };
        const std::uint32_t zeros = std::uint32_t(ring_slots_ * sizeof(Slot<T>));
        group_start.assign(chunks + 1, 0);
        groups.clear();
        for (std::size_t c = 0; c < chunks; ++c) {
            bucket_.assign(order.begin() + start[c], order.begin() + start[c + 1]);
            std::sort(bucket_.begin(), bucket_.end(), [&](Index a, Index b) {
                const Index la = lstart[a + 1] - lstart[a], lb = lstart[b + 1] - lstart[b];
                return la != lb ? la < lb : a < b;
            });
            for (std::size_t g0 = 0; g0 < bucket_.size(); g0 += kGroup) {
                SumGroup g;
                g.count = std::int32_t(std::min<std::size_t>(kGroup, bucket_.size() - g0));
                g.table = std::uint32_t(group_table_.size());
                for (int l = 0; l < kGroup; ++l) {
                    const Index s = l < g.count ? bucket_[g0 + std::size_t(l)] : -1;
                    g.grain[l] = s;
                    if (s < 0) continue;
                    g.as_j = std::max(g.as_j, lstart[s + 1] - lstart[s]);
                    g.as_i = std::max(g.as_i, pstart[s + 1] - pstart[s]);
                }
                for (Index e = 0; e < g.as_j; ++e)
                    for (int l = 0; l < kGroup; ++l) {
                        const Index s = g.grain[l];
                        group_table_.push_back(s >= 0 && e < lstart[s + 1] - lstart[s] ? offset(lslot[lstart[s] + e]) : zeros);
                    }
                for (Index e = 0; e < g.as_i; ++e)
                    for (int l = 0; l < kGroup; ++l) {
                        const Index s = g.grain[l];
                        group_table_.push_back(s >= 0 && e < pstart[s + 1] - pstart[s] ? offset(pstart[s] + e) : zeros);
                    }
                groups.push_back(g);
            }
            group_start[c + 1] = Index(groups.size());
        }
    }

    // The indices i of key by key[i] (a stable counting sort into `buckets` buckets): order[start[b] …
    // start[b + 1]) holds those of bucket b, ascending.
    static void bucket_sort(const std::vector<Index>& key, std::size_t buckets, std::vector<Index>& start, std::vector<Index>& order)
    {
        const std::size_t count = key.size();
        start.assign(buckets + 1, 0);
        order.resize(count);
        for (std::size_t i = 0; i < count; ++i) ++start[std::size_t(key[i]) + 1];
        for (std::size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
        for (std::size_t i = 0; i < count; ++i) order[std::size_t(start[std::size_t(key[i])]++)] = Index(i);
        for (std::size_t b = buckets; b > 0; --b) start[b] = start[b - 1];  // back to starts
        start[0] = 0;
    }

    FastOptions opt_;
    bool par_ = true, prefetch_ = false;
    bool corrector_pending_ = false;  // the arrays hold the predicted state of step_, f_/t_ its forces (predict())
    bool rebuild_due_ = false;        // the displacement check of the last predict() asks for a rebuild
    std::size_t n_ = 0, nw_ = 0;
    std::int64_t step_ = 0, rebuilds_ = 0;
    double dt_ = 0.0;
    T skin_ = T(0), cell_ = T(0);
    GearCoefficients<T> gear_;
    ContactParams<T> params_;
    Vec3<T> g_;
    std::vector<Wall> walls_;
    // Particles in storage (cell) order; id_[s] is the id at slot s, pos_[id] the slot of an id.
    std::vector<T> x_, v_, a_, b3_, b4_, b5_, th_, w_, al_, r3_, r4_, r5_;  // (3N): x block, y block, z block
    std::vector<T> f_, t_, xref_, tmp_;                                      // (3N)
    std::vector<T> r_, m_, I_, tmp1_;                                        // (N)
    std::vector<Index> id_, pos_;                                            // (N)
    std::vector<WallRecord<T>> wall_rec_;                                    // (walls)
    // The neighbour list: pairs of s in [pstart[s], pstart[s+1]), one slot each; where s is the partner.
    std::vector<Index> pstart_, partner_, owner_, lstart_, lslot_;
    std::vector<Slot<T>> slot_;  // every slot (canonical mode on several threads: the straddling sums' slots)
    std::vector<Kin<T>> kin_;                 // (N) the kernel's copy of x, R, v, ω
    std::vector<std::uint8_t> near_wall_;   // (N) the walls it may touch this step (a bit each, see mark_walls)
    std::vector<Index> wall_first_;          // (N) where a particle marked near a wall has its first candidate
    // The canonical sweep: per particle, the chunks of its slots' first and last owners; the particles
    // by their last chunk (by_last_, from last_start_[chunk]) and by their first; where each piece
    // starts, in chunks.
    std::vector<Index> first_chunk_, last_chunk_, last_start_, by_last_, first_start_, by_first_;
    std::vector<std::size_t> piece_chunk_;
    // The sums' groups of each chunk's two schedules (by last chunk, by first), from group_*_start_[chunk],
    // and their tables of ring offsets.
    std::vector<SumGroup> groups_last_, groups_first_;
    std::vector<Index> group_last_start_, group_first_start_, bucket_;
    std::vector<std::uint32_t> group_table_;
    // The most chunks and slots from a particle's first slot to its last (the sweep's reach); per thread,
    // a ring of ring_slots_ slots (a power of two, at least that reach), + 2: a slot of zeros (the sums'
    // padding) and room for the quad a sum reads from the last value of a slot.
    std::size_t span_chunks_ = 0, ring_slots_ = 1;
    std::vector<std::vector<Slot<T>>> rings_;
    std::vector<std::vector<WallCandidate>> wall_cand_;  // per thread: the particle–wall pairs that may touch
    std::size_t wall_lists_ = 0;                         // the team that listed them (wall_lists_listed)
    std::vector<std::size_t> wall_range_end_;            // where each of its ranges ends
    std::vector<std::vector<Load<T>>> wall_res_;         // per thread: their force and torque (zeros: no contact)
    std::vector<Key> key_, keytmp_;
    std::vector<std::int64_t> cell3_;  // (3N) cell coordinates at the last rebuild
    std::vector<Index> cstart_;        // first storage slot of each cell (dense grid), cells + 1
    bool dense_ = true;
    std::int64_t dims_[2] = {0, 0};
    std::vector<std::vector<Load<T>>> loads_;                // per thread: loads in storage order (unordered mode)
    std::vector<std::pair<std::size_t, std::size_t>> spans_;  // per thread: the storage range its slots reach
    std::size_t span_threads_ = 0;                            // the thread count spans_ is for
    std::vector<std::vector<Index>> scan_;          // per thread: partners found by list_pairs' scan
    std::unique_ptr<Claim[]> claims_;  // per piece of the canonical sweep
    std::size_t nclaims_ = 0;
    std::int64_t pp_ = 0, pw_ = 0;
    std::size_t team_ = 0;  // the threads of the last force pass (0: none yet)
};

} // namespace

std::unique_ptr<FastVariant> make_fast_variant(const FastOptions& options) { return std::make_unique<Fast<double, FullModel>>(options); }

void register_variant_fast(Registry& r)
{
    r.add({"fast", "data-oriented SoA in cell order, skin neighbour list, OpenMP; canonical order, bit-identical to arrays",
           [] { return make_fast_variant(FastOptions{}); }, true, true});
    VariantInfo u{"fast_unordered", "fast without the canonical order: plain accumulation (not bit-identical to arrays)",
                  [] {
                      FastOptions unordered;  // the default skin, so that only the order differs
                      unordered.canonical = false;
                      return make_fast_variant(unordered);
                  }};
    u.bitwise = false;
    u.threaded = true;
    r.add(std::move(u));
}

} // namespace demmat
