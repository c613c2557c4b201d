#pragma once
// One rank's contact memory under a law of physics.md §9 (contact_memory.hpp) besides the pairs' (the
// pair kernel keeps a listed pair's stretch in its record, rank_pair_kernel.hpp): each owned particle's
// contact with each wall (a row of one slot per wall), and the pairs' stretches across a rebuild.
// Keys are ids, never slots: across a rebuild the pairs' stretches pass through a map keyed by the pair
// (lower id, higher id); a migrant takes along its walls' row and the stretches of its pairs, which the
// rank it joins needs for the pairs with particles it did not hold (a pair that straddles a face is held,
// and updated from the same inputs, by both ranks).
#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "bricks.hpp"
#include "comm.hpp"
#include "rank_particles.hpp"
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

    // Rank 0's state's stretches (collective), to the ranks that own a contact's particles (both, for a
    // pair that straddles a face): a wall contact into its owned particle's row, a pair into `pending`
    // for the first rebuild. `p` holds this rank's owned particles, no ghosts yet.
    void load(const Comm& comm, const Bricks& bricks, const State& s, std::size_t wall_count, const RankParticles& p)
    {
        walls = wall_count;
        resize_owned(p.owned());
        std::vector<std::vector<double>> parts;
        if (comm.root()) {
            parts.resize(std::size_t(comm.size()));
            auto owner = [&](std::int64_t i) { return bricks.owner(s.trans.x[std::size_t(i)]); };
            for (const ContactStretch& c : s.stretches) {
                const Stretch<double> v{c.tangential, c.rolling};
                const int oi = owner(c.i);
                pack_stretch(parts[std::size_t(oi)], c.i, c.wall ? -1 - c.partner : c.partner, v);
                if (!c.wall && owner(c.partner) != oi) pack_stretch(parts[std::size_t(owner(c.partner))], c.i, c.partner, v);
            }
        }
        const std::vector<double> mine = comm.scatter(parts);
        std::unordered_map<std::int64_t, std::size_t> local;
        for (std::size_t l = 0; l < p.owned(); ++l) local[p.id[l]] = l;
        for (std::size_t at = 0; at + kStretchDoubles <= mine.size(); at += kStretchDoubles) {
            const double* q = &mine[at];
            const std::int64_t i = double_to_id(q[0]), j = double_to_id(q[1]);
            if (j < 0) {
                const std::size_t w = std::size_t(-1 - j), l = local.at(i);
                wall_row(l)[w] = unpack_stretch(q);
                wall_live[l * walls + w] = 1;
            } else {
                pending[{i, j}] = unpack_stretch(q);
            }
        }
    }

    // Every live contact's stretch once (collective): `pairs`, the rank's packed pair contacts (each once
    // over the ranks), and the wall contacts of its owned particles, gathered into rank 0's `out` in the
    // canonical order.
    void save(const Comm& comm, std::vector<double> pairs, const RankParticles& p, State& out) const
    {
        std::vector<double>& mine = pairs;
        const std::size_t no = p.owned();
        for (std::size_t l = 0; l < no; ++l)
            for (std::size_t w = 0; w < walls; ++w)
                if (wall_live[l * walls + w]) pack_stretch(mine, p.id[l], -1 - std::int64_t(w), wall[l * walls + w]);
        const std::vector<double> all = comm.gather(mine);
        for (std::size_t at = 0; at + kStretchDoubles <= all.size(); at += kStretchDoubles) {
            const double* q = &all[at];
            const std::int64_t i = double_to_id(q[0]), j = double_to_id(q[1]);
            const Stretch<double> v = unpack_stretch(q);
            out.stretches.push_back({i, j < 0 ? -1 - j : j, j < 0, v.t, v.r});
        }
        std::sort(out.stretches.begin(), out.stretches.end());
    }

    std::size_t memory_bytes() const
    {
        return wall.capacity() * sizeof(Stretch<double>) + wall_live.capacity() +
               pending.size() * (sizeof(PairKey) + sizeof(Stretch<double>) + 2 * sizeof(void*));
    }
};

} // namespace demmat::mpi
