#pragma once
// The phases on one rank (docs/variants/mpi.md), for model M (model.hpp), gear5 in double:
//
//   predict  the pending corrector and the Gear predictor on the owned particles in one pass, and the
//            displacement check (rank_gear.hpp); moving walls placed from the step number (every rank
//            computes the same wall positions, nothing is sent for them)
//   search   a neighbour list with a skin, as fast keeps one: rebuilt when some particle on some rank
//            has moved more than 0.45 skin since the last rebuild (one allreduce of a flag per step).
//            At a rebuild, communicate (rank_halo.hpp): owned particles that left the brick migrate to
//            the rank that owns them now (with their whole Gear history), the owned particles are sorted
//            into cell order, then the ranks exchange ghost copies of the particles within the interaction
//            range plus the skin of each shared face, an axis at a time, and remember whom they sent; the
//            cell search over owned and ghosts lists every pair with an owned particle closer than
//            R_i + R_j + skin (rank_list.hpp). Between rebuilds, communicate only refreshes the ghosts
//            (position, velocity, angular velocity of the same particles, in the same order). A particle
//            moves less than half the skin between rebuilds, so the list holds every contact (the law
//            decides)
//   forces   each pair's force once per rank, by the shared law with the lower id as i: by the
//            shared pair kernel on lanes (rank_pair_kernel.hpp, fast's kernel, the laws of physics.md §9
//            with their stretches included), a block of owned particles' pairs into a ring of slots
//            and then the block's sums, four at a time (rank_sum_table.hpp). Each owned
//            particle's sum in the canonical order (partners ascending by id, then walls in order).
//            The owned particles are in cell order from each rebuild (sort_owned), for locality
//   correct  marks the Gear corrector pending: the next predict's pass applies it, snapshot and save
//            apply it to what they gather
//
// A pair that straddles a face is computed by both ranks from the same inputs (the same bits); no force
// is sent back. So every owned particle receives exactly the terms arrays gives it, in arrays' order.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "comm.hpp"
#include "mpi_variant.hpp"
#include "rank_gear.hpp"
#include "rank_list.hpp"
#include "rank_pair_kernel.hpp"
#include "rank_walls.hpp"
#include "rank_particles.hpp"
#include "rank_stretches.hpp"
#include "rank_sum_table.hpp"
#include "bricks.hpp"
#include "rank_halo.hpp"
#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/error.hpp"
#include "demmat/integrators.hpp"
#include "demmat/soa/cell_order.hpp"

namespace demmat::mpi {

// What rank 0 decides at init and every rank receives: the model, the bricks, the lengths.
struct Plan {
    ModelFeatures features;
    Bricks bricks;
    double radius_max = 0.0;
    double cell = 0.0;   // edge of the search's cells
    double skin = 0.0;   // the neighbour list's skin
    double halo = 0.0;   // ghosts: particles within this distance of a shared face (contact range + skin)
    double r0 = 0.0, m0 = 0.0;  // particle 0's radius and mass (a monodisperse model's coefficients)
};

template <class M>
class RankProcessor final : public MpiVariant {
public:
    RankProcessor(const Comm& comm, const Plan& plan) : comm_(comm), plan_(plan), halo_(comm, plan.bricks, plan.halo) {}

    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        step_ = s.step;
        dt_ = setup.scene->dt;
        coef_ = GearCoefficients<double>::make(dt_);
        params_ = setup.contact;
        memory_ = setup.memory;
        g_ = setup.scene->gravity;
        walls_ = s.walls;
        wp_.resize(walls_.size());
        place_walls(step_);
        if constexpr (!M::polydisperse) {
            mono_pp_ = pair_coefficients(plan_.r0, plan_.r0, plan_.m0, plan_.m0, params_);
            mono_pw_ = wall_coefficients(plan_.r0, plan_.m0, params_);
        }
        kernel_.init(params_, mono_pp_, memory_);
        // Rank 0 holds the whole state: each rank receives its brick's particles as migrants.
        std::vector<std::vector<double>> parts;
        if (comm_.root()) {
            parts.resize(std::size_t(comm_.size()));
            const std::vector<Vec3d>* g[12] = {&s.trans.x, &s.trans.v, &s.trans.a, &s.trans.b3, &s.trans.b4, &s.trans.b5,
                                               &s.rot.x,   &s.rot.v,   &s.rot.a,   &s.rot.b3,   &s.rot.b4,   &s.rot.b5};
            for (std::size_t i = 0; i < s.size(); ++i) {
                std::vector<double>& out = parts[std::size_t(plan_.bricks.owner(s.trans.x[i]))];
                out.push_back(id_to_double(std::int64_t(i)));
                out.push_back(s.radius[i]);
                out.push_back(setup.mass[i]);
                out.push_back(setup.inertia[i]);
                for (const auto* q : g)
                    for (int c = 0; c < 3; ++c) out.push_back(component((*q)[i], c));
            }
        }
        p_ = RankParticles{};
        p_.add_migrants(comm_.scatter(parts));
        for (std::size_t l = 0; l < p_.owned(); ++l) p_.f[l] = p_.t[l] = Vec3d{};
        if constexpr (M::memory) st_.load(comm_, plan_.bricks, s, walls_.size(), p_);
        owned_max_ = std::int64_t(p_.owned());
        steps_ = 0;
        migrants_ = 0;
        rebuilds_ = 0;
        built_ = false;
        corrector_pending_ = false;
    }

