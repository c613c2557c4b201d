#pragma once
// The fast variant's walls: no list. In predict()'s pass each particle gets a bit per wall it may touch
// (a scene has a handful of walls: testing each every step costs less than a wall list, and keeps the
// moving wall out of the rebuild criterion), the particle–wall pairs are listed from the bits per
// thread, in particle order, walls in wall order, and the force pass computes them a pack at a time on
// the lanes, the packs shared out among all threads (a wall's grains may all be in one thread's range).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/state.hpp"
#include "heap_bytes.hpp"
#include "particles.hpp"
#include "quads.hpp"
#include "team.hpp"

namespace demmat::fast {

// A force and a torque, a quad each (the fourth lanes unused): a wall contact's result, and in
// fast_unordered a particle's load. One cache line.
struct alignas(2 * sizeof(Quad)) Load {
    Quad f;
    Quad t;
};

class WallContacts {
public:
    void init(const std::vector<Wall>& walls, double dt, std::size_t n)
    {
        walls_ = walls;
        dt_ = dt;
        rec_.assign(walls_.size(), Record{});
        for (std::size_t w = 0; w < walls_.size(); ++w)
            for (int c = 0; c < 3; ++c) {
                rec_[w].n[c] = component(walls_[w].normal, c);
                rec_[w].v[c] = component(walls_[w].velocity, c);
            }
        near_.assign(n, 0);
        first_.assign(n, 0);
    }
    const std::vector<Wall>& walls() const { return walls_; }

    // Every wall where it is at this step.
    void place(std::int64_t step)
    {
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            const Vec3d p = walls_[w].point_at(step, dt_);
            for (int c = 0; c < 3; ++c) rec_[w].p[c] = component(p, c);
        }
    }

    // Room for every thread's list (before a parallel region that lists).
    void reserve_lists()
    {
        const std::size_t limit = std::size_t(thread_limit());
        if (cand_.size() < limit) {
            cand_.resize(limit);
            res_.resize(limit);
        }
    }

    // Thread t's list, for [lo, hi), its range of the particles: the bits of the walls each may touch
    // (may_touch_wall, vectorised over a chunk of particles, every wall over the chunk, so that the
    // chunk's positions are read once), then its pairs in particle order, walls in wall order. Beyond
    // kWallBits walls one bit stands for any, and each wall is tested again for the particles marked.
    void clear_list(std::size_t t) { cand_[t].clear(); }
    void list(const Particles& p, std::size_t lo, std::size_t hi, std::size_t t)
    {
        mark(p, lo, hi);
        std::vector<Candidate>& cand = cand_[t];
        const std::uint8_t* near = near_.data();
        const std::size_t nw = walls_.size();
        for (std::size_t s = lo; s < hi; ++s) {
            if (!near[s]) continue;
            first_[s] = Index(cand.size());
            if (nw <= kWallBits) {  // the walls are the bits, ascending
                for (unsigned m = near[s]; m != 0; m &= m - 1) cand.push_back({Index(s), Index(__builtin_ctz(m))});
                continue;
            }
            const Quad& xr = p.kin[s].xr;
            for (std::size_t w = 0; w < nw; ++w)
                if (may_touch_wall(Vec3d{xr[0], xr[1], xr[2]}, xr[3], point(w), normal(w))) cand.push_back({Index(s), Index(w)});
        }
    }
    void size_results(std::size_t t) { res_[t].resize(cand_[t].size()); }

    // The lists were made by a team of `team` threads, each its range of the particles (thread_range),
    // into lists 0 … team: the force pass, whatever its own team (OpenMP's dynamic teams may give it
    // another), reads those lists and finds a particle's by these ranges.
    void listed_by(std::size_t team, std::size_t n)
    {
        lists_ = team;
        range_end_.resize(team);
        for (std::size_t u = 0; u < team; ++u) range_end_[u] = range_end(n, u, team);
    }

    // The law on every list's candidates, kLanes pairs at a time, the packs shared out among the team
    // (zeros where h <= 0); no barrier at the end. Inside a parallel region. Returns the contacts found.
    std::int64_t compute(const Particles& p, const ContactParams<double>& params)
    {
        auto packs_of = [this](std::size_t u) { return (cand_[u].size() + kLanes - 1) / kLanes; };
        std::size_t packs = 0;
        for (std::size_t u = 0; u < lists_; ++u) packs += packs_of(u);
        std::int64_t found = 0;
#pragma omp for schedule(static) nowait
        for (std::size_t k = 0; k < packs; ++k) {
            std::size_t u = 0, first = 0;  // the list that pack k falls in, and its first pack
            while (k >= first + packs_of(u)) first += packs_of(u++);
            const std::size_t e = (k - first) * kLanes, count = std::min<std::size_t>(kLanes, cand_[u].size() - e);
            found += pack(p, params, cand_[u].data() + e, int(count), res_[u].data() + e);
        }
        return found;
    }

