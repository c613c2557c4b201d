#pragma once
// One rank's contact memory under a law of physics.md §9 (contact_memory.hpp): the stretch of each
// listed pair (a slot per pair of the neighbour list, zero unless the pair was in contact at the last
// force evaluation) and of each owned particle's contact with each wall (a row of one slot per wall).
// Keys are ids, never slots: across a rebuild the pairs' stretches pass through a map keyed by the pair
// (lower id, higher id); a migrant takes along its walls' row and the stretches of its pairs, which the
// rank it joins needs for the pairs with particles it did not hold (a pair that straddles a face is held,
// and updated from the same inputs, by both ranks).
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "comm.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/state.hpp"

namespace demmat::mpi {

struct PairKey {
    std::int64_t i, j;  // i < j
    bool operator==(const PairKey&) const = default;
};
struct PairKeyHash {
    std::size_t operator()(const PairKey& k) const
    {
        return std::size_t((std::uint64_t(k.i) * 0x9e3779b97f4a7c15ull) ^ (std::uint64_t(k.j) + 0x632be59bd9b4e019ull));
    }
};

// A stretch on the wire: i, j (j = −1 − w for wall w), ξ (3), ξ_r (3).
inline constexpr std::size_t kStretchDoubles = 8;

inline void pack_stretch(std::vector<double>& out, std::int64_t i, std::int64_t j, const Stretch<double>& s)
{
    out.insert(out.end(), {id_to_double(i), id_to_double(j), s.t.x, s.t.y, s.t.z, s.r.x, s.r.y, s.r.z});
}
inline Stretch<double> unpack_stretch(const double* p) { return {{p[2], p[3], p[4]}, {p[5], p[6], p[7]}}; }

struct RankStretches {
    std::size_t walls = 0;
    std::vector<Stretch<double>> pair;             // per pair of the list
    std::vector<Stretch<double>> wall;             // (owned, walls)
    std::vector<char> wall_live;                   // (owned, walls): in contact at the last evaluation
    std::unordered_map<PairKey, Stretch<double>, PairKeyHash> pending;  // pairs' stretches across a rebuild

    Stretch<double>* wall_row(std::size_t l) { return &wall[l * walls]; }

    void resize_owned(std::size_t n)
    {
        wall.resize(n * walls);
        wall_live.resize(n * walls);
    }
    // Owned particle `last` moved into slot l (RankParticles::remove_owned).
    void move_owned(std::size_t last, std::size_t l)
    {
        for (std::size_t w = 0; w < walls; ++w) {
            wall[l * walls + w] = wall[last * walls + w];
            wall_live[l * walls + w] = wall_live[last * walls + w];
        }
    }
    // The owned particles took a new order (RankParticles::permute_owned): slot s's row is slot from[s]'s.
    void permute_owned(const std::vector<std::size_t>& from)
    {
        const std::vector<Stretch<double>> old = wall;
        const std::vector<char> old_live = wall_live;
        for (std::size_t s = 0; s < from.size(); ++s)
            for (std::size_t w = 0; w < walls; ++w) {
                wall[s * walls + w] = old[from[s] * walls + w];
                wall_live[s * walls + w] = old_live[from[s] * walls + w];
            }
    }
    void pack_wall_row(std::size_t l, std::vector<double>& out) const
    {
        for (std::size_t w = 0; w < walls; ++w) {
            const Stretch<double>& s = wall[l * walls + w];
            out.insert(out.end(), {double(wall_live[l * walls + w]), s.t.x, s.t.y, s.t.z, s.r.x, s.r.y, s.r.z});
        }
    }
    static constexpr std::size_t kWallDoubles = 7;  // per wall in a migrant's row: live, ξ, ξ_r
    void set_wall_row(std::size_t l, const double* p)
    {
        for (std::size_t w = 0; w < walls; ++w, p += kWallDoubles) {
            wall_live[l * walls + w] = p[0] != 0.0;
            wall[l * walls + w] = {{p[1], p[2], p[3]}, {p[4], p[5], p[6]}};
        }
    }

    std::size_t memory_bytes() const
    {
        return (pair.capacity() + wall.capacity()) * sizeof(Stretch<double>) + wall_live.capacity() +
               pending.size() * (sizeof(PairKey) + sizeof(Stretch<double>) + 2 * sizeof(void*));
    }
};

} // namespace demmat::mpi
