#pragma once
// Linked cells for the contact search (physics.md §5), shared by the variants that keep particles in
// flat arrays: cubic cells of edge s over the particles' bounding box, each cell a linked list
// (head, next) as in the Fortran original, lists ascending by particle index.
//
// The table of list heads has a fixed size, the first power of two ≥ 2N. When the box, padded by one
// empty cell on every side, has no more cells than that, a cell's linear index is its slot (the
// classic dense grid) and the 27 neighbour slots are the particle's slot plus fixed offsets, with no
// bounds checks; otherwise cells are hashed into the table and a particle is taken from a slot only if
// its own cell is the one visited. Memory is O(N) whatever the domain: the paper's literal 2 m box of
// 8 mm grains would need 200³ cells of bookkeeping per step.
//
// This is search, not physics: the set it yields is a superset filter for may_touch, and the trajectory
// does not depend on it (cells of 2·R_max, 4·R_max and every pair agree bit for bit).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"

namespace demmat {

// floor(q) as an integer cell coordinate. A NaN, an infinity or a coordinate beyond 2^40 cells means the
// run has blown up (the conversion would be undefined): stop with the particle; the driver adds the step.
template <class T>
inline std::int64_t cell_coordinate(T q, std::size_t particle)
{
    const T f = std::floor(q);
    if (!(std::abs(f) < T(1099511627776.0)))
        throw InstabilityError(fmt::format("particle {} has a non-finite or runaway position (found by the cell search)", particle),
                               -1, std::int64_t(particle));
    return std::int64_t(f);
}

class LinkedCells {
public:
    using Index = std::int32_t;

    void reserve(std::size_t n)
    {
        std::size_t table = 1;
        while (table < 2 * n) table *= 2;
        head_.assign(table, -1);
        next_.assign(n, -1);
        slot_.assign(n, 0);
        cx_.assign(n, 0);
        cy_.assign(n, 0);
        cz_.assign(n, 0);
    }

    // Bins n particles whose coordinates are x[i], y[i], z[i] into cells of edge `edge`.
    template <class T>
    void build(std::size_t n, const T* x, const T* y, const T* z, T edge)
    {
        const T* xs[3] = {x, y, z};
        std::int64_t* cs[3] = {cx_.data(), cy_.data(), cz_.data()};
        for (int c = 0; c < 3; ++c) {
            const T lo = *std::min_element(xs[c], xs[c] + n);
            std::int64_t hi = 0;
            for (std::size_t i = 0; i < n; ++i) {
                cs[c][i] = cell_coordinate((xs[c][i] - lo) / edge, i) + 1;  // +1: an empty padding layer
                hi = std::max(hi, cs[c][i]);
            }
            dims_[c] = hi + 2;
        }
        const auto table = std::uint64_t(head_.size());
        direct_ = double(dims_[0]) * double(dims_[1]) * double(dims_[2]) <= double(table);
        mask_ = table - 1;
        if (direct_) {
            int k = 0;
            for (std::int64_t dz = -1; dz <= 1; ++dz)
                for (std::int64_t dy = -1; dy <= 1; ++dy)
                    for (std::int64_t dx = -1; dx <= 1; ++dx) offset_[k++] = dx + dims_[0] * (dy + dims_[1] * dz);
        }
        std::fill(head_.begin(), head_.end(), Index(-1));
        for (std::size_t i = n; i-- > 0;) {  // pushed in descending order: each cell's list ascends
            const std::uint64_t s = slot(cx_[i], cy_[i], cz_[i]);
            slot_[i] = s;
            next_[i] = head_[s];
            head_[s] = Index(i);
        }
    }

    // Calls f(j) for every particle j > i in the 27 cells around particle i's cell.
    template <class F>
    void for_each_above(std::size_t i, F&& f) const
    {
        const Index* head = head_.data();
        const Index* next = next_.data();
        if (direct_) {
            const auto s = std::int64_t(slot_[i]);
            for (int k = 0; k < 27; ++k)
                for (Index j = head[s + offset_[k]]; j >= 0; j = next[j])
                    if (std::size_t(j) > i) f(std::size_t(j));
            return;
        }
        for (std::int64_t dz = -1; dz <= 1; ++dz)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dx = -1; dx <= 1; ++dx) {
                    const std::int64_t qx = cx_[i] + dx, qy = cy_[i] + dy, qz = cz_[i] + dz;
                    for (Index j = head[slot(qx, qy, qz)]; j >= 0; j = next[j])
                        if (std::size_t(j) > i && cx_[j] == qx && cy_[j] == qy && cz_[j] == qz) f(std::size_t(j));
                }
    }

    std::size_t memory_bytes() const
    {
        return (head_.size() + next_.size()) * sizeof(Index) + slot_.size() * sizeof(std::uint64_t) +
               3 * cx_.size() * sizeof(std::int64_t);
    }

private:
    std::uint64_t slot(std::int64_t ix, std::int64_t iy, std::int64_t iz) const
    {
        if (direct_) return std::uint64_t(ix + dims_[0] * (iy + dims_[1] * iz));
        const std::uint64_t h = std::uint64_t(ix) * 73856093ull ^ std::uint64_t(iy) * 19349663ull ^ std::uint64_t(iz) * 83492791ull;
        return (h * 0x9e3779b97f4a7c15ull >> 20) & mask_;
    }

    std::vector<Index> head_, next_;
    std::vector<std::uint64_t> slot_;
    std::vector<std::int64_t> cx_, cy_, cz_;
    std::int64_t dims_[3] = {0, 0, 0};
    std::int64_t offset_[27] = {};
    std::uint64_t mask_ = 0;
    bool direct_ = true;
};

// Counts candidates per particle while a search stores at most `cap` of them, so that an overflow can
// name the value that would fit (the paper's "control of overestimation").
class CandidateOverflow {
public:
    void note(std::int64_t count, std::size_t i)
    {
        if (count > worst_) {
            worst_ = count;
            particle_ = std::int64_t(i);
        }
    }
    void check(std::int64_t cap) const
    {
        if (worst_ > cap)
            throw CapacityError(fmt::format("capacity.contacts_per_particle = {} exceeded: particle {} has {} candidate "
                                            "partners; set it to at least {} in the scene", cap, particle_, worst_, worst_));
    }

private:
    std::int64_t worst_ = 0, particle_ = -1;
};

// Inserts j into row[0, count) kept ascending (a particle has few partners: insertion is cheapest).
template <class I>
inline void insert_ascending(I* row, std::int64_t count, I j)
{
    std::int64_t k = count;
    while (k > 0 && row[k - 1] > j) {
        row[k] = row[k - 1];
        --k;
    }
    row[k] = j;
}

} // namespace demmat