    // The pending corrector of the last step fused with this step's predictor, and the displacement
    // check (rank_gear.hpp).
    void predict(std::int64_t step) override
    {
        step_ = step;
        const double limit = 0.45 * plan_.skin;
        moved_far_ = gear_pass<M::rotation>(p_, coef_, corrector_pending_, built_ ? x_built_.data() : nullptr, limit * limit);
        corrector_pending_ = false;
        if constexpr (M::moving_walls) place_walls(step);
    }

    void search() override
    {
        if (!built_ || must_rebuild()) {
            migrate();
            sort_owned();
            halo_.exchange_ghosts(comm_, p_);
            find_pairs();
            if constexpr (M::memory) st_.pending.clear();
            x_built_.assign(p_.x.begin(), p_.x.begin() + std::ptrdiff_t(p_.owned()));
            built_ = true;
            ++rebuilds_;
        } else {
            halo_.refresh_ghosts(comm_, p_);
        }
        if constexpr (M::walls) find_walls();  // every step, without a skin: a wall may move
        ++steps_;
        owned_max_ = std::max(owned_max_, std::int64_t(p_.owned()));
    }

    void forces() override
    {
        pw_ = 0;
        const std::size_t no = p_.owned();
        // The pairs whose lower id is a ghost's first (few, at the faces), then block by block the pairs
        // found at a block's particles and the block's sums, while its slots are in cache.
        kernel_.refresh_records(p_);
        kernel_.run_ghost_pairs();
        pp_ = 0;
        for (std::size_t a = 0; a < no; a += kSumBlock) {
            const std::size_t b = std::min(no, a + kSumBlock);
            pp_ += kernel_.run(list_.found_at[a], list_.found_at[b]);
            sum_owned(a, b);
        }
        candidates_ = std::int64_t(list_.counted);
    }

