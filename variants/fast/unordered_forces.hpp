#pragma once
// fast_unordered's force pass (FastOptions::canonical = false): what an unordered code does. Each pack's
// forces are added to both particles as they come, into loads of the thread's own (zeroed over the
// span of storage its pairs reach, set at the rebuild); after a barrier each particle sums its loads
// over the threads, in thread order, and adds its walls. Deterministic for a fixed thread count, but
// its bits depend on the storage order and the thread count.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

#include "demmat/lane_engine/heap_bytes.hpp"
#include "demmat/lane_engine/neighbour_list.hpp"
#include "demmat/lane_engine/pair_kernel.hpp"
#include "demmat/lane_engine/particles.hpp"
#include "demmat/lane_engine/team.hpp"
#include "demmat/lane_engine/wall_contacts.hpp"

namespace demmat::fast {

class UnorderedForces {
public:
    struct Counts {
        std::int64_t pairs = 0, walls = 0;
        std::size_t team = 1;
    };

    template <class M>
    Counts run(const NeighbourList& list, WallContacts& walls, Particles& p, const LawInputs& law, bool prefetch, bool parallel)
    {
        const std::size_t n = p.n;
        const std::size_t limit = std::size_t(thread_limit());
        if (loads_.size() < limit) loads_.resize(limit);
        std::atomic<std::int64_t> pp{0}, pw{0};
        std::size_t team = 1;
        const PairKernel<M> kernel(list, p, law, nullptr, prefetch);
        in_team(parallel, [&] {
            const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
            if (t == 0) team = nt;
            const auto [lo, hi] = thread_range(n);
            // A thread count other than the rebuild's (no rebuild since it changed): every thread zeroes all.
            const bool spans_known = list.spans.size() == nt;
            auto span = [&](std::size_t u) { return spans_known ? list.spans[u] : std::pair<std::size_t, std::size_t>{0, n}; };
            std::vector<Load>& mine = loads_[t];
            if (mine.size() != n) mine.resize(n);
            const auto [z0, z1] = span(t);
            std::fill(mine.begin() + std::ptrdiff_t(z0), mine.begin() + std::ptrdiff_t(z1), Load{});
            if constexpr (M::walls) pw += walls.compute<M>(p, law);  // the lists and records were made by predict() or a rebuild
            pp += kernel.template run<false>(std::size_t(list.start[lo]), std::size_t(list.start[hi]), mine.data());
#pragma omp barrier
            for (std::size_t s = lo; s < hi; ++s) {
                Quad f{}, tq{};
                for (std::size_t u = 0; u < nt; ++u) {
                    const auto [u0, u1] = span(u);
                    if (s < u0 || s >= u1) continue;
                    f += loads_[u][s].f;
                    tq += loads_[u][s].t;
                }
                walls.add(s, f, tq);
                p.store_sum(s, f, tq);
            }
        });
        return {pp.load(), pw.load(), team};
    }

    std::size_t bytes() const { return heap_bytes(loads_); }

private:
    PerThread<std::vector<Load>> loads_;  // loads in storage order
};

} // namespace demmat::fast
