#pragma once
// The fast variant for one model M (model.hpp): data-oriented, vectorised, OpenMP multi-threaded, and
// still bit-identical to arrays for any number of threads (docs/variants/fast.md). This file is the
// Variant: it owns the parts and runs the phases; each part is a header of its own.
//
// - particles.hpp: the state in storage (cell) order, a structure of arrays, and predict()'s one pass
//   between two force passes (the corrector of one step fused with the predictor of the next, the
//   displacement check, the kernels' records).
// - cell_order.hpp, neighbour_list.hpp: the cell sort at each rebuild and the list with a skin, rebuilt
//   only when the displacement check says it must be (a superset of the contact set: the shared law
//   alone decides h > 0, so the contacts are those of a search every step).
// - wall_contacts.hpp: the walls each particle may touch, listed per thread, and their law on lanes.
// - quads.hpp, pair_kernel.hpp: the pair law on lanes, the records moved by transposes of whole vectors.
// - pair_stretches.hpp: under a law with memory (physics.md §9), the pairs' stretches in their slots,
//   carried across rebuilds by pair of ids (the walls' beside their candidates, wall_contacts.hpp).
// - canonical_sums.hpp, canonical_sweep.hpp: each particle's sum in the canonical order of physics.md
//   §6, in one sweep with the kernel shared among the threads (team.hpp); no sum depends on which thread
//   did what, so the bits do not depend on the thread count.
// - unordered_forces.hpp: fast_unordered (FastOptions::canonical = false), plain accumulation.
// Instantiated for the models fast.cpp's dispatch names (fast_models.hpp), each in the file of its kind.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/soa/canonical_sums.hpp"
#include "demmat/soa/canonical_sweep.hpp"
#include "demmat/soa/cell_order.hpp"
#include "demmat/soa/neighbour_list.hpp"
#include "demmat/soa/pair_stretches.hpp"
#include "demmat/soa/particles.hpp"
#include "demmat/soa/team.hpp"
#include "demmat/soa/wall_contacts.hpp"
#include "fast.hpp"
#include "unordered_forces.hpp"

namespace demmat::fast {

template <class M>
class Fast final : public FastVariant {
    static constexpr bool kLaw = M::restitution_damping || M::history || M::rolling;
    static constexpr bool kMemory = stretch_quads<M> > 0;

public:
    explicit Fast(const FastOptions& o) : opt_(o) {}

    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        step_ = s.step;
        law_.params = setup.contact;
        law_.memory = setup.memory;
        if (s.size() > 0) {  // a monodisperse model's coefficients, from particle 0 as arrays takes them
            const Coefficients<double> pp = pair_coefficients(s.radius[0], s.radius[0], setup.mass[0], setup.mass[0], setup.contact);
            const Coefficients<double> pw = wall_coefficients(s.radius[0], setup.mass[0], setup.contact);
            law_.mono_pp = {splat<Lanes>(pp.kn), splat<Lanes>(pp.cn), splat<Lanes>(pp.ct)};
            law_.mono_pw = {splat<Lanes>(pw.kn), splat<Lanes>(pw.cn), splat<Lanes>(pw.ct)};
        }
        p_.init(setup);
        walls_.init(s.walls, setup.scene->dt, p_.n, std::size_t(stretch_quads<M>));
        // Below min_parallel one thread: a fork and join per phase would cost more than the work shared.
        par_ = p_.n >= opt_.min_parallel;
        prefetch_ = p_.n >= opt_.prefetch_from;
        stream_ = p_.n >= opt_.stream_records_from;
        skin_ = opt_.skin * setup.radius_max;
        // Cells at least as wide as the longest listed pair; a wider scene cell is honoured (it only
        // changes the candidates, never the contact set).
        cell_ = std::max(setup.cell_size, 2.0 * setup.radius_max) + skin_;
        walls_.place(step_);
        list_.start.assign(p_.n + 1, 0);
        rebuilds_ = 0;
        team_ = 0;
        pp_ = pw_ = 0;
        if constexpr (kMemory) {
            // The state's stretches stand for the last force pass until there is one: the rebuilds
            // before it take the pairs' from them, and the first listing the walls'.
            stretches_.init(M::history, M::rolling);
            stretches_.load(s.stretches, p_.n);
            loaded_ = s.stretches;
            fresh_ = true;
        }
        rebuild();
        if constexpr (kMemory) walls_.load_stretches(s.stretches, p_.pos, M::history, M::rolling);
    }

