#pragma once
// The fast variant's pair kernel: a run of listed pairs (slots) through the contact law on lanes, for
// the run's model M (model.hpp). Each lane has the scalar law's bits (particle_contact_lanes and
// particle_contact_memory_lanes are the scalar laws' template code on packs), so the contacts are those
// of arrays; what becomes of them is the caller's: written into their slots (canonical order, summed
// later) or added to both particles' loads as they come (fast_unordered). Under a law with memory each
// slot's stretches (pair_stretches.hpp) go through the lanes with it and come back, zeroed where the
// pair is out of contact (a contact that ends is forgotten, as in arrays).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "heap_bytes.hpp"
#include "neighbour_list.hpp"
#include "pair_stretches.hpp"
#include "particles.hpp"
#include "quads.hpp"
#include "wall_contacts.hpp"

namespace demmat::fast {

// One contact's result, kept in list order: torque on j, force on i (on j it is -f), torque on i. Eight
// of its nine values fill one cache line, t_j, f, t_i.x, t_i.y, in this order, so that a sum reads t_j
// and f (as j) or f and t_i's first two (as i) in one aligned load (a load across two lines costs two,
// and nine values in a row put seven of eight slots across); t_i.z lies in an array beside (SlotView).
struct alignas(64) Slot {
    double v[8];
    Vec3d tj() const { return {v[0], v[1], v[2]}; }
    Vec3d f() const { return {v[3], v[4], v[5]}; }
};
static_assert(sizeof(Slot) == 64);

// Slots by index: slot k's line at line[k], its t_i.z at tz[k].
struct SlotView {
    Slot* line = nullptr;
    double* tz = nullptr;
};

// Storage for count slots (a ring, or the whole list), zeroed.
struct SlotStore {
    std::vector<Slot> line;
    std::vector<double> tz;

    void assign(std::size_t count)
    {
        line.assign(count, Slot{});
        tz.assign(count, 0.0);
    }
    void zero(std::size_t k)
    {
        line[k] = Slot{};
        tz[k] = 0.0;
    }
    std::size_t size() const { return line.size(); }
    Vec3d ti(std::size_t k) const { return {line[k].v[6], line[k].v[7], tz[k]}; }
    // From slot k on.
    SlotView view(std::size_t k = 0) { return {line.data() + k, tz.data() + k}; }
    std::size_t bytes() const { return heap_bytes(line, tz); }
};

// Where the canonical kernel puts slot k: ring at k & mask, a thread's ring of the slots its sweep has
// yet to sum, and, where all.line is set, all at k too (the whole list, for the sums that straddle two
// pieces).
struct SlotSink {
    SlotView ring;
    std::size_t mask = 0;
    SlotView all;
    // count slots ks[e]'s nine values: the line as two quads, t_i.z alone, straight from the kernel's
    // rows into place. A whole pack (count = kLanes) is a loop of known length, which the compiler
    // unrolls, and the test for `all` is made once per call, not once per slot.
    template <class Head, class Tail, class Last>
    [[gnu::always_inline]] void put(const std::size_t* ks, int count, Head&& head, Tail&& tail, Last&& last) const
    {
        auto to = [&](const SlotView& base, std::size_t m) {
            auto one = [&](int e) {
                const std::size_t k = ks[e] & m;
                char* bytes = reinterpret_cast<char*>(base.line + k);
                std::memcpy(bytes, &head(e), sizeof(Quad));
                std::memcpy(bytes + sizeof(Quad), &tail(e), sizeof(Quad));
                base.tz[k] = last(e);
            };
            if (count == kLanes)
                for (int e = 0; e < kLanes; ++e) one(e);
            else
                for (int e = 0; e < count; ++e) one(e);
        };
        to(ring, mask);
        if (all.line) to(all, ~std::size_t(0));
    }
};

template <class M>
class PairKernel {
    static constexpr bool kLaw = M::restitution_damping || M::history || M::rolling;
    static constexpr std::size_t kQ = std::size_t(stretch_quads<M>);

public:
    // From FastOptions::prefetch_from particles on, the kernel prefetches the far particle's record of
    // each slot kPrefetch candidates ahead (and in fast_unordered its load): a slot is stored with the
    // pair's particle that comes first in storage, whose records come in order, which the hardware
    // prefetches; the other (the later, max(owner, partner)) lies anywhere in the sweep's reach, which it
    // does not, and a large bed's records do not stay in the caches from one force pass to the next.
    static constexpr std::size_t kPrefetch = 128;

    PairKernel(const NeighbourList& list, const Particles& p, const LawInputs& law, Quad* stretches, bool prefetch)
        : owner_(list.owner.data()), partner_(list.partner.data()), pairs_(list.pairs()), kin_(p.kin.data()), law_(law),
          stretch_(stretches), prefetch_(prefetch)
    {
    }

