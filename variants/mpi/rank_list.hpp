#pragma once
// A rank's neighbour list (docs/variants.md, "mpi"): every pair with an owned particle closer than
// R_i + R_j + skin, found by the linked cells over owned particles and ghosts, each pair once with the
// lower id as i (`pairs`, the pairs whose i this rank owns first, so that a contact is counted once
// over all ranks); and each owned particle's row of its pairs, by ascending partner id: the canonical
// order of its sum (physics.md §6), whatever the local order.
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
    struct Entry {
        std::int64_t partner;  // the partner's id: the key of the canonical order
        std::int32_t pair;
        bool lower;            // this particle is the pair's i (the lower id)
    };

    std::vector<Pair> pairs;
    std::size_t counted = 0;            // pairs[0, counted): the lower id is owned here
    std::vector<Entry> rows;            // owned particle l's row: rows[row_start[l], row_start[l + 1])
    std::vector<std::size_t> row_start;

    // Owned first in the local order: a pair (a, b), a < b, has an owned particle exactly when a is owned.
    void build(const RankParticles& p, double cell, double skin)
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
        row_start.assign(no + 1, 0);
        for (const Pair& q : pairs) {
            if (std::size_t(q.i) < no) ++row_start[std::size_t(q.i) + 1];
            if (std::size_t(q.j) < no) ++row_start[std::size_t(q.j) + 1];
        }
        for (std::size_t l = 0; l < no; ++l) row_start[l + 1] += row_start[l];
        rows.resize(row_start[no]);
        fill_.assign(row_start.begin(), row_start.end() - 1);
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            const Pair& q = pairs[k];
            if (std::size_t(q.i) < no) rows[fill_[std::size_t(q.i)]++] = {p.id[std::size_t(q.j)], std::int32_t(k), true};
            if (std::size_t(q.j) < no) rows[fill_[std::size_t(q.j)]++] = {p.id[std::size_t(q.i)], std::int32_t(k), false};
        }
        for (std::size_t l = 0; l < no; ++l)  // a few partners per row: insertion sort
            for (std::size_t e = row_start[l] + 1; e < row_start[l + 1]; ++e)
                for (std::size_t k = e; k > row_start[l] && rows[k - 1].partner > rows[k].partner; --k) std::swap(rows[k - 1], rows[k]);
    }

    std::size_t memory_bytes() const
    {
        return pairs.capacity() * sizeof(Pair) + rows.capacity() * sizeof(Entry) + (row_start.capacity() + fill_.capacity()) * sizeof(std::size_t) +
               (px_.capacity() + py_.capacity() + pz_.capacity()) * sizeof(double) + cells_.memory_bytes();
    }

private:
    std::vector<double> px_, py_, pz_;  // the positions as the cells read them
    LinkedCells cells_;
    std::size_t cells_reserved_ = 0;
    std::vector<std::size_t> fill_;
};

} // namespace demmat::mpi
