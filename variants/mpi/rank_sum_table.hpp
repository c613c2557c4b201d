#pragma once
// The slots each group of kGroup owned particles sums under the paper's law, as one table per group
// (made at a rebuild): entry e of every member's row side by side, the rows where the members are j,
// then those where they are i (rank_list.hpp), each entry the slot's position (rank_pair_kernel.hpp),
// a row shorter than the group's longest padded with the slot of zeros. So the sums run four at a time
// with no test per entry (the additions of one sum wait for each other; those of four sums do not),
// and a padded entry adds +0 or -0, which changes no sum (a sum that starts at +0 is never -0, and
// x + ±0 = x): the bits are those of each sum alone.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "demmat/lane_engine/heap_bytes.hpp"
#include "rank_list.hpp"

namespace demmat::mpi {

class RankSumTable {
public:
    static constexpr std::size_t kGroup = 4;

    struct Group {
        std::uint32_t table;      // where its entries start
        std::uint16_t as_j, as_i;  // the longest of its members' rows where they are j, and where i
    };

    // Owned particles in groups from 0; position(k) is pair k's slot, zero the slot of zeros.
    template <class Position>
    void build(const RankList& list, std::size_t owned, Position&& position, std::int32_t zero)
    {
        groups_.resize((owned + kGroup - 1) / kGroup);
        table_.clear();
        for (std::size_t q = 0; q < groups_.size(); ++q) {
            const std::size_t l0 = q * kGroup, n = std::min(kGroup, owned - l0);
            std::size_t as_j = 0, as_i = 0;
            for (std::size_t g = 0; g < n; ++g) {
                as_j = std::max(as_j, list.row_mid[l0 + g] - list.row_start[l0 + g]);
                as_i = std::max(as_i, list.row_start[l0 + g + 1] - list.row_mid[l0 + g]);
            }
            groups_[q] = {std::uint32_t(table_.size()), std::uint16_t(as_j), std::uint16_t(as_i)};
            auto add = [&](std::size_t e, auto begin, auto end) {
                for (std::size_t g = 0; g < kGroup; ++g) {
                    const std::size_t l = l0 + g;
                    const std::size_t at = g < n ? begin(l) + e : 0;
                    table_.push_back(g < n && at < end(l) ? position(std::size_t(list.rows[at])) : zero);
                }
            };
            for (std::size_t e = 0; e < as_j; ++e)
                add(e, [&](std::size_t l) { return list.row_start[l]; }, [&](std::size_t l) { return list.row_mid[l]; });
            for (std::size_t e = 0; e < as_i; ++e)
                add(e, [&](std::size_t l) { return list.row_mid[l]; }, [&](std::size_t l) { return list.row_start[l + 1]; });
        }
    }

    const Group& group(std::size_t q) const { return groups_[q]; }
    const std::int32_t* table(const Group& g) const { return table_.data() + g.table; }

    std::size_t memory_bytes() const { return fast::heap_bytes(groups_, table_); }

private:
    std::vector<Group> groups_;
    std::vector<std::int32_t> table_;
};

} // namespace demmat::mpi
