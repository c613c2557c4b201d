#pragma once
// The Gear step on a rank's owned particles, as fast does it (docs/variants.md, "fast"): the corrector
// of one step fused with the predictor of the next in one pass over the Gear arrays (the arrays read and
// written once instead of twice), with the displacement check of the neighbour list in the same pass.
// The corrector is the shared Gear5Scheme::correct and the predictor Gear5Scheme::predict, the same
// operations in the same order as two passes, so the same bits. Between the force pass and the next
// predict the arrays hold the predicted state and the corrector is pending: snapshot and save read the
// state through `corrected`.
#include <cstdint>
#include <vector>

#include "demmat/integrators.hpp"
#include "rank_particles.hpp"

namespace demmat::mpi {

// f(c) for the three components, c(v) being v.x, v.y or v.z (no run-time branch per value).
template <class F>
void each_component(F&& f)
{
    f([](auto& v) -> auto& { return v.x; });
    f([](auto& v) -> auto& { return v.y; });
    f([](auto& v) -> auto& { return v.z; });
}

// The pending corrector on owned particle l (accelerations acc and alc from the last force pass).
template <bool Rotation>
inline void gear_correct_particle(RankParticles& p, std::size_t l, const GearCoefficients<double>& k)
{
    each_component([&](auto c) {
        Gear5Scheme::correct(c(p.x[l]), c(p.v[l]), c(p.a[l]), c(p.b3[l]), c(p.b4[l]), c(p.b5[l]), c(p.acc[l]), k);
        if constexpr (Rotation) Gear5Scheme::correct(c(p.th[l]), c(p.w[l]), c(p.al[l]), c(p.q3[l]), c(p.q4[l]), c(p.q5[l]), c(p.alc[l]), k);
    });
}

// One pass over the owned particles: the pending corrector (when `fused`), then the predictor. Returns
// whether some particle is now farther than sqrt(lim2) from its position in `built` (or not finite);
// `built` null: no check.
template <bool Rotation>
bool gear_pass(RankParticles& p, const GearCoefficients<double>& k, bool fused, const Vec3d* built, double lim2)
{
    bool far = false;
    for (std::size_t l = 0; l < p.owned(); ++l) {
        if (fused) gear_correct_particle<Rotation>(p, l, k);
        each_component([&](auto c) {
            Gear5Scheme::predict(c(p.x[l]), c(p.v[l]), c(p.a[l]), c(p.b3[l]), c(p.b4[l]), c(p.b5[l]), k);
            if constexpr (Rotation) Gear5Scheme::predict(c(p.th[l]), c(p.w[l]), c(p.al[l]), c(p.q3[l]), c(p.q4[l]), c(p.q5[l]), k);
        });
        if (built) {
            const Vec3d d = p.x[l] - built[l];
            far |= !(dot(d, d) <= lim2);  // a NaN compares false: rebuild, so that the search names it
        }
    }
    return far;
}

// The particles as the pending corrector leaves them (a copy; `pending` false: as they are).
template <bool Rotation>
RankParticles corrected(const RankParticles& p, const GearCoefficients<double>& k, bool pending)
{
    RankParticles q = p;
    if (pending)
        for (std::size_t l = 0; l < q.owned(); ++l) gear_correct_particle<Rotation>(q, l, k);
    return q;
}

} // namespace demmat::mpi