    // Particle s's walls added to its sum (f, tq), in wall order (zeros for a pair out of contact add
    // nothing).
    void add(std::size_t s, Quad& f, Quad& tq) const
    {
        if (!near_[s]) return;
        std::size_t u = 0;  // the list that holds s (a loop, not a division: cheaper)
        while (s >= range_end_[u]) ++u;
        const std::vector<Candidate>& cand = cand_[u];
        const Load* res = res_[u].data();
        for (std::size_t e = std::size_t(first_[s]); e < cand.size() && std::size_t(cand[e].s) == s; ++e) {
            f += res[e].f;
            tq += res[e].t;
        }
    }

    std::size_t bytes() const { return heap_bytes(walls_, rec_, near_, first_, cand_, res_, range_end_); }

private:
    static constexpr std::size_t kWallBits = 8;  // near_ holds a bit per wall up to this many walls

    // A wall as the kernel reads it: point (where it is this step), unit normal, velocity.
    struct alignas(sizeof(Quad)) Record {
        Quad p, n, v;  // (x, y, z, 0) each
    };
    // A particle–wall pair that may touch this step.
    struct Candidate {
        std::int32_t s, w;  // storage slot of the particle, wall index
    };

    Vec3d point(std::size_t w) const { return {rec_[w].p[0], rec_[w].p[1], rec_[w].p[2]}; }
    Vec3d normal(std::size_t w) const { return {rec_[w].n[0], rec_[w].n[1], rec_[w].n[2]}; }

    void mark(const Particles& p, std::size_t lo, std::size_t hi)
    {
        const std::size_t n = p.n, nw = walls_.size();
        const double* __restrict x = p.x.data();
        const double* __restrict r = p.r.data();
        std::uint8_t* __restrict near = near_.data();
        std::fill(near + lo, near + hi, std::uint8_t(0));
        constexpr std::size_t chunk = 512;
        for (std::size_t c0 = lo; c0 < hi; c0 += chunk) {
            const std::size_t c1 = std::min(hi, c0 + chunk);
            for (std::size_t w = 0; w < nw; ++w) {
                const Vec3d pt = point(w), nrm = normal(w);
                const int bit = nw <= kWallBits ? int(w) : 0;
#pragma omp simd
                for (std::size_t s = c0; s < c1; ++s)
                    near[s] |= std::uint8_t(std::uint8_t(may_touch_wall(Vec3d{x[s], x[n + s], x[2 * n + s]}, r[s], pt, nrm)) << bit);
            }
        }
    }

    // The wall law for up to kLanes particle–wall pairs (unused lanes repeat the last pair and are not
    // stored): the records transposed into the lanes, wall_contact_lanes, and back. Each lane's bits are
    // those wall_contact gives.
    int pack(const Particles& p, const ContactParams<double>& params, const Candidate* cand, int count, Load* out) const
    {
        std::size_t s[kLanes], w[kLanes];
        for (int l = 0; l < kLanes; ++l) {
            s[l] = std::size_t(cand[l < count ? l : count - 1].s);
            w[l] = std::size_t(cand[l < count ? l : count - 1].w);
        }
        const Kin* kin = p.kin.data();
        Lanes xr[4]{}, v[4]{}, om[4]{}, pt[4]{}, nrm[4]{}, vw[4]{};
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].xr; }, xr);
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].v; }, v);
        gather_lanes([&](int l) -> const Quad& { return kin[s[l]].w; }, om);
        gather_lanes([&](int l) -> const Quad& { return rec_[w[l]].p; }, pt);
        gather_lanes([&](int l) -> const Quad& { return rec_[w[l]].n; }, nrm);
        gather_lanes([&](int l) -> const Quad& { return rec_[w[l]].v; }, vw);
        ContactForce<Lanes> c;
        auto vec = [](const Lanes* q) { return Vec3<Lanes>{q[0], q[1], q[2]}; };
        const auto touch = wall_contact_lanes<FullModel>(vec(xr), vec(v), vec(om), xr[3], v[3], vec(pt), vec(nrm), vec(vw), params,
                                                         Coefficients<Lanes>{}, c);
        const Lanes zero{};
        const Lanes gf[4] = {c.f_i.x, c.f_i.y, c.f_i.z, zero}, gt[4] = {c.t_i.x, c.t_i.y, c.t_i.z, zero};
        Quad f[kLanes], tq[kLanes];
        lanes_to_rows<Lanes>(gf, f);
        lanes_to_rows<Lanes>(gt, tq);
        int found = 0;
        for (int l = 0; l < count; ++l) {
            out[l].f = f[l];
            out[l].t = tq[l];
            found += int(touch[l] != 0);
        }
        return found;
    }

    std::vector<Wall> walls_;
    double dt_ = 0.0;
    std::vector<Record> rec_;                        // (walls)
    std::vector<std::uint8_t> near_;                 // (N) the walls each particle may touch this step, a bit each
    std::vector<Index> first_;                       // (N) where a particle marked near a wall has its first candidate
    std::vector<std::vector<Candidate>> cand_;       // per listing thread: the pairs that may touch
    std::vector<std::vector<Load>> res_;             // per listing thread: their force and torque (zeros: no contact)
    std::size_t lists_ = 0;                          // the team that listed them
    std::vector<std::size_t> range_end_;             // where each of its ranges ends
};

} // namespace demmat::fast
