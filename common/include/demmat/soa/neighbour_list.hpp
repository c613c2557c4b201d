#pragma once
// The fast variant's neighbour list with a skin: each pair closer than R_i + R_j + skin is listed once,
// under its lower-id particle (the law's i, the owner), in a slot of its own: the pairs of owner s are
// slots [start[s], start[s + 1]). For the canonical order the partners are in ascending id, and each
// particle also has the slots where it is the partner, by ascending id of the owner (as_j).
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
    std::vector<Index> start, partner, owner;  // the slots of each owner; each slot's partner and owner
    std::vector<Index> jstart, as_j;           // canonical: the slots where each particle is the partner
    // Per thread of the last build: the storage range its slots reach (its particles and their partners).
    std::vector<std::pair<std::size_t, std::size_t>> spans;

    std::size_t pairs() const { return partner.size(); }

    // Lists the pairs of the particles p, in the cell order `cells`, closer than R_i + R_j + skin. One
    // scan of the cells: each thread lists its particles' partners in a buffer of its own, then (after
    // the counts' prefix sum) copies them into place. Canonical: partners by ascending id, and as_j;
    // otherwise partners in the scan's order (ascending storage).
    void build(const Particles& p, const CellOrder& cells, double skin, bool canonical, bool parallel)
    {
        const std::size_t n = p.n;
        const double half_skin = skin * 0.5;
        const std::vector<Index>& id = p.id;
        // may_touch with each radius grown by skin/2: pairs closer than R_i + R_j + skin, with the law's margin.
        auto near = [&](std::size_t s, std::size_t q) {
            return id[q] > id[s] && may_touch(p.get(p.x, s), p.get(p.x, q), p.r[s] + half_skin, p.r[q] + half_skin);
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
            for (std::size_t s = lo; s < hi; ++s) {
                std::fill(powner + pstart[s], powner + pstart[s + 1], Index(s));
                if (canonical)
                    std::sort(ppartner + pstart[s], ppartner + pstart[s + 1], [&id](Index x, Index y) { return id[x] < id[y]; });
            }
        });
        if (!canonical) return;
        bucket_sort(partner, n, jstart, as_j);
        const Index* pjstart = jstart.data();
        const Index* powner = owner.data();
        Index* pas_j = as_j.data();
        in_team(parallel, [&] {
#pragma omp for schedule(static)
            for (std::size_t s = 0; s < n; ++s)
                std::sort(pas_j + pjstart[s], pas_j + pjstart[s + 1], [&](Index x, Index y) { return id[powner[x]] < id[powner[y]]; });
        });
    }

    std::size_t bytes() const { return heap_bytes(start, partner, owner, jstart, as_j, spans, scan_); }

private:
    std::vector<std::vector<Index>> scan_;  // per thread: partners found by the scan
};

} // namespace demmat::fast
