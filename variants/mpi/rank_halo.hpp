#pragma once
// What a rank exchanges with the bricks around it (bricks.hpp), one stage per cut axis (x, then y, then
// z), each stage one message to each of the two neighbours along that axis:
//
//   migrate          at a rebuild, owned particles whose brick is another rank's go to it with their whole
//                    Gear history (and, under a law with memory, their wall stretches and the stretches
//                    of their pairs, by key); one whose new brick is diagonal travels through a neighbour,
//                    a stage per axis it crossed
//   exchange_ghosts  then ghost copies of the particles within the halo of each shared face: at the stage
//                    of axis a, of the owned particles and of the ghosts received at the earlier stages, so
//                    the bricks across an edge or a corner receive theirs through a neighbour (the usual
//                    staged exchange, as LAMMPS's comm and ExaMiniMD's do it); each is sent once
//   refresh_ghosts   between rebuilds, position, velocity and angular velocity of the same particles in the
//                    same order, stage by stage (a ghost forwarded at a later stage is refreshed first)
//
// A particle moves less than half the skin between rebuilds and the halo is the contact range plus the
// skin, so the ghosts hold every partner an owned particle may touch until the next rebuild.
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "bricks.hpp"
#include "comm.hpp"
#include "demmat/error.hpp"
#include "rank_particles.hpp"
#include "rank_stretches.hpp"

namespace demmat::mpi {

class RankHalo {
public:
    RankHalo(const Comm& comm, const Bricks& bricks, double halo) : bricks_(bricks), halo_(halo), me_(comm.rank())
    {
        for (int a = 0; a < 3; ++a)
            for (int side = 0; side < 2; ++side) next_[std::size_t(a)][std::size_t(side)] = bricks.neighbour(me_, a, side ? 1 : -1);
    }

    // Owned particles to the ranks whose bricks they are now in (ghosts must have been dropped). With `st`
    // (a law with memory), each migrant takes its wall row along, and the stretches in st->pending of
    // every pair it is in (st->pending holds the rank's live pairs by key; the receiver merges them into
    // its own). Returns the migrants this rank sent.
    std::int64_t migrate(Comm& comm, RankParticles& p, RankStretches* st)
    {
        std::int64_t sent = 0;
        const std::size_t record = kMigrantDoubles + (st ? st->walls * RankStretches::kWallDoubles : 0);
        for (int a = 0; a < 3; ++a) {
            if (bricks_.dims[std::size_t(a)] == 1) continue;
            const int mine = bricks_.coordinates(me_)[std::size_t(a)];
            for (auto& out : out_) out.assign(1, 0.0);  // the count of migrants, their records, then stretches
            leaving_.clear();
            for (std::size_t l = 0; l < p.owned();) {
                const int to = bricks_.index(a, component(p.x[l], a));
                if (to == mine) {
                    ++l;
                    continue;
                }
                if (to != mine - 1 && to != mine + 1)
                    throw InstabilityError(fmt::format("particle {} moved across more than one brick along {} between neighbour-list "
                                                       "rebuilds (from rank {}): the run has blown up",
                                                       p.id[l], "xyz"[a], me_),
                                           -1, p.id[l]);
                const int side = to > mine;
                std::vector<double>& out = out_[std::size_t(side)];
                p.pack_migrant(l, out);
                out[0] += 1.0;
                if (st) {
                    leaving_[p.id[l]] = side;
                    st->pack_wall_row(l, out);
                    st->move_owned(p.owned() - 1, l);
                }
                p.remove_owned(l);
                if (st) st->resize_owned(p.owned());
                ++sent;
            }
            if (st && !leaving_.empty())
                for (const auto& [key, s] : st->pending) {
                    const auto i = leaving_.find(key.i), j = leaving_.find(key.j);
                    if (i != leaving_.end()) pack_stretch(out_[std::size_t(i->second)], key.i, key.j, s);
                    if (j != leaving_.end() && (i == leaving_.end() || i->second != j->second)) pack_stretch(out_[std::size_t(j->second)], key.i, key.j, s);
                }
            swap(comm, a, 1);
            for (const std::vector<double>& in : in_) {
                if (in.empty()) continue;
                const std::size_t n = std::size_t(in[0]);
                for (std::size_t k = 0; k < n; ++k) {
                    const double* q = &in[1 + k * record];
                    p.add_migrant(q);
                    if (st) {
                        st->resize_owned(p.owned());
                        st->set_wall_row(p.owned() - 1, q + kMigrantDoubles);
                    }
                }
                if (st)
                    for (std::size_t at = 1 + n * record; at + kStretchDoubles <= in.size(); at += kStretchDoubles) {
                        const double* q = &in[at];
                        st->pending[{double_to_id(q[0]), double_to_id(q[1])}] = unpack_stretch(q);
                    }
            }
        }
        return sent;
    }