    // Slots [k0, k1): the contacts among them, each into its slot (canonical, through `sink`) or added to
    // the loads of both particles (unordered). A canonical sum reads every slot of a particle, so there a
    // pair out of contact holds zeros, which add nothing (a sum that starts at +0 is never -0, and
    // x + ±0 = x for every other x), so the bits are those of arrays, which skips the pair; reading zeros
    // costs less than a branch taken at random (a dropped pair's slot is zeroed every step: the ring's
    // slot k & mask held another pair's). may_touch first, a cheap and conservative test (the law rejects
    // every pair it rejects), so the skin's extra candidates cost a distance, not a pass through the law;
    // the rest go through the law kLanes at a time. The test sorts the slots into kept and dropped
    // without a branch (a third are dropped, in no pattern a predictor learns). Returns the contacts found.
    // `next`: where this thread's slots go on after k1 (the chunk a downward sweep takes next, below
    // this one), so that the last kPrefetch slots' prefetches fetch what it reads next; by default k1.
    template <bool Canonical>
    std::int64_t run(std::size_t k0, std::size_t k1, Load* load, const SlotSink& sink = {}, std::size_t next = SIZE_MAX) const
    {
        if (next == SIZE_MAX) next = k1;
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
                    const std::size_t past = k + kPrefetch < k1 ? k + kPrefetch : next + (k + kPrefetch - k1);
                    const std::size_t ahead = std::min(past, pairs_ - kLanes);
                    for (int l = 0; l < kLanes; ++l) {
                        const Index far = std::max(owner_[ahead + std::size_t(l)], partner_[ahead + std::size_t(l)]);
                        const char* rec = reinterpret_cast<const char*>(&kin_[far]);
                        __builtin_prefetch(rec);
                        __builtin_prefetch(rec + 64);
                        if constexpr (!Canonical) __builtin_prefetch(&load[far], 1);
                    }
                }
                Lanes a[4], b[4];
                gather_lanes([&](int l) -> const Quad& { return kin_[owner_[k + std::size_t(l)]].xr; }, a);
                gather_lanes([&](int l) -> const Quad& { return kin_[partner_[k + std::size_t(l)]].xr; }, b);
                const auto t = may_touch_lanes(Vec3<Lanes>{a[0], a[1], a[2]}, Vec3<Lanes>{b[0], b[1], b[2]}, a[3], b[3]);
                sort_pack(k, t, kept, nk, dropped, nd);
            }
            for (; k < c1; ++k) {
                const Quad& a = kin_[owner_[k]].xr;
                const Quad& b = kin_[partner_[k]].xr;
                const bool t = may_touch(Vec3d{a[0], a[1], a[2]}, Vec3d{b[0], b[1], b[2]}, a[3], b[3]);
                kept[nk] = k;
                dropped[nd] = k;
                nk += std::size_t(t);
                nd += std::size_t(!t);
            }
            if constexpr (Canonical)
                for (std::size_t e = 0; e < nd; e += kLanes) {
                    const Quad zero{};
                    auto zeros = [&](int) -> const Quad& { return zero; };
                    sink.put(dropped + e, int(std::min<std::size_t>(kLanes, nd - e)), zeros, zeros, [](int) { return 0.0; });
                }
            if constexpr (kQ > 0)  // out of contact: the stretch is forgotten
                for (std::size_t e = 0; e < nd; ++e)
                    for (std::size_t q = 0; q < kQ; ++q) stretch_[dropped[e] * kQ + q] = Quad{};
            for (std::size_t e = 0; e < nk; e += kLanes)
                found += pack<Canonical>(kept + e, int(std::min<std::size_t>(kLanes, nk - e)), load, sink);
        }
        return found;
    }

private:
    static constexpr std::size_t kBlock = 1024;  // candidates sorted into kept and dropped at a time

    // Slots k, ..., k + kLanes - 1 onto the ends of kept (the lanes where t is set) and dropped (the
    // others), in order. With AVX-512 each list takes its lanes' slots in one compressing shuffle and
    // one whole store of kLanes places, the unused ones past its new end: the lists then hold
    // nk + nd = k - c0 slots and k + kLanes <= c1 <= c0 + kBlock, so the store stays in the block.
    // Elsewhere slot by slot, both lists written and one end advanced, with no branch.
    template <class Test>
    [[gnu::always_inline]] static void sort_pack(std::size_t k, const Test& t, std::size_t* kept, std::size_t& nk,
                                                 std::size_t* dropped, std::size_t& nd)
    {
#if defined(__AVX512F__)
        if constexpr (kLanes == 8 && sizeof(std::size_t) == 8) {
            const __m512i lanes = (__m512i)t;
            const __mmask8 in = _mm512_test_epi64_mask(lanes, lanes);
            const __m512i slots = _mm512_add_epi64(_mm512_set1_epi64((long long)k), _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0));
            _mm512_storeu_si512(kept + nk, _mm512_maskz_compress_epi64(in, slots));
            _mm512_storeu_si512(dropped + nd, _mm512_maskz_compress_epi64(__mmask8(~in), slots));
            const auto n_in = std::size_t(__builtin_popcount(unsigned(in)));
            nk += n_in;
            nd += std::size_t(kLanes) - n_in;
            return;
        }