    // Owned particles [a, b): each one's sum in the canonical order (its pairs as j, as i, then its
    // walls), its loads and accelerations.
    void sum_owned(std::size_t a, std::size_t b)
    {
        const std::size_t words = wall_words(walls_.size());
        for (std::size_t l0 = a; l0 < b; l0 += kSumGroup) {
            const std::size_t n = std::min(kSumGroup, b - l0);
            Vec3d fs[kSumGroup]{}, ts[kSumGroup]{};
            slot_sums(l0, fs, ts);
            for (std::size_t g = 0; g < n; ++g) {
                const std::size_t l = l0 + g;
                Vec3d f = fs[g], t = ts[g];
            if constexpr (M::walls && !M::memory) {
                // Without stretches to forget, a wall that is not a candidate adds nothing: the candidates
                // alone, in wall order.
                for (std::size_t q = 0; q < words; ++q)
                    for (std::uint64_t bits = near_[l * words + q]; bits != 0; bits &= bits - 1) {
                        const std::size_t w = 64 * q + std::size_t(std::countr_zero(bits));
                        ContactForce<double> c;
                        Stretch<double> none{};  // restitution damping alone: no stretch to carry
                        bool live;
                        if constexpr (law)
                            live = wall_contact_memory<M>(p_.x[l], p_.v[l], p_.w[l], p_.r[l], p_.m[l], wp_[w], walls_[w].normal,
                                                          walls_[w].velocity, params_, memory_, none, true, c);
                        else
                            live = wall_contact<M>(p_.x[l], p_.v[l], p_.w[l], p_.r[l], p_.m[l], wp_[w], walls_[w].normal, walls_[w].velocity,
                                                   params_, mono_pw_, c);
                        if (!live) continue;
                        ++pw_;
                        f = f + c.f_i;
                        if constexpr (M::rotation) t = t + c.t_i;
                    }
            } else if constexpr (M::walls) {
                for (std::size_t w = 0; w < walls_.size(); ++w) {  // in wall order
                    const bool candidate = (near_[l * words + w / 64] >> (w % 64)) & 1u;
                    Stretch<double> none{};
                    Stretch<double>& s = M::memory ? st_.wall_row(l)[w] : none;
                    bool live = false;
                    ContactForce<double> c;
                    if (candidate) {
                        if constexpr (law)
                            live = wall_contact_memory<M>(p_.x[l], p_.v[l], p_.w[l], p_.r[l], p_.m[l], wp_[w], walls_[w].normal,
                                                          walls_[w].velocity, params_, memory_, s, true, c);
                        else
                            live = wall_contact<M>(p_.x[l], p_.v[l], p_.w[l], p_.r[l], p_.m[l], wp_[w], walls_[w].normal,
                                                   walls_[w].velocity, params_, mono_pw_, c);
                    }
                    if constexpr (M::memory) {
                        if (!live) s = Stretch<double>{};  // a contact no longer touching is forgotten
                        st_.wall_live[l * walls_.size() + w] = live;
                    }
                    if (!live) continue;
                    ++pw_;
                    f = f + c.f_i;
                    if constexpr (M::rotation) t = t + c.t_i;
                }
            }
            p_.f[l] = f;
            p_.t[l] = t;
            p_.acc[l] = {acceleration(f.x, p_.m[l], g_.x), acceleration(f.y, p_.m[l], g_.y), acceleration(f.z, p_.m[l], g_.z)};
            if constexpr (M::rotation) p_.alc[l] = t / p_.inertia[l];
            }
        }
    }

    // The pair terms of the sums of the group of owned particles from l0 (rank_sum_table.hpp): every
    // listed pair's slot counts, zeros out of contact, which add nothing, as the table's padding.
    void slot_sums(std::size_t l0, Vec3d* f, Vec3d* t) const
    {
        const RankSumTable::Group& grp = sums_.group(l0 / kSumGroup);
        const std::int32_t* at = sums_.table(grp);
        const fast::SlotStore& slot = kernel_.slots();
        for (std::size_t e = 0; e < grp.as_j; ++e, at += kSumGroup)
            for (std::size_t g = 0; g < kSumGroup; ++g) {
                const fast::Slot& c = slot.line[std::size_t(at[g])];
                f[g] = f[g] + (-c.f());
                if constexpr (M::rotation) t[g] = t[g] + c.tj();
            }
        for (std::size_t e = 0; e < grp.as_i; ++e, at += kSumGroup)
            for (std::size_t g = 0; g < kSumGroup; ++g) {
                const fast::Slot& c = slot.line[std::size_t(at[g])];
                f[g] = f[g] + c.f();
                if constexpr (M::rotation) t[g] = t[g] + slot.ti(std::size_t(at[g]));
            }
    }

    // Pending until the next predict (its pass applies it) or a snapshot or save (they read `corrected`).
    void correct() override { corrector_pending_ = true; }

