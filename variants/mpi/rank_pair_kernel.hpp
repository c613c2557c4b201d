#pragma once
// A rank's pairs through the shared pair kernel on lanes (demmat/soa/pair_kernel.hpp, the kernel fast
// runs), for the paper's law. The rank's particles, owned and ghosts, get the kernel's records (one
// record of three quads per particle, soa/particles.hpp); its listed pairs (lower id as i) become the
// kernel's slots, each contact's force and torques into its slot, zeros where the pair is out of
// contact; the rank's canonical gather then reads the slots (rank_processor.hpp). The slots are ordered
// with the pairs whose lower id this rank owns first, so that the contacts are counted once over all
// ranks. Each lane has the scalar law's bits, so the slots hold what particle_contact gives.
#include <cstdint>
#include <vector>

#include "demmat/model.hpp"
#include "demmat/soa/neighbour_list.hpp"
#include "demmat/soa/pair_kernel.hpp"
#include "demmat/soa/particles.hpp"
#include "demmat/soa/wall_contacts.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

// The kernel needs only the pair part of a model: walls are the rank's own (scalar) pass.
template <class M>
using PairModel = Model<M::rotation, M::friction, M::damping, false, false, M::polydisperse>;

template <class M>
class RankPairKernel {
public:
    // From this many local particles on, the kernel prefetches partners' records (fast's default).
    static constexpr std::size_t kPrefetchFrom = 8000;

    void init(const ContactParams<double>& params, const Coefficients<double>& mono_pp)
    {
        law_.params = params;
        law_.mono_pp = {splat<fast::Lanes>(mono_pp.kn), splat<fast::Lanes>(mono_pp.cn), splat<fast::Lanes>(mono_pp.ct)};
    }

    // At a rebuild: the pairs (local indices, i the lower id), those with i owned first (`counted` of them).
    template <class Pair>
    void set_pairs(const std::vector<Pair>& pairs, std::size_t counted)
    {
        list_.owner.resize(pairs.size());
        list_.partner.resize(pairs.size());
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            list_.owner[k] = fast::Index(pairs[k].i);
            list_.partner[k] = fast::Index(pairs[k].j);
        }
        counted_ = counted;
        slots_.resize(pairs.size());
    }

    // Every slot from the particles' current state; returns the contacts among the counted pairs.
    std::int64_t run(const RankParticles& p)
    {
        refresh_records(p);
        const fast::PairKernel<PairModel<M>> kernel(list_, soa_, law_, nullptr, p.size() >= kPrefetchFrom);
        const fast::SlotSink sink{slots_.data(), ~std::size_t(0), nullptr};
        const std::int64_t found = kernel.template run<true>(0, counted_, nullptr, sink);
        kernel.template run<true>(counted_, slots_.size(), nullptr, sink);
        return found;
    }

    const fast::Slot& slot(std::size_t k) const { return slots_[k]; }

    std::size_t memory_bytes() const { return list_.bytes() + soa_.bytes() + fast::heap_bytes(slots_); }

private:
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
    }

    fast::LawInputs law_;
    fast::Particles soa_;         // only the kernel's records (kin) are used
    fast::NeighbourList list_;    // only the slots' owners and partners are used
    std::vector<fast::Slot> slots_;
    std::size_t counted_ = 0;
};

} // namespace demmat::mpi
