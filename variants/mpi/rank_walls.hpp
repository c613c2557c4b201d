#pragma once
// The walls each owned particle of a rank may touch this step (no list: a wall may move), in particle
// order, walls in wall order: a bit per wall and particle, marked a wall at a time over all owned
// particles (vectorised, as fast's wall marks), then the candidates read from the bits.
#include <bit>
#include <cstdint>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/state.hpp"
#include "rank_gear.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

// Owned particle l's candidates: rows[start[l], start[l + 1]). `near` is scratch.
inline void list_wall_candidates(const RankParticles& p, const std::vector<Wall>& walls, const std::vector<Vec3d>& points,
                                 std::vector<std::size_t>& start, std::vector<std::int32_t>& rows, std::vector<std::uint64_t>& near)
{
    const std::size_t no = p.owned(), nw = walls.size();
    start.assign(no + 1, 0);
    rows.clear();
    if (nw > 64) {  // more walls than bits: one test at a time
        for (std::size_t l = 0; l < no; ++l) {
            for (std::size_t w = 0; w < nw; ++w)
                if (may_touch_wall(p.x[l], p.r[l], points[w], walls[w].normal)) rows.push_back(std::int32_t(w));
            start[l + 1] = rows.size();
        }
        return;
    }
    near.assign(no, 0);
    std::uint64_t* __restrict bits = near.data();
    const double* __restrict x = flat(p.x);
    const double* __restrict r = p.r.data();
    for (std::size_t w = 0; w < nw; ++w) {
        const Vec3d pt = points[w], nrm = walls[w].normal;
#pragma omp simd
        for (std::size_t l = 0; l < no; ++l)
            bits[l] |= std::uint64_t(may_touch_wall(Vec3d{x[3 * l], x[3 * l + 1], x[3 * l + 2]}, r[l], pt, nrm)) << w;
    }
    for (std::size_t l = 0; l < no; ++l) {
        for (std::uint64_t b = bits[l]; b != 0; b &= b - 1) rows.push_back(std::int32_t(std::countr_zero(b)));
        start[l + 1] = rows.size();
    }
}

} // namespace demmat::mpi