    void snapshot(Snapshot& out) const override
    {
        const RankParticles now = corrected<M::rotation>(p_, coef_, corrector_pending_);
        std::vector<double> mine;
        mine.reserve(16 * now.owned());
        for (std::size_t l = 0; l < now.owned(); ++l) {
            mine.push_back(id_to_double(now.id[l]));
            for (const Vec3d* q : {&now.x[l], &now.v[l], &now.w[l], &now.f[l], &now.t[l]})
                for (int c = 0; c < 3; ++c) mine.push_back(component(*q, c));
        }
        const std::vector<double> all = comm_.gather(mine);
        out.step = step_;
        out.resize(all.size() / 16);
        for (std::size_t k = 0; k + 16 <= all.size(); k += 16) {
            const std::size_t i = std::size_t(double_to_id(all[k]));
            const double* q = &all[k + 1];
            Vec3d* dst[5] = {&out.position[i], &out.velocity[i], &out.angular_velocity[i], &out.force[i], &out.torque[i]};
            for (Vec3d* d : dst) {
                *d = {q[0], q[1], q[2]};
                q += 3;
            }
        }
    }

    void save(State& out) const override
    {
        const RankParticles now = corrected<M::rotation>(p_, coef_, corrector_pending_);
        std::vector<double> mine;
        mine.reserve(kMigrantDoubles * now.owned());
        for (std::size_t l = 0; l < now.owned(); ++l) now.pack_migrant(l, mine);
        const std::vector<double> all = comm_.gather(mine);
        out = State{};
        out.step = step_;
        out.walls = walls_;
        out.resize(all.size() / kMigrantDoubles);
        std::vector<Vec3d>* g[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                     &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (std::size_t k = 0; k + kMigrantDoubles <= all.size(); k += kMigrantDoubles) {
            const double* q = &all[k];
            const std::size_t i = std::size_t(double_to_id(q[0]));
            out.radius[i] = q[1];  // as given: a continued run derives the same masses
            q += 4;
            for (auto* d : g) {
                (*d)[i] = {q[0], q[1], q[2]};
                q += 3;
            }
        }
        if constexpr (M::memory) {
            // The pairs that touched at the last force pass, once: where the lower id is owned.
            std::vector<double> pairs;
            for (std::size_t k = 0; k < list_.counted; ++k) {
                const auto [i, j] = list_.pairs[k];
                if (kernel_.touched(std::size_t(i), std::size_t(j)))
                    pack_stretch(pairs, p_.id[std::size_t(i)], p_.id[std::size_t(j)], kernel_.stretch(k));
            }
            st_.save(comm_, pairs, p_, out);
        }
    }

    bool supports(const ContactModel&) const override { return true; }
    ContactCounts counts() const override { return {comm_.sum(pp_), comm_.sum(pw_), comm_.sum(candidates_)}; }
    std::size_t memory_bytes() const override
    {
        return p_.memory_bytes() + st_.memory_bytes() + list_.memory_bytes() + halo_.memory_bytes() + near_.capacity() * sizeof(std::uint64_t) + kernel_.memory_bytes() + sums_.memory_bytes() + order_.bytes() + fast::heap_bytes(order_x_, order_id_, order_from_);
    }
    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

    const Comm& comm() const override { return comm_; }
    double communicate_seconds() const override { return comm_.traffic().seconds; }
    const Bricks& bricks() const override { return plan_.bricks; }
    double halo() const override { return plan_.halo; }
    RankReport local_report() const override
    {
        return {comm_.rank(), std::int64_t(p_.owned()), std::int64_t(p_.size() - p_.owned()), owned_max_, steps_, migrants_, rebuilds_,
                comm_.traffic()};
    }

private:
    using Pair = RankList::Pair;
    static constexpr std::size_t kSumBlock = 256;  // owned particles per block of forces()
    static constexpr std::size_t kSumGroup = RankSumTable::kGroup;  // sums made side by side (slot_sums)

    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < walls_.size(); ++w) wp_[w] = walls_[w].point_at(step, dt_);
    }

    // Owned particles whose predicted position left the brick go to the rank that now owns it
    // (rank_halo.hpp). Under a law with memory every live pair's stretch waits in `pending` by its key,
    // taken while the ghosts' ids are still here; a migrant's pairs go with it.
    void migrate()
    {
        if constexpr (M::memory)
            for (std::size_t k = 0; k < list_.pairs.size(); ++k)
                if (kernel_.carries(k)) st_.pending[{p_.id[std::size_t(list_.pairs[k].i)], p_.id[std::size_t(list_.pairs[k].j)]}] = kernel_.stretch(k);
        p_.drop_ghosts();
        migrants_ += halo_.migrate(comm_, p_, M::memory ? &st_ : nullptr);
    }

    // The owned particles into fast's cell order (soa/cell_order.hpp), so that the list's pairs, the
    // kernel's records and the slots each sum reads lie near one another in memory. The local order
    // changes no bits: every sum is in the order of ids.
    void sort_owned()
    {
        const std::size_t no = p_.owned();
        if (no == 0) return;
        order_x_.resize(3 * no);
        order_id_.resize(no);
        for (std::size_t l = 0; l < no; ++l) {
            for (int c = 0; c < 3; ++c) order_x_[std::size_t(c) * no + l] = component(p_.x[l], c);
            order_id_[l] = fast::Index(p_.id[l]);
        }
        order_.sort(order_x_, order_id_, no, plan_.cell);
        order_from_.resize(no);
        for (std::size_t s = 0; s < no; ++s) order_from_[s] = std::size_t(order_.key(s).from);
        p_.permute_owned(order_from_);
        if constexpr (M::memory) st_.permute_owned(order_from_);
    }

    // Has any particle on any rank moved more than 0.45 skin since the last rebuild (fast's criterion)?
    // Each rank's answer comes from its predict pass.
    bool must_rebuild() { return comm_.any(moved_far_); }

    // The rank's neighbour list (rank_list.hpp), the kernel's slots (each pair with the stretch it
    // carries, by key), and the sums' table.
    void find_pairs()
    {
        list_.build(p_, plan_.cell, plan_.skin, kSumBlock);
        kernel_.set_pairs(list_.pairs, list_.counted, list_.reach, p_, [&](std::int64_t i, std::int64_t j) -> const Stretch<double>* {
            if constexpr (M::memory) {
                const auto it = st_.pending.find({i, j});
                return it == st_.pending.end() ? nullptr : &it->second;
            }
            return nullptr;
        });
        sums_.build(list_, p_.owned(), [&](std::size_t k) { return kernel_.position(k); }, kernel_.zero_position());
    }

    // The walls each owned particle may touch, in wall order.
    void find_walls() { mark_wall_candidates(p_, walls_, wp_, near_); }

    static constexpr bool law = M::restitution_damping || M::history || M::rolling;  // a §9 law, not the paper's

    Comm comm_;
    Plan plan_;
    MemoryParams<double> memory_;
    RankStretches st_;  // a §9 law with memory: the stretches
    std::int64_t step_ = 0, steps_ = 0, owned_max_ = 0, migrants_ = 0, rebuilds_ = 0;
    bool built_ = false;
    bool corrector_pending_ = false;  // correct() was called; the next predict applies it
    bool moved_far_ = false;          // the last predict moved some owned particle 0.45 skin from x_built_
    std::vector<Vec3d> x_built_;                         // owned positions at the last rebuild
    double dt_ = 0.0;
    GearCoefficients<double> coef_;
    ContactParams<double> params_;
    Coefficients<double> mono_pp_, mono_pw_;
    Vec3d g_;
    std::vector<Wall> walls_;
    std::vector<Vec3d> wp_;  // the walls' points at the current step
    RankParticles p_;
    RankHalo halo_;  // the exchanges with the bricks around
    RankList list_;
    std::vector<std::uint64_t> near_;  // find_walls: a bit per wall that each owned particle may touch
    std::int64_t pp_ = 0, pw_ = 0, candidates_ = 0;
    RankPairKernel<M> kernel_;        // the pairs on lanes, and under a law with memory their stretches
    RankSumTable sums_;               // the slots each group of sums reads
    fast::CellOrder order_;           // sort_owned's scratch
    std::vector<double> order_x_;
    std::vector<fast::Index> order_id_;
    std::vector<std::size_t> order_from_;
};

// The instantiations, in two translation units compiled side by side: the paper's law on with_model's
// models (rank_paper.cpp) and the laws of physics.md §9 on the full model (rank_laws.cpp).
std::unique_ptr<MpiVariant> make_rank_processor_paper(const ModelFeatures& need, const Comm& comm, const Plan& plan);
std::unique_ptr<MpiVariant> make_rank_processor_law(const ModelFeatures& need, const Comm& comm, const Plan& plan);

} // namespace demmat::mpi