    // One pass over the particles between two force passes, timed as the predictor: everything that
    // streams the per-particle arrays, done a block at a time while the block is in cache, instead of a
    // pass each (particles.hpp). The driver finds correct() empty and search() a rebuild or nothing.
    void predict(std::int64_t step) override
    {
        step_ = step;
        walls_.place(step);
        const bool fused = p_.corrector_pending;
        p_.corrector_pending = false;
        walls_.begin_listing();
        // Rebuild when a pair may have closed by more than the skin since the last rebuild:
        // |Δx_i| + |Δx_j| ≤ 2·max|Δx|. 0.9 leaves room for rounding; a NaN fails the test and goes to
        // the rebuild, whose cell search reports it. (Walls need no list: see wall_contacts.hpp.)
        const double half = 0.9 * skin_ * 0.5;
        std::atomic<int> over{!(half > 0.0)};
        std::size_t listing_team = 1;
        const std::size_t n = p_.n;
        in_team(par_, [&] {
            const auto [lo, hi] = thread_range(n);
            const std::size_t t = std::size_t(thread_index());
            if (t == 0) listing_team = std::size_t(thread_count());
            walls_.clear_list(t);
            int mine = 0;
            for (std::size_t b0 = lo; b0 < hi; b0 += Particles::kPassBlock) {
                const std::size_t b1 = std::min(hi, b0 + Particles::kPassBlock);
                mine |= p_.template integrate<M::rotation>(b0, b1, fused, half * half);
                if (stream_) p_.template refresh_records<true>(b0, b1);
                else p_.refresh_records(b0, b1);
                if constexpr (M::walls) walls_.list(p_, b0, b1, t);
            }
            if (stream_) p_.records_fence();  // before the team's barrier, after which others read them
            walls_.size_results(t);
            if (mine) over.store(1, std::memory_order_relaxed);
        });
        walls_.listed_by(listing_team, n);
        rebuild_due_ = over.load(std::memory_order_relaxed) != 0;
    }

    void search() override
    {
        if (rebuild_due_) rebuild();
    }

    void forces() override
    {
        if (opt_.canonical) {
            const auto c = sweep_.template run<M>(list_, sums_, walls_, p_, law_, stretches_.slots.data(), prefetch_, par_);
            pp_ = c.pairs;
            pw_ = c.walls;
            team_ = c.team;
        } else if constexpr (!kLaw) {
            const auto c = unordered_.template run<M>(list_, walls_, p_, law_, prefetch_, par_);
            pp_ = c.pairs;
            pw_ = c.walls;
            team_ = c.team;
        } else {
            throw Error("fast_unordered does not run the contact laws of physics.md §9");  // refused by supports() before
        }
        if (fresh_) {
            fresh_ = false;
            if constexpr (kMemory) {
                stretches_.release_carry();
                std::vector<ContactStretch>().swap(loaded_);
            }
        }
    }

    // Deferred to the next predict() (fused with its predictor), or applied by snapshot() and save() to
    // what they read.
    void correct() override { p_.corrector_pending = true; }