    // Ghost copies for the neighbours, stage by stage; the rank's ghosts are appended in the order they
    // arrive (stage, then from below, then from above), and each stage's sends are remembered for
    // refresh_ghosts.
    void exchange_ghosts(Comm& comm, RankParticles& p)
    {
        for (int a = 0; a < 3; ++a) {
            Stage& g = stages_[std::size_t(a)];
            for (auto& s : g.send) s.clear();
            g.first = p.size();
            g.count = {0, 0};
            if (bricks_.dims[std::size_t(a)] == 1) continue;
            const double lo = bricks_.low(me_, a), hi = bricks_.high(me_, a);
            for (auto& out : out_) out.clear();
            for (std::size_t l = 0; l < p.size(); ++l) {  // owned and the ghosts of the earlier stages
                const double c = component(p.x[l], a);
                if (next_[std::size_t(a)][0] >= 0 && c - lo < halo_) {
                    p.pack_ghost(l, out_[0]);
                    g.send[0].push_back(std::int32_t(l));
                }
                if (next_[std::size_t(a)][1] >= 0 && hi - c < halo_) {
                    p.pack_ghost(l, out_[1]);
                    g.send[1].push_back(std::int32_t(l));
                }
            }
            swap(comm, a, 2);
            for (int side = 0; side < 2; ++side) {
                g.count[std::size_t(side)] = in_[std::size_t(side)].size() / kGhostDoubles;
                p.add_ghosts(in_[std::size_t(side)]);
            }
        }
    }

    // The ghosts' position, velocity and angular velocity from the particles they copy, stage by stage.
    void refresh_ghosts(Comm& comm, RankParticles& p)
    {
        for (int a = 0; a < 3; ++a) {
            if (bricks_.dims[std::size_t(a)] == 1) continue;
            const Stage& g = stages_[std::size_t(a)];
            for (int side = 0; side < 2; ++side) {
                std::vector<double>& out = out_[std::size_t(side)];
                out.clear();
                for (std::int32_t l : g.send[std::size_t(side)])
                    for (const Vec3d* q : {&p.x[std::size_t(l)], &p.v[std::size_t(l)], &p.w[std::size_t(l)]})
                        for (int c = 0; c < 3; ++c) out.push_back(component(*q, c));
            }
            swap(comm, a, 3);
            std::size_t first = g.first;
            for (int side = 0; side < 2; ++side) {
                const std::vector<double>& in = in_[std::size_t(side)];
                const std::size_t count = g.count[std::size_t(side)];
                if (in.size() != 9 * count) throw Error("internal: a neighbour refreshed a different number of ghosts");
                for (std::size_t k = 0; k < count; ++k) {
                    const double* q = &in[9 * k];
                    p.x[first + k] = {q[0], q[1], q[2]};
                    p.v[first + k] = {q[3], q[4], q[5]};
                    p.w[first + k] = {q[6], q[7], q[8]};
                }
                first += count;
            }
        }
    }

    std::size_t memory_bytes() const
    {
        std::size_t b = 0;
        for (const auto& v : {&out_[0], &out_[1], &in_[0], &in_[1]}) b += v->capacity() * sizeof(double);
        for (const Stage& g : stages_) b += (g.send[0].capacity() + g.send[1].capacity()) * sizeof(std::int32_t);
        return b + leaving_.size() * (sizeof(std::int64_t) + sizeof(int) + 2 * sizeof(void*));
    }

private:
    // One message each way with the two neighbours along axis a (none past an end of the grid).
    void swap(Comm& comm, int a, int tag)
    {
        comm.exchange(next_[std::size_t(a)][0], next_[std::size_t(a)][1], out_[0], out_[1], in_[0], in_[1], tag);
    }

    struct Stage {
        std::array<std::vector<std::int32_t>, 2> send;  // the local particles copied to the neighbour below, above
        std::size_t first = 0;                          // the stage's ghosts: from below, then from above
        std::array<std::size_t, 2> count = {0, 0};
    };

    Bricks bricks_;
    double halo_;
    int me_;
    std::array<std::array<int, 2>, 3> next_{};  // the neighbour below and above along each axis, −1: none
    std::array<Stage, 3> stages_;
    std::array<std::vector<double>, 2> out_, in_;  // buffers to and from the neighbour below, above
    std::unordered_map<std::int64_t, int> leaving_;  // migrate: the side each migrant of a stage leaves by
};

} // namespace demmat::mpi
