#pragma once
// The fast variant's neighbour list with a skin: each pair closer than R_i + R_j + skin is listed once,
// in a slot of its own, under the particle that comes first in storage: the slots stored at s are
// [start[s], start[s + 1]), so each chunk of the storage order has its slots together. Each slot names
// the pair by the law's roles: owner the lower id (i), partner the higher (j). For the canonical order
// each particle also has the slots where it is i, by ascending id of the partner (as_i), and those where
// it is j, by ascending id of the owner (as_j). Stored with the storage-earlier particle, a sum reaches
// back only to its partners below it in storage, never above, as it did with the slots under the lower id.
#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

#include "cell_order.hpp"
#include "demmat/contact_law.hpp"
#include "heap_bytes.hpp"
#include "particles.hpp"
#include "team.hpp"

namespace demmat::fast {

// The indices i of key by key[i] (a stable counting sort into `buckets` buckets): order[start[b] …
// start[b + 1]) holds those of bucket b, ascending.
inline void bucket_sort(const std::vector<Index>& key, std::size_t buckets, std::vector<Index>& start, std::vector<Index>& order)
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

class NeighbourList {
public:
    std::vector<Index> start, partner, owner;  // the slots stored at each particle; each slot's j and i (by id)
    std::vector<Index> istart, as_i;           // canonical: the slots where each particle is i, partners ascending
    std::vector<Index> jstart, as_j;           // canonical: the slots where each particle is j, owners ascending
    // canonical: per particle, the earliest storage index where one of its slots is stored (its own, or
    // that of a partner below it in storage: a slot is stored with the pair's storage-earlier particle).
    std::vector<Index> earliest;
    // Per thread of the last build: the storage range its slots reach (its particles and their partners).
    std::vector<std::pair<std::size_t, std::size_t>> spans;

    std::size_t pairs() const { return partner.size(); }

    // Lists the pairs of the particles p, in the cell order `cells`, closer than R_i + R_j + skin. One
    // scan of the cells: each thread lists its particles' later neighbours in storage in a buffer of its
    // own, then (after the counts' prefix sum) copies them into place, in the scan's order (ascending
    // storage). Canonical: as_i and as_j too.
    void build(const Particles& p, const CellOrder& cells, double skin, bool canonical, bool parallel)
    {
        const std::size_t n = p.n;
        const double half_skin = skin * 0.5;
        const std::vector<Index>& id = p.id;
        // may_touch with each radius grown by skin/2: pairs closer than R_i + R_j + skin, with the law's margin.
        auto near = [&](std::size_t s, std::size_t q) {
            return may_touch(p.get(p.x, s), p.get(p.x, q), p.r[s] + half_skin, p.r[q] + half_skin);
        };
        start.assign(n + 1, 0);
        Index* pstart = start.data();
        if (scan_.size() < std::size_t(thread_limit())) scan_.resize(std::size_t(thread_limit()));
        in_team(parallel, [&] {
            const auto [lo, hi] = thread_range(n);
            std::vector<Index>& mine = scan_[std::size_t(thread_index())];
            mine.clear();
            for (std::size_t s = lo; s < hi; ++s) {
                const std::size_t before = mine.size();
                // Each candidate written, and kept by counting it: no branch on the test's outcome.
                cells.for_each_later(s, [&](std::size_t a, std::size_t b) {
                    const std::size_t at = mine.size();
                    mine.resize(at + (b - a));
                    Index* out = mine.data() + at;
                    std::size_t k = 0;
                    for (std::size_t q = a; q < b; ++q) {
                        out[k] = Index(q);
                        k += std::size_t(near(s, q));
                    }
                    mine.resize(at + k);
                });
                pstart[s + 1] = Index(mine.size() - before);
            }
#pragma omp barrier
#pragma omp single
            {
                pstart[0] = 0;
                for (std::size_t s = 0; s < n; ++s) pstart[s + 1] += pstart[s];
                partner.resize(std::size_t(pstart[n]));
                owner.resize(std::size_t(pstart[n]));
                spans.resize(std::size_t(thread_count()));
            }
            Index* ppartner = partner.data();
            Index* powner = owner.data();
            std::copy(mine.begin(), mine.end(), ppartner + pstart[lo]);
            std::size_t span_lo = lo, span_hi = hi;
            for (const Index q : mine) {
                span_lo = std::min(span_lo, std::size_t(q));
                span_hi = std::max(span_hi, std::size_t(q) + 1);
            }
            spans[std::size_t(thread_index())] = {span_lo, span_hi};
            for (std::size_t s = lo; s < hi; ++s)
                for (Index k = pstart[s]; k < pstart[s + 1]; ++k) {
                    const Index q = ppartner[k];  // the law's i is the lower id
                    const bool swap = id[std::size_t(q)] < id[s];
                    powner[k] = swap ? q : Index(s);
                    ppartner[k] = swap ? Index(s) : q;
                }
        });
        if (canonical) index_by_particle(p.pos, parallel);
    }