#endif
        for (int l = 0; l < kLanes; ++l) {
            kept[nk] = k + std::size_t(l);
            dropped[nd] = k + std::size_t(l);
            nk += std::size_t(t[l] != 0);
            nd += std::size_t(t[l] == 0);
        }
    }

    // The law for up to kLanes slots at once (unused lanes repeat the last slot and are not stored):
    // both particles' records transposed into the lanes, particle_contact_lanes (the pair's coefficients
    // computed from R and m in the lanes: cheaper than reading them from a per-pair array), and the lanes
    // transposed back into the slots (zeros where h <= 0) or added to the loads.
    template <bool Canonical>
    [[gnu::flatten]] int pack(const std::size_t* ks, int count, Load* load, const SlotSink& sink) const
    {
        std::size_t k[kLanes], s[kLanes], q[kLanes];
        for (int l = 0; l < kLanes; ++l) {
            k[l] = ks[l < count ? l : count - 1];
            s[l] = std::size_t(owner_[k[l]]);
            q[l] = std::size_t(partner_[k[l]]);
        }
        Lanes xi[4]{}, xj[4]{}, vi[4]{}, vj[4]{}, wi[4]{}, wj[4]{};
        const Kin* kin = kin_;
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].xr; }, xi);
        gather_lanes([&](int l) -> const Quad& { return kin[q[l]].xr; }, xj);
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].v; }, vi);
        gather_lanes([&](int l) -> const Quad& { return kin[q[l]].v; }, vj);
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].w; }, wi);
        gather_lanes([&](int l) -> const Quad& { return kin[q[l]].w; }, wj);
        ContactForce<Lanes> c;
        const Vec3<Lanes> pi{xi[0], xi[1], xi[2]}, pj{xj[0], xj[1], xj[2]}, ui{vi[0], vi[1], vi[2]}, uj{vj[0], vj[1], vj[2]},
            oi{wi[0], wi[1], wi[2]}, oj{wj[0], wj[1], wj[2]};
        const auto touch = [&] {
            if constexpr (kLaw) {
                Stretch<Lanes> st;
                if constexpr (kQ > 0) lanes_from_records<M>(stretch_, k, st);
                const auto t = particle_contact_memory_lanes<M>(pi, pj, ui, uj, oi, oj, xi[3], xj[3], vi[3], vj[3], law_.params,
                                                                law_.memory, st, true, c);
                if constexpr (kQ > 0) lanes_to_records<M>(stretch_, k, count, t, st);
                return t;
            } else {
                return particle_contact_lanes<M>(pi, pj, ui, uj, oi, oj, xi[3], xj[3], vi[3], vj[3], law_.params, law_.mono_pp, c);
            }
        }();
        int found = 0;
        if (count == kLanes)  // a loop of known length, unrolled
            for (int l = 0; l < kLanes; ++l) found += int(touch[l] != 0);
        else
            for (int l = 0; l < count; ++l) found += int(touch[l] != 0);
        if constexpr (Canonical) {
            // A slot is nine values: t_j, f, t_i; the first eight (its line) go as two quads, the ninth alone.
            const Lanes g0[4] = {c.t_j.x, c.t_j.y, c.t_j.z, c.f_i.x}, g1[4] = {c.f_i.y, c.f_i.z, c.t_i.x, c.t_i.y};
            Quad r0[kLanes], r1[kLanes];
            lanes_to_rows<Lanes>(g0, r0);
            lanes_to_rows<Lanes>(g1, r1);
            sink.put(k, count, [&](int l) -> const Quad& { return r0[l]; }, [&](int l) -> const Quad& { return r1[l]; },
                     [&](int l) { return c.t_i.z[l]; });
        } else {
            // Added as they come, lane by lane (a particle may sit in several lanes).
            const Lanes zero{};
            const Lanes gf[4] = {c.f_i.x, c.f_i.y, c.f_i.z, zero}, gi[4] = {c.t_i.x, c.t_i.y, c.t_i.z, zero},
                        gj[4] = {c.t_j.x, c.t_j.y, c.t_j.z, zero};
            Quad f[kLanes], ti[kLanes], tj[kLanes];
            lanes_to_rows<Lanes>(gf, f);
            lanes_to_rows<Lanes>(gi, ti);
            lanes_to_rows<Lanes>(gj, tj);
            for (int l = 0; l < count; ++l) {
                load[s[l]].f += f[l];
                load[q[l]].f -= f[l];
                load[s[l]].t += ti[l];
                load[q[l]].t += tj[l];
            }
        }
        return found;
    }

    const Index* owner_;
    const Index* partner_;
    std::size_t pairs_;
    const Kin* kin_;
    const LawInputs& law_;
    Quad* stretch_;  // kQ quads per slot (a law with memory), else unused
    bool prefetch_;
};

} // namespace demmat::fast
