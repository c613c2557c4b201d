#pragma once
// The walls each owned particle of a rank may touch this step (no list: a wall may move): a bit per wall
// and particle, marked in one vectorised pass over the owned particles; the sums read the bits in wall
// order.
#include <bit>
#include <cstdint>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/state.hpp"
#include "rank_gear.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

// The walls owned particle l may touch: bit w % 64 of word l * words + w / 64 of `near`, where words =
// wall_words(walls) (one word for up to 64 walls, all walls tested in one pass over the particles).
inline std::size_t wall_words(std::size_t walls) { return (walls + 63) / 64; }

inline void mark_wall_candidates(const RankParticles& p, const std::vector<Wall>& walls, const std::vector<Vec3d>& points,
                                 std::vector<std::uint64_t>& near)
{
    const std::size_t no = p.owned(), nw = walls.size(), words = wall_words(nw);
    near.assign(no * words, 0);
    std::uint64_t* __restrict bits = near.data();
    const double* __restrict x = flat(p.x);
    const double* __restrict r = p.r.data();
    if (words == 1) {
#pragma omp simd
        for (std::size_t l = 0; l < no; ++l) {
            std::uint64_t b = 0;
            for (std::size_t w = 0; w < nw; ++w)
                b |= std::uint64_t(may_touch_wall(Vec3d{x[3 * l], x[3 * l + 1], x[3 * l + 2]}, r[l], points[w], walls[w].normal)) << w;
            bits[l] = b;
        }
        return;
    }
    for (std::size_t w = 0; w < nw; ++w)
        for (std::size_t l = 0; l < no; ++l)
            bits[l * words + w / 64] |= std::uint64_t(may_touch_wall(p.x[l], r[l], points[w], walls[w].normal)) << (w % 64);
}

} // namespace demmat::mpi
