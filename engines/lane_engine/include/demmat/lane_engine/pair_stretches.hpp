#pragma once
// The fast variant's contact memory (physics.md §9): under a law with memory each listed pair's slot
// holds its stretches, one quad (x, y, z, 0) per spring, so that the pair kernel moves them into its
// lanes and back by the same transposes as the particles' records. A slot is a place, not a key: when
// the list is rebuilt (the particles re-sorted, new slots) the live stretches are collected by their pair
// of ids (lower, higher) before the re-sort and looked up by pair in the new list, never by slot. A
// contact out of contact at a force pass has its slot zeroed (forgotten, as in arrays); all-zero bits
// are a contact's start, so only slots with a bit set are carried.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "demmat/contact_memory.hpp"
#include "demmat/state.hpp"
#include "heap_bytes.hpp"
#include "neighbour_list.hpp"
#include "particles.hpp"
#include "quads.hpp"
#include "team.hpp"

namespace demmat::fast {

// The quads of a contact's record under model M: one per spring (tangential, rolling); 0 for the paper's
// law and for restitution damping alone.
template <class M>
inline constexpr int stretch_quads = int(M::history) + int(M::rolling);

// The stretches of the kLanes records base[k[l]] into the lanes (tangential in the first quad, rolling
// in the last).
template <class M>
[[gnu::always_inline]] inline void lanes_from_records(const Quad* base, const std::size_t* k, Stretch<Lanes>& st)
{
    constexpr std::size_t Q = std::size_t(stretch_quads<M>);
    Lanes q[4];
    if constexpr (M::history) {
        gather_lanes([&](int l) -> const Quad& { return base[k[l] * Q]; }, q);
        st.t = {q[0], q[1], q[2]};
    }
    if constexpr (M::rolling) {
        gather_lanes([&](int l) -> const Quad& { return base[k[l] * Q + Q - 1]; }, q);
        st.r = {q[0], q[1], q[2]};
    }
}

// The lanes' stretches back into the first `count` records, zero where the lane is out of contact.
template <class M, class Mask>
[[gnu::always_inline]] inline void lanes_to_records(Quad* base, const std::size_t* k, int count, const Mask& touch, const Stretch<Lanes>& st)
{
    constexpr std::size_t Q = std::size_t(stretch_quads<M>);
    auto put = [&](const Vec3<Lanes>& v, std::size_t q) {
        const Vec3<Lanes> kept = demmat::detail::select(touch, v, Vec3<Lanes>{});
        const Lanes g[4] = {kept.x, kept.y, kept.z, Lanes{}};
        Quad rows[kLanes];
        lanes_to_rows<Lanes>(g, rows);
        if (count == kLanes)  // a whole pack: a loop of known length, unrolled
            for (int l = 0; l < kLanes; ++l) base[k[l] * Q + q] = rows[l];
        else
            for (int l = 0; l < count; ++l) base[k[l] * Q + q] = rows[l];
    };
    if constexpr (M::history) put(st.t, 0);
    if constexpr (M::rolling) put(st.r, Q - 1);
}

// A record's quads as a state's stretches (ContactStretch), and back.
inline void record_to_stretch(const Quad* rec, bool history, bool rolling, ContactStretch& out)
{
    if (history) out.tangential = {rec[0][0], rec[0][1], rec[0][2]};
    if (rolling) {
        const Quad& r = rec[history ? 1 : 0];
        out.rolling = {r[0], r[1], r[2]};
    }
}
inline void stretch_to_record(const ContactStretch& in, bool history, bool rolling, Quad* rec)
{
    if (history) rec[0] = Quad{in.tangential.x, in.tangential.y, in.tangential.z, 0.0};
    if (rolling) rec[history ? 1 : 0] = Quad{in.rolling.x, in.rolling.y, in.rolling.z, 0.0};
}

class PairStretches {
public:
    std::vector<Quad> slots;  // quads() per list slot

    void init(bool history, bool rolling)
    {
        history_ = history;
        rolling_ = rolling;
        q_ = std::size_t(history) + std::size_t(rolling);
        slots.clear();
    }
    std::size_t quads() const { return q_; }

