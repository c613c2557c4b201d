#pragma once
// A rank's pairs through the shared pair kernel on lanes (demmat/lane_engine/pair_kernel.hpp, the kernel fast
// runs), under the paper's law and the laws of physics.md §9. The rank's particles, owned and ghosts,
// get the kernel's records (one record of three quads per particle, lane_engine/particles.hpp); its listed
// pairs (lower id as i) become the kernel's slots, each contact's force and torques into its slot, zeros
// where the pair is out of contact; the rank's canonical gather then reads the slots
// (rank_processor.hpp), a block of particles at a time (the list's order, rank_list.hpp), from a ring
// that stays in cache, as fast's sweep does. Under a law with memory each pair's stretch is a record of
// fast's (lane_engine/pair_stretches.hpp) beside it, advanced by the kernel. Each lane has the scalar law's
// bits, so the slots hold what particle_contact and particle_contact_memory give.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "demmat/model.hpp"
#include "demmat/lane_engine/neighbour_list.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/lane_engine/pair_kernel.hpp"
#include "demmat/lane_engine/pair_stretches.hpp"
#include "demmat/lane_engine/particles.hpp"
#include "demmat/lane_engine/wall_contacts.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

// The kernel needs only the pair part of a model, the law's memory included: walls are the rank's own
// (scalar) pass.
template <class M>
using PairModel = Model<M::rotation, M::friction, M::damping, false, false, M::polydisperse, M::restitution_damping, M::history, M::rolling>;

template <class M>
class RankPairKernel {
public:
    // From this many local particles on, the kernel prefetches partners' records (fast's default).
    static constexpr std::size_t kPrefetchFrom = 8000;

    // Stretch quads per pair (fast's records): one per spring of the law, none for the paper's law.
    static constexpr std::size_t kQ = std::size_t(fast::stretch_quads<PairModel<M>>);

    void init(const ContactParams<double>& params, const Coefficients<double>& mono_pp, const MemoryParams<double>& memory)
    {
        law_.params = params;
        law_.memory = memory;
        law_.mono_pp = {splat<fast::Lanes>(mono_pp.kn), splat<fast::Lanes>(mono_pp.cn), splat<fast::Lanes>(mono_pp.ct)};
    }

    // At a rebuild: the pairs (local indices, i the lower id), the `counted` ones (i owned) first, in
    // the order of the list (rank_list.hpp); the sums read a counted slot at most `reach` slots after
    // it was written, so a ring of that many keeps them. The pairs whose i is a ghost keep a slot each.
    // Under a law with memory each pair starts with what `carried(i_id, j_id)` gives (a pointer to its
    // stretch, or null: a new contact starts at zero), looked up by the pair's ids, never by a slot.
    template <class Pair, class Carried>
    void set_pairs(const std::vector<Pair>& pairs, std::size_t counted, std::size_t reach, const RankParticles& p, Carried&& carried)
    {
        counted_ = counted;
        fill(list_, pairs, 0, counted);
        fill(ghost_list_, pairs, counted, pairs.size());
        ring_size_ = std::bit_ceil(std::max<std::size_t>(reach, 1));
        slots_.assign(ring_size_ + (pairs.size() - counted) + 1);  // the ring, the ghosts' pairs, a zero
        if constexpr (kQ > 0) {
            stretches_.assign(pairs.size() * kQ, fast::Quad{});
            for (std::size_t k = 0; k < pairs.size(); ++k)
                if (const Stretch<double>* s = carried(p.id[std::size_t(pairs[k].i)], p.id[std::size_t(pairs[k].j)])) {
                    ContactStretch c;
                    c.tangential = s->t;
                    c.rolling = s->r;
                    fast::stretch_to_record(c, M::history, M::rolling, &stretches_[k * kQ]);
                }
        }
    }

