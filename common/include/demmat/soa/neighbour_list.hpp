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
            return q > s && may_touch(p.get(p.x, s), p.get(p.x, q), p.r[s] + half_skin, p.r[q] + half_skin);
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
                cells.for_each_near(s, [&](std::size_t q) {
                    if (near(s, q)) mine.push_back(Index(q));
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
        if (canonical) index_by_particle(id, parallel);
    }

    // as_i and as_j from owner and partner: each particle's slots as i, by ascending partner id, and as
    // j, by ascending owner id (ids are unique, so the order is total). The two sides are independent: on
    // a team, one thread each (the bucket sort is serial, and the two take about as long).
    void index_by_particle(const std::vector<Index>& id, bool parallel)
    {
        const std::size_t n = start.size() - 1;
        in_team(parallel, [&] {
#pragma omp single nowait
            by_particle(owner, partner, id, n, istart, as_i);
#pragma omp single nowait
            by_particle(partner, owner, id, n, jstart, as_j);
        });
    }

    std::size_t bytes() const { return heap_bytes(start, partner, owner, istart, as_i, jstart, as_j, spans, scan_); }

private:
    // The slots by `key` (bucket_sort), each particle's by the id of `other`: a handful a particle, so an
    // insertion sort, each key looked up once.
    static void by_particle(const std::vector<Index>& key, const std::vector<Index>& other, const std::vector<Index>& id, std::size_t n,
                            std::vector<Index>& first, std::vector<Index>& order)
    {
        bucket_sort(key, n, first, order);
        const Index* po = other.data();
        const Index* pid = id.data();
        Index* slots = order.data();
        for (std::size_t s = 0; s < n; ++s) {
            Index* const begin = slots + first[s];
            Index* const end = slots + first[s + 1];
            for (Index* a = begin + 1; a < end; ++a) {
                const Index k = *a, at = pid[po[k]];
                Index* b = a;
                for (; b > begin && pid[po[b[-1]]] > at; --b) *b = b[-1];
                *b = k;
            }
        }
    }

    std::vector<std::vector<Index>> scan_;  // per thread: partners found by the scan
};

} // namespace demmat::fast