    // Before a re-sort: every slot with a bit set, keyed by (owner id, partner id); each particle's slots
    // as owner come by ascending partner (as_i, the canonical list), so each owner's entries do.
    void collect(const NeighbourList& list, const std::vector<Index>& id, std::size_t n)
    {
        carry_start_.assign(n + 1, 0);
        auto live = [&](std::size_t k) {
            for (std::size_t q = 0; q < q_; ++q) {
                const Quad& r = slots[k * q_ + q];
                for (int c = 0; c < 3; ++c)
                    if (std::bit_cast<std::uint64_t>(r[c]) != 0) return true;
            }
            return false;
        };
        for (std::size_t s = 0; s < n; ++s)
            for (Index e = list.istart[s]; e < list.istart[s + 1]; ++e)
                if (live(std::size_t(list.as_i[std::size_t(e)]))) ++carry_start_[std::size_t(id[s]) + 1];
        for (std::size_t i = 0; i < n; ++i) carry_start_[i + 1] += carry_start_[i];
        const std::size_t total = std::size_t(carry_start_[n]);
        carry_partner_.resize(total);
        carry_rec_.resize(total * q_);
        fill_.assign(carry_start_.begin(), carry_start_.end() - 1);
        for (std::size_t s = 0; s < n; ++s)
            for (Index e0 = list.istart[s]; e0 < list.istart[s + 1]; ++e0) {
                const Index k = list.as_i[std::size_t(e0)];
                if (!live(std::size_t(k))) continue;
                const std::size_t e = std::size_t(fill_[std::size_t(id[s])]++);
                carry_partner_[e] = id[std::size_t(list.partner[std::size_t(k)])];
                for (std::size_t q = 0; q < q_; ++q) carry_rec_[e * q_ + q] = slots[std::size_t(k) * q_ + q];
            }
    }

    // From a state: its pair contacts (in canonical order: by particle, partners ascending), as collect().
    void load(const std::vector<ContactStretch>& in, std::size_t n)
    {
        carry_start_.assign(n + 1, 0);
        for (const ContactStretch& c : in)
            if (!c.wall) ++carry_start_[std::size_t(c.i) + 1];
        for (std::size_t i = 0; i < n; ++i) carry_start_[i + 1] += carry_start_[i];
        const std::size_t total = std::size_t(carry_start_[n]);
        carry_partner_.resize(total);
        carry_rec_.assign(total * q_, Quad{});
        std::size_t e = 0;
        for (const ContactStretch& c : in) {
            if (c.wall) continue;
            carry_partner_[e] = Index(c.partner);
            stretch_to_record(c, history_, rolling_, carry_rec_.data() + e * q_);
            ++e;
        }
    }

    // After the list is (re)built: each slot takes the stretches its pair had (zero for a new one),
    // looked up by ids; both sides ascend, so a merge.
    void apply(const NeighbourList& list, const std::vector<Index>& id, std::size_t n, bool parallel)
    {
        slots.assign(list.pairs() * q_, Quad{});
        in_team(parallel, [&] {
#pragma omp for schedule(static)
            for (std::size_t s = 0; s < n; ++s) {
                const std::size_t i = std::size_t(id[s]);
                Index e = carry_start_[i];
                const Index e1 = carry_start_[i + 1];
                for (Index a = list.istart[s]; a < list.istart[s + 1] && e < e1; ++a) {
                    const Index k = list.as_i[std::size_t(a)];
                    const Index j = id[std::size_t(list.partner[std::size_t(k)])];
                    while (e < e1 && carry_partner_[std::size_t(e)] < j) ++e;
                    if (e < e1 && carry_partner_[std::size_t(e)] == j)
                        for (std::size_t q = 0; q < q_; ++q) slots[std::size_t(k) * q_ + q] = carry_rec_[std::size_t(e) * q_ + q];
                }
            }
        });
    }

    // The carried stretches are no longer needed once every rebuild that may read them is done (held
    // only across a rebuild: rebuilds are rare, and the bytes are the live contacts' once more).
    void release_carry()
    {
        std::vector<Index>().swap(carry_start_);
        std::vector<Index>().swap(carry_partner_);
        std::vector<Index>().swap(fill_);
        std::vector<Quad>().swap(carry_rec_);
    }

    // The live pair contacts of the last force pass (h > 0 at the positions it read: the records), as a
    // state holds them.
    void save(const NeighbourList& list, const Particles& p, std::vector<ContactStretch>& out) const
    {
        for (std::size_t s = 0; s < p.n; ++s)
            for (Index e = list.istart[s]; e < list.istart[s + 1]; ++e) {
                const Index k = list.as_i[std::size_t(e)];
                const std::size_t q = std::size_t(list.partner[std::size_t(k)]);
                const Quad& a = p.kin[s].xr;
                const Quad& b = p.kin[q].xr;
                Vec3d dx;
                double d;
                if (!(demmat::detail::pair_overlap(Vec3d{a[0], a[1], a[2]}, Vec3d{b[0], b[1], b[2]}, a[3], b[3], dx, d) > 0.0)) continue;
                ContactStretch c;
                c.i = p.id[s];
                c.partner = p.id[q];
                c.wall = false;
                record_to_stretch(slots.data() + std::size_t(k) * q_, history_, rolling_, c);
                out.push_back(c);
            }
    }

    std::size_t bytes() const { return heap_bytes(slots, carry_start_, carry_partner_, carry_rec_, fill_); }

private:
    bool history_ = false, rolling_ = false;
    std::size_t q_ = 0;
    // The carried stretches by owner id: entries [carry_start_[i], carry_start_[i + 1]), partners ascending.
    std::vector<Index> carry_start_, carry_partner_, fill_;
    std::vector<Quad> carry_rec_;
};

} // namespace demmat::fast