    void snapshot(Snapshot& out) const override
    {
        const std::size_t n = p_.n;
        out.resize(n);
        out.step = step_;
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t s = std::size_t(p_.pos[i]);
            const std::array<Vec3d, 6> trans = p_.gear_state(false, s);
            out.position[i] = trans[0];
            out.velocity[i] = trans[1];
            out.angular_velocity[i] = p_.gear_state(true, s)[1];
            out.force[i] = p_.get(p_.f, s);
            out.torque[i] = p_.get(p_.t, s);
        }
    }

    void save(State& out) const override
    {
        const std::size_t n = p_.n;
        out.resize(n);
        out.step = step_;
        out.walls = walls_.walls();
        std::vector<Vec3d>* dst[2][6] = {{&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5},
                                         {&out.rot.x, &out.rot.v, &out.rot.a, &out.rot.b3, &out.rot.b4, &out.rot.b5}};
        for (int rot = 0; rot < 2; ++rot)
            for (std::size_t i = 0; i < n; ++i) {
                const std::array<Vec3d, 6> g = p_.gear_state(rot == 1, std::size_t(p_.pos[i]));
                for (int k = 0; k < 6; ++k) (*dst[rot][k])[i] = g[std::size_t(k)];
            }
        for (std::size_t i = 0; i < n; ++i) out.radius[i] = p_.r[std::size_t(p_.pos[i])];
        out.stretches.clear();
        if constexpr (kMemory) {
            if (fresh_) {
                out.stretches = loaded_;  // no force pass yet: the contacts of the state it started from
            } else {
                stretches_.save(list_, p_, out.stretches);
                walls_.save_stretches(p_, M::history, M::rolling, out.stretches);
                std::sort(out.stretches.begin(), out.stretches.end());  // the canonical order
            }
        }
    }

    ContactCounts counts() const override { return {pp_, pw_, std::int64_t(list_.pairs())}; }
    std::int64_t rebuilds() const override { return rebuilds_; }
    // The team of the last force pass; before one, the team it will get (one below min_parallel).
    int threads_used() const override { return team_ > 0 ? int(team_) : par_ ? thread_limit() : 1; }

    std::size_t memory_bytes() const override
    {
        return p_.bytes() + cells_.bytes() + list_.bytes() + walls_.bytes() + sums_.bytes() + sweep_.bytes() + unordered_.bytes() +
               stretches_.bytes() + loaded_.capacity() * sizeof(ContactStretch);
    }

private:
    // Re-sorts the particles into cell order, lists the pairs (and plans the canonical sums), carries
    // the pairs' stretches to their new slots, and makes the new storage order's records and wall
    // candidates (predict() made them for the old one).
    void rebuild()
    {
        ++rebuilds_;
        const std::size_t n = p_.n;
        if (n == 0) return;
        if constexpr (kMemory)
            if (!fresh_) stretches_.collect(list_, p_.id, n);  // by ids, before the slots change
        cells_.sort(p_.x, p_.id, n, cell_);
        p_.permute([this](std::size_t s) { return std::size_t(cells_.key(s).from); }, [this](std::size_t s) { return cells_.key(s).id; },
                   par_);
        list_.build(p_, cells_, skin_, opt_.canonical, par_);
        if (opt_.canonical) sums_.plan(list_, n, par_);
        if constexpr (kMemory) {
            stretches_.apply(list_, p_.id, n, par_);
            if (!fresh_) stretches_.release_carry();  // while fresh, the next rebuild reads the state's again
        }
        p_.xref = p_.x;
        walls_.begin_listing();
        std::size_t listing_team = 1;
        in_team(par_, [&] {
            const auto [lo, hi] = thread_range(n);
            const std::size_t t = std::size_t(thread_index());
            if (t == 0) listing_team = std::size_t(thread_count());
            p_.refresh_records(lo, hi);
            walls_.clear_list(t);
            if constexpr (M::walls) walls_.list(p_, lo, hi, t, [this](std::size_t s) { return std::size_t(cells_.key(s).from); });
            walls_.size_results(t);
        });
        walls_.listed_by(listing_team, n);
    }

    FastOptions opt_;
    bool par_ = true, prefetch_ = false, stream_ = false;
    bool rebuild_due_ = false;  // the displacement check of the last predict() asks for a rebuild
    std::int64_t step_ = 0, rebuilds_ = 0;
    double skin_ = 0.0, cell_ = 0.0;
    LawInputs law_;
    Particles p_;
    CellOrder cells_;
    NeighbourList list_;
    WallContacts walls_;
    CanonicalSums sums_;
    CanonicalSweep sweep_;
    UnorderedForces unordered_;
    PairStretches stretches_;              // a law with memory: the pairs' stretches in their slots
    std::vector<ContactStretch> loaded_;   // the state's stretches, saved as they are until the first force pass
    bool fresh_ = false;                   // no force pass since init (the stretches are the state's)
    std::int64_t pp_ = 0, pw_ = 0;
    std::size_t team_ = 0;  // the threads of the last force pass (0: none yet)
};

} // namespace demmat::fast