    // as_i and as_j from owner and partner: each particle's slots as i, by ascending partner id, and as
    // j, by ascending owner id (ids are unique, so the order is total); and earliest. Two counting sorts
    // a side and no comparison: the slots grouped by owner and by partner, then each side dealt from the
    // other's grouping (deal(), which takes the ids in order through pos, the storage slot of each id).
    // On a team, each of the four goes to a thread of its own, two at a time.
    void index_by_particle(const std::vector<Index>& pos, bool parallel)
    {
        const std::size_t n = start.size() - 1;
        earliest.resize(n);
        in_team(parallel, [&] {
#pragma omp single nowait
            bucket_sort(owner, n, by_owner_.start, by_owner_.order);
#pragma omp single nowait
            bucket_sort(partner, n, by_partner_.start, by_partner_.order);
#pragma omp barrier
#pragma omp single nowait
            deal(partner, by_owner_, by_partner_.start, pos, jstart, as_j);
#pragma omp single nowait
            {
                deal(owner, by_partner_, by_owner_.start, pos, istart, as_i);
                find_earliest();  // with the shorter of the two deals
            }
        });
    }

    std::size_t bytes() const
    {
        return heap_bytes(start, partner, owner, istart, as_i, jstart, as_j, earliest, spans, scan_) + by_owner_.bytes() +
               by_partner_.bytes();
    }

private:
    // Slots grouped by particle (bucket_sort), in no order that matters within a group.
    struct Grouping {
        std::vector<Index> start, order;
        std::size_t bytes() const { return heap_bytes(start, order); }
    };

    // The slots by `key` (starting at key_start, its grouping's), each key's by ascending id of the other
    // particle of the pair (as_i: key owner, other partner; as_j the reverse): the groups of the other
    // (by_other) taken in ascending id of their particle, each slot dealt to its key's group in turn, so
    // that each key's slots come in ascending id of the other (a pair is listed once).
    void deal(const std::vector<Index>& key, const Grouping& by_other, const std::vector<Index>& key_start, const std::vector<Index>& pos,
              std::vector<Index>& first, std::vector<Index>& order) const
    {
        const std::size_t n = start.size() - 1;
        first = key_start;
        order.resize(key.size());
        const Index* pkey = key.data();
        const Index* grouped = by_other.order.data();
        const Index* group_start = by_other.start.data();
        Index* next = first.data();  // each key's next place: its start, until dealt to, then its end
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t o = std::size_t(pos[i]);
            for (Index e = group_start[o]; e < group_start[o + 1]; ++e) {
                const Index k = grouped[e];
                order[std::size_t(next[pkey[k]]++)] = k;
            }
        }
        for (std::size_t b = n; b > 0; --b) first[b] = first[b - 1];  // back to starts
        first[0] = 0;
    }

    // earliest[s]: the slots stored at s are [start[s], start[s + 1]), each with a partner q above s.
    // Going down the storage, each s writes itself as the earliest of those partners: the last to write
    // one, the lowest, stays. None above s writes s's, so s starts as its own before those below it come.
    // (Slot k's particle other than s is owner + partner - s.)
    void find_earliest()
    {
        const std::size_t n = start.size() - 1;
        const Index* po = owner.data();
        const Index* pp = partner.data();
        Index* out = earliest.data();
        for (std::size_t s = n; s-- > 0;) {
            out[s] = Index(s);
            for (Index k = start[s]; k < start[s + 1]; ++k) out[std::size_t(po[k] + pp[k]) - s] = Index(s);
        }
    }

    PerThread<std::vector<Index>> scan_;  // partners found by the scan
    Grouping by_owner_, by_partner_;        // index_by_particle: the slots by each particle of the pair
};

} // namespace demmat::fast
