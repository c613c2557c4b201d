#pragma once
// The fast variant's walls: no list. In predict()'s pass each particle gets a bit per wall it may touch
// (a scene has a handful of walls: testing each every step costs less than a wall list, and keeps the
// moving wall out of the rebuild criterion), the particle–wall pairs are listed from the bits per
// thread, in particle order, walls in wall order, and the force pass computes them a pack at a time on
// the lanes: fast_unordered shares the packs out among all threads (a wall's grains may all be in one
// thread's range); the canonical sweep computes each chunk's with the chunk (canonical_sweep.hpp).
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

// What the law needs besides the particles: the scene's parameters, the one radius's coefficients of a
// monodisperse model (pair and wall), the §9 constants. (The wall kernel here and the pair kernel.)
struct LawInputs {
    ContactParams<double> params;
    Coefficients<Lanes> mono_pp, mono_pw;  // read only by a model with !polydisperse
    MemoryParams<double> memory;           // read only by a §9 law
};

class WallContacts {
public:
    // q: the quads of a contact's stretches (stretch_quads), 0 without memory.
    void init(const std::vector<Wall>& walls, double dt, std::size_t n, std::size_t q = 0)
    {
        q_ = q;
        cur_ = 0;
        now_ = &buf_[0];
        walls_ = walls;
        dt_ = dt;
        rec_.assign(walls_.size(), Record{});
        for (std::size_t w = 0; w < walls_.size(); ++w)
            for (int c = 0; c < 3; ++c) {
                rec_[w].n[c] = component(walls_[w].normal, c);
                rec_[w].v[c] = component(walls_[w].velocity, c);
            }
        for (Listing& l : buf_) {
            l.near.assign(n, 0);
            l.first.assign(n, 0);
            l.lists = 0;
            l.range_end.clear();
            for (std::size_t u = 0; u < l.cand.size(); ++u) l.cand[u].clear();
        }
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

    // A new listing (before a parallel region that lists): the last one kept to carry stretches from
    // (under a law with memory), room for every thread's list.
    void begin_listing()
    {
        if (q_ > 0) cur_ ^= 1;
        now_ = &buf_[cur_];
        Listing& l = *now_;
        const std::size_t limit = std::size_t(thread_limit());
        if (l.cand.size() < limit) {
            l.cand.resize(limit);
            l.res.resize(limit);
            l.st.resize(limit);
        }
    }

    // Thread t's list, for [lo, hi), its range of the particles: the bits of the walls each may touch
    // (may_touch_wall, vectorised over a chunk of particles, every wall over the chunk, so that the
    // chunk's positions are read once), then its pairs in particle order, walls in wall order. Beyond
    // kWallBits walls one bit stands for any, and each wall is tested again for the particles marked.
    // With a law with memory, old_slot(s) is particle s's slot in the listing before.
    void clear_list(std::size_t t)
    {
        now_->cand[t].clear();
        now_->st[t].clear();
    }
    void list(const Particles& p, std::size_t lo, std::size_t hi, std::size_t t) { list(p, lo, hi, t, [](std::size_t s) { return s; }); }
    template <class OldSlot>
    void list(const Particles& p, std::size_t lo, std::size_t hi, std::size_t t, OldSlot&& old_slot)
    {
        Listing& l = *now_;
        mark(p, lo, hi);
        std::vector<Candidate>& cand = l.cand[t];
        const std::size_t before = cand.size();  // a thread lists its range a block at a time
        const std::uint8_t* near = l.near.data();
        const std::size_t nw = walls_.size();
        for (std::size_t s = lo; s < hi; ++s) {
            if (!near[s]) continue;
            l.first[s] = Index(cand.size());
            if (nw <= kWallBits) {  // the walls are the bits, ascending
                for (unsigned m = near[s]; m != 0; m &= m - 1) cand.push_back({Index(s), Index(__builtin_ctz(m))});
            } else {
                const Quad& xr = p.kin[s].xr;
                for (std::size_t w = 0; w < nw; ++w)
                    if (may_touch_wall(Vec3d{xr[0], xr[1], xr[2]}, xr[3], point(w), normal(w))) cand.push_back({Index(s), Index(w)});
            }
        }
        if (q_ == 0) return;
        std::vector<Quad>& st = l.st[t];
        st.resize(cand.size() * q_, Quad{});
        for (std::size_t e = before; e < cand.size(); ++e) carry(old_slot(std::size_t(cand[e].s)), std::size_t(cand[e].w), st.data() + e * q_);
    }
    void size_results(std::size_t t) { now_->res[t].resize(now_->cand[t].size()); }

    // The lists were made by a team of `team` threads, each its range of the particles (thread_range),
    // into lists 0 … team: the force pass, whatever its own team (OpenMP's dynamic teams may give it
    // another), reads those lists and finds a particle's by these ranges.
    void listed_by(std::size_t team, std::size_t n)
    {
        Listing& l = *now_;
        l.lists = team;
        l.range_end.resize(team);
        for (std::size_t u = 0; u < team; ++u) l.range_end[u] = range_end(n, u, team);
    }

    // The law on every list's candidates, kLanes pairs at a time, the packs shared out among the team
    // (zeros where h <= 0); no barrier at the end. Inside a parallel region. Returns the contacts found.
    template <class M>
    [[gnu::always_inline]] std::int64_t compute(const Particles& p, const LawInputs& law)
    {
        Listing& l = *now_;
        auto packs_of = [&l](std::size_t u) { return (l.cand[u].size() + kLanes - 1) / kLanes; };
        std::size_t packs = 0;
        for (std::size_t u = 0; u < l.lists; ++u) packs += packs_of(u);
        std::int64_t found = 0;
#pragma omp for schedule(static) nowait
        for (std::size_t k = 0; k < packs; ++k) {
            std::size_t u = 0, first = 0;  // the list that pack k falls in, and its first pack
            while (k >= first + packs_of(u)) first += packs_of(u++);
            const std::size_t e = (k - first) * kLanes, count = std::min<std::size_t>(kLanes, l.cand[u].size() - e);
            Quad* st = q_ > 0 ? l.st[u].data() + e * q_ : nullptr;
            found += pack<M>(p, law, l.cand[u].data() + e, int(count), l.res[u].data() + e, st);
        }
        return found;
    }

    // The law on the candidates of particles [s0, s1) only, kLanes at a time, by the calling thread
    // (a range's candidates lie together in each list, found by a binary search). Returns the contacts
    // found.
    template <class M>
    [[gnu::always_inline]] std::int64_t compute_range(const Particles& p, const LawInputs& law, std::size_t s0, std::size_t s1)
    {
        Listing& l = *now_;
        std::int64_t found = 0;
        for (std::size_t u = 0, lo = 0; u < l.lists && lo < s1; lo = l.range_end[u++]) {
            const std::size_t a = std::max(s0, lo), b = std::min(s1, l.range_end[u]);
            if (a >= b) continue;
            const std::vector<Candidate>& cand = l.cand[u];
            auto below = [](const Candidate& c, std::size_t s) { return std::size_t(c.s) < s; };
            const std::size_t e0 = std::size_t(std::lower_bound(cand.begin(), cand.end(), a, below) - cand.begin());
            const std::size_t e1 = std::size_t(std::lower_bound(cand.begin() + std::ptrdiff_t(e0), cand.end(), b, below) - cand.begin());
            for (std::size_t e = e0; e < e1; e += kLanes) {
                Quad* st = q_ > 0 ? l.st[u].data() + e * q_ : nullptr;
                found += pack<M>(p, law, cand.data() + e, int(std::min<std::size_t>(kLanes, e1 - e)), l.res[u].data() + e, st);
            }
        }
        return found;
    }

    // Particle s's walls added to its sum (f, tq), in wall order (zeros for a pair out of contact add
    // nothing).
    void add(std::size_t s, Quad& f, Quad& tq) const
    {
        const Listing& l = *now_;
        if (!l.near[s]) return;
        std::size_t u = 0;  // the list that holds s (a loop, not a division: cheaper)
        while (s >= l.range_end[u]) ++u;
        const std::vector<Candidate>& cand = l.cand[u];
        const Load* res = l.res[u].data();
        for (std::size_t e = std::size_t(l.first[s]); e < cand.size() && std::size_t(cand[e].s) == s; ++e) {
            f += res[e].f;
            tq += res[e].t;
        }
    }

    // A state's wall contacts (particle id, wall index) as the listing the next one carries from, in
    // the storage order `pos` (pos[id] is the slot), for a run that starts from that state.
    void load_stretches(const std::vector<ContactStretch>& in, const std::vector<Index>& pos, bool history, bool rolling)
    {
        if (q_ == 0) return;
        Listing& l = *now_;
        std::fill(l.near.begin(), l.near.end(), std::uint8_t(0));
        std::vector<std::pair<Candidate, const ContactStretch*>> got;
        for (const ContactStretch& c : in)
            if (c.wall) got.push_back({{pos[std::size_t(c.i)], Index(c.partner)}, &c});
        std::sort(got.begin(), got.end(), [](const auto& a, const auto& b) { return a.first.s != b.first.s ? a.first.s < b.first.s : a.first.w < b.first.w; });
        l.cand.resize(std::max<std::size_t>(l.cand.size(), 1));
        l.res.resize(l.cand.size());
        l.st.resize(l.cand.size());
        l.cand[0].clear();
        l.st[0].assign(got.size() * q_, Quad{});
        for (const auto& [c, from] : got) {
            const std::size_t s = std::size_t(c.s);
            if (!l.near[s]) l.first[s] = Index(l.cand[0].size());
            l.near[s] |= std::uint8_t(walls_.size() <= kWallBits ? 1u << c.w : 1u);
            stretch_to_record(*from, history, rolling, l.st[0].data() + l.cand[0].size() * q_);
            l.cand[0].push_back(c);
        }
        l.res[0].resize(l.cand[0].size());
        l.lists = 1;
        l.range_end.assign(1, pos.size());
    }

    // The live wall contacts of the last force pass (h > 0 at the positions it read), as a state holds them.
    void save_stretches(const Particles& p, bool history, bool rolling, std::vector<ContactStretch>& out) const
    {
        const Listing& l = *now_;
        for (std::size_t u = 0; u < l.lists; ++u)
            for (std::size_t e = 0; e < l.cand[u].size(); ++e) {
                const Candidate& c = l.cand[u][e];
                const Quad& xr = p.kin[std::size_t(c.s)].xr;
                const double h = xr[3] - dot(Vec3d{xr[0], xr[1], xr[2]} - point(std::size_t(c.w)), normal(std::size_t(c.w)));
                if (!(h > 0.0)) continue;
                ContactStretch cs;
                cs.i = p.id[std::size_t(c.s)];
                cs.partner = c.w;
                cs.wall = true;
                record_to_stretch(l.st[u].data() + e * q_, history, rolling, cs);
                out.push_back(cs);
            }
    }

    std::size_t bytes() const
    {
        std::size_t b = heap_bytes(walls_, rec_);
        for (const Listing& l : buf_) b += heap_bytes(l.near, l.first, l.cand, l.res, l.st, l.range_end);
        return b;
    }

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
    // One listing: the walls each particle may touch, and the candidates with their results (and
    // stretches) per listing thread.
    struct Listing {
        std::vector<std::uint8_t> near;              // (N) the walls each particle may touch this step, a bit each
        std::vector<Index> first;                    // (N) where a particle marked near a wall has its first candidate
        PerThread<std::vector<Candidate>> cand;      // per listing thread: the pairs that may touch
        PerThread<std::vector<Load>> res;            // per listing thread: their force and torque (zeros: no contact)
        PerThread<std::vector<Quad>> st;             // per listing thread: q_ quads of stretches per candidate
        std::size_t lists = 0;                       // the team that listed them
        std::vector<std::size_t> range_end;          // where each of its ranges ends
    };

    // The stretches the listing before holds for (old slot os, wall w) into out (left zero if none).
    void carry(std::size_t os, std::size_t w, Quad* out) const
    {
        const Listing& o = buf_[cur_ ^ 1];
        if (o.lists == 0 || !o.near[os]) return;
        std::size_t u = 0;
        while (os >= o.range_end[u]) ++u;
        const std::vector<Candidate>& cand = o.cand[u];
        for (std::size_t e = std::size_t(o.first[os]); e < cand.size() && std::size_t(cand[e].s) == os; ++e)
            if (std::size_t(cand[e].w) == w) {
                for (std::size_t q = 0; q < q_; ++q) out[q] = o.st[u][e * q_ + q];
                return;
            }
    }

    Vec3d point(std::size_t w) const { return {rec_[w].p[0], rec_[w].p[1], rec_[w].p[2]}; }
    Vec3d normal(std::size_t w) const { return {rec_[w].n[0], rec_[w].n[1], rec_[w].n[2]}; }

    void mark(const Particles& p, std::size_t lo, std::size_t hi)
    {
        const std::size_t n = p.n, nw = walls_.size();
        const double* __restrict x = p.x.data();
        const double* __restrict r = p.r.data();
        std::uint8_t* __restrict near = now_->near.data();
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
    template <class M>
    [[gnu::flatten]] int pack(const Particles& p, const LawInputs& law, const Candidate* cand, int count, Load* out, Quad* stretches) const
    {
        constexpr bool kLaw = M::restitution_damping || M::history || M::rolling;
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
        const auto touch = [&] {
            if constexpr (kLaw) {
                Stretch<Lanes> st;
                std::size_t k[kLanes];
                for (int l = 0; l < kLanes; ++l) k[l] = std::size_t(l < count ? l : count - 1);
                if constexpr (stretch_quads<M> > 0) lanes_from_records<M>(stretches, k, st);
                const auto t = wall_contact_memory_lanes<M>(vec(xr), vec(v), vec(om), xr[3], v[3], vec(pt), vec(nrm), vec(vw), law.params,
                                                            law.memory, st, true, c);
                if constexpr (stretch_quads<M> > 0) lanes_to_records<M>(stretches, k, count, t, st);
                return t;
            } else {
                return wall_contact_lanes<M>(vec(xr), vec(v), vec(om), xr[3], v[3], vec(pt), vec(nrm), vec(vw), law.params, law.mono_pw, c);
            }
        }();
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
    std::vector<Record> rec_;  // (walls)
    std::size_t q_ = 0;        // quads of stretches per candidate (a law with memory), else 0
    // The listing of this step, buf_[cur_] (now_), and the one before (kept under a law with memory only).
    Listing buf_[2];
    int cur_ = 0;
    Listing* now_ = &buf_[0];  // buf_[cur_]
};

} // namespace demmat::fast
