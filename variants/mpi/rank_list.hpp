#pragma once
// A rank's neighbour list (docs/variants/mpi.md): every pair with an owned particle closer than
// R_i + R_j + skin, found by the linked cells over owned particles and ghosts, each pair once with the
// lower id as i (`pairs`: first the pairs whose i this rank owns, so that a contact is counted once
// over all ranks, in the order of the owned particle that found them; then the few whose i is a ghost);
// and each owned particle's row of its pairs, by ascending partner id: the canonical order of its sum
// (physics.md §6), whatever the local order. A row is the pairs where the particle is j (partners of
// lower id), then those where it is i, so the sum needs no test per entry.
//
// The cells find each pair at the lower of its two local indices, and ghosts come after the owned
// particles: every pair of owned particle l is found at some owned a <= l. So once the pairs found at
// a < L have their forces, the sums of the particles below L can be made (`found_at`): the rank sums
// a block while the block's slots are still in cache.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/linked_cells.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

class RankList {
public:
    struct Pair {
        std::int32_t i, j;  // local indices, id[i] < id[j]
    };
    std::vector<Pair> pairs;
    std::size_t counted = 0;             // pairs[0, counted): the lower id is owned here
    std::vector<std::size_t> found_at;   // pairs[found_at[a], found_at[a + 1]): the counted pairs found at owned a
    // Owned particle l's row of pair indices: rows[row_start[l], row_mid[l]) where l is j, ascending by
    // partner id, then rows[row_mid[l], row_start[l + 1]) where l is i, ascending.
    std::vector<std::int32_t> rows;
    std::vector<std::size_t> row_start, row_mid;
    // Summed `block` owned particles at a time, after the pairs found at the block: the most counted
    // slots from the oldest one a block's sum reads to the last the block's pairs write.
    std::size_t reach = 0;

    // Owned first in the local order: a pair (a, b), a < b, has an owned particle exactly when a is owned.
    void build(const RankParticles& p, double cell, double skin, std::size_t block)
    {
        const std::size_t n = p.size(), no = p.owned();
        px_.resize(n);
        py_.resize(n);
        pz_.resize(n);
        for (std::size_t l = 0; l < n; ++l) {
            px_[l] = p.x[l].x;
            py_[l] = p.x[l].y;
            pz_[l] = p.x[l].z;
        }
        if (n > cells_reserved_) {
            cells_reserved_ = n + n / 4;
            cells_.reserve(cells_reserved_);
        }
        pairs.clear();
        const double half_skin = 0.5 * skin;  // may_touch with each radius grown: pairs closer than R_i + R_j + skin
        if (n > 0) cells_.build(n, px_.data(), py_.data(), pz_.data(), cell);
        for (std::size_t a = 0; a < no; ++a)
            cells_.for_each_above(a, [&](std::size_t b) {
                if (!may_touch(p.x[a], p.x[b], p.r[a] + half_skin, p.r[b] + half_skin)) return;
                pairs.push_back(p.id[a] < p.id[b] ? Pair{std::int32_t(a), std::int32_t(b)} : Pair{std::int32_t(b), std::int32_t(a)});
            });
        const auto mine = std::stable_partition(pairs.begin(), pairs.end(), [no](const Pair& q) { return std::size_t(q.i) < no; });
        counted = std::size_t(mine - pairs.begin());
        found_at.assign(no + 1, counted);
        for (std::size_t k = counted; k-- > 0;) found_at[std::size_t(std::min(pairs[k].i, pairs[k].j))] = k;
        for (std::size_t a = no; a-- > 0;) found_at[a] = std::min(found_at[a], found_at[a + 1]);  // a with no pairs
        row_start.assign(no + 1, 0);
        for (const Pair& q : pairs) {
            if (std::size_t(q.i) < no) ++row_start[std::size_t(q.i) + 1];
            if (std::size_t(q.j) < no) ++row_start[std::size_t(q.j) + 1];
        }
        for (std::size_t l = 0; l < no; ++l) row_start[l + 1] += row_start[l];
        entries_.resize(row_start[no]);
        fill_.assign(row_start.begin(), row_start.end() - 1);
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            const Pair& q = pairs[k];
            if (std::size_t(q.i) < no) entries_[fill_[std::size_t(q.i)]++] = {p.id[std::size_t(q.j)], std::int32_t(k)};
            if (std::size_t(q.j) < no) entries_[fill_[std::size_t(q.j)]++] = {p.id[std::size_t(q.i)], std::int32_t(k)};
        }
        rows.resize(entries_.size());
        row_mid.resize(no);
        reach = 0;
        for (std::size_t l = 0; l < no; ++l) {
            const std::size_t b = row_start[l], e = row_start[l + 1];
            for (std::size_t f = b + 1; f < e; ++f)  // a few partners per row: insertion sort
                for (std::size_t k = f; k > b && entries_[k - 1].partner > entries_[k].partner; --k) std::swap(entries_[k - 1], entries_[k]);
            row_mid[l] = b;
            std::size_t oldest = counted;
            for (std::size_t f = b; f < e; ++f) {
                rows[f] = entries_[f].pair;
                if (entries_[f].partner < p.id[l]) row_mid[l] = f + 1;
                if (std::size_t(rows[f]) < counted) oldest = std::min(oldest, std::size_t(rows[f]));
            }
            if (oldest < counted) reach = std::max(reach, found_at[std::min(no, (l / block + 1) * block)] - oldest);
        }
    }

    std::size_t memory_bytes() const
    {
        return pairs.capacity() * sizeof(Pair) + rows.capacity() * sizeof(std::int32_t) + entries_.capacity() * sizeof(Entry) +
               (found_at.capacity() + row_start.capacity() + row_mid.capacity() + fill_.capacity()) * sizeof(std::size_t) +
               (px_.capacity() + py_.capacity() + pz_.capacity()) * sizeof(double) + cells_.memory_bytes();
    }

private:
    struct Entry {
        std::int64_t partner;  // the partner's id: the key of the canonical order
        std::int32_t pair;
    };

    std::vector<Entry> entries_;  // the rows with their keys, while they are sorted
    std::vector<double> px_, py_, pz_;  // the positions as the cells read them
    LinkedCells cells_;
    std::size_t cells_reserved_ = 0;
    std::vector<std::size_t> fill_;
};

} // namespace demmat::mpi