    // Pair k's stretch (zero out of contact: forgotten, as arrays forgets it), and whether it holds a
    // bit (fast's convention: all-zero bits are a contact's start, so only those with a bit are carried).
    Stretch<double> stretch(std::size_t k) const
    {
        ContactStretch c;
        if constexpr (kQ > 0) fast::record_to_stretch(&stretches_[k * kQ], M::history, M::rolling, c);
        return {c.tangential, c.rolling};
    }
    bool carries(std::size_t k) const
    {
        for (std::size_t q = 0; q < kQ; ++q)
            for (int c = 0; c < 3; ++c)
                if (std::bit_cast<std::uint64_t>(stretches_[k * kQ + q][c]) != 0) return true;
        return false;
    }
    // Whether pair (a, b), local indices, touched at the last force pass (h > 0 at the records it read).
    bool touched(std::size_t a, std::size_t b) const
    {
        const fast::Quad& x = soa_.kin[a].xr;
        const fast::Quad& y = soa_.kin[b].xr;
        Vec3d dx;
        double d;
        return demmat::detail::pair_overlap(Vec3d{x[0], x[1], x[2]}, Vec3d{y[0], y[1], y[2]}, x[3], y[3], dx, d) > 0.0;
    }

    // The kernel's records from the particles' current state: before run, once per force pass.
    void refresh_records(const RankParticles& p)
    {
        const std::size_t n = p.size();
        soa_.kin.resize(n);
        fast::Kin* rec = soa_.kin.data();
        for (std::size_t l = 0; l < n; ++l) {
            rec[l].xr = fast::Quad{p.x[l].x, p.x[l].y, p.x[l].z, p.r[l]};
            rec[l].v = fast::Quad{p.v[l].x, p.v[l].y, p.v[l].z, p.m[l]};
            rec[l].w = fast::Quad{p.w[l].x, p.w[l].y, p.w[l].z, 0.0};
        }
        prefetch_ = n >= kPrefetchFrom;
    }

    // The pairs whose i is a ghost: few, at the faces, each into its own slot. First in a force pass.
    void run_ghost_pairs()
    {
        if (ghost_list_.pairs() == 0) return;
        const fast::PairKernel<PairModel<M>> kernel(ghost_list_, soa_, law_, stretch_at(counted_), false);  // too few to prefetch
        kernel.template run<true>(0, ghost_list_.pairs(), nullptr, fast::SlotSink{slots_.view(ring_size_), ~std::size_t(0), {}});
    }

    // Counted slots [begin, end), into the ring; returns the contacts among them.
    std::int64_t run(std::size_t begin, std::size_t end)
    {
        if (begin >= end) return 0;
        const fast::PairKernel<PairModel<M>> kernel(list_, soa_, law_, stretch_at(0), prefetch_ && list_.pairs() >= fast::kLanes);
        return kernel.template run<true>(begin, end, nullptr, fast::SlotSink{slots_.view(), ring_size_ - 1, {}});
    }

    // Where pair k's slot lies in slots(): valid from the run that wrote it until the ring comes round.
    // The last position holds zeros.
    std::int32_t position(std::size_t k) const { return std::int32_t(k < counted_ ? k & (ring_size_ - 1) : ring_size_ + (k - counted_)); }
    std::int32_t zero_position() const { return std::int32_t(slots_.size() - 1); }
    const fast::SlotStore& slots() const { return slots_; }

    std::size_t memory_bytes() const { return list_.bytes() + ghost_list_.bytes() + soa_.bytes() + slots_.bytes() + fast::heap_bytes(stretches_); }

private:
    fast::Quad* stretch_at(std::size_t k) { return kQ > 0 ? stretches_.data() + k * kQ : nullptr; }

    template <class Pair>
    static void fill(fast::NeighbourList& list, const std::vector<Pair>& pairs, std::size_t begin, std::size_t end)
    {
        list.owner.resize(end - begin);
        list.partner.resize(end - begin);
        for (std::size_t k = begin; k < end; ++k) {
            list.owner[k - begin] = fast::Index(pairs[k].i);
            list.partner[k - begin] = fast::Index(pairs[k].j);
        }
    }

    fast::LawInputs law_;
    fast::Particles soa_;         // only the kernel's records (kin) are used
    fast::NeighbourList list_, ghost_list_;  // the counted pairs, the others; only owners and partners are used
    fast::SlotStore slots_;  // a ring for the counted pairs, then a slot per other pair, then zeros
    std::vector<fast::Quad> stretches_;  // kQ per pair (a law with memory), in the list's order
    std::size_t counted_ = 0, ring_size_ = 1;
    bool prefetch_ = false;
};

} // namespace demmat::mpi
