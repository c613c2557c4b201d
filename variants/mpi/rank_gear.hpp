#pragma once
// The Gear step on a rank's owned particles, as fast does it (docs/variants/engine.md): the corrector
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

// A Gear quantity's values as one flat array: a Vec3d is three doubles, and every component of every
// particle takes the same operations, so an array of owned Vec3d is 3·owned independent values (the
// pass vectorises over them, as fast's does over its component blocks).
static_assert(sizeof(Vec3d) == 3 * sizeof(double));
inline double* flat(std::vector<Vec3d>& v) { return reinterpret_cast<double*>(v.data()); }
inline const double* flat(const std::vector<Vec3d>& v) { return reinterpret_cast<const double*>(v.data()); }

// One degree of freedom (translation or rotation) over m values: the pending corrector (accel: the
// accelerations of the last force pass) then the predictor, or the predictor alone.
inline void gear_values(double* __restrict x, double* __restrict v, double* __restrict a, double* __restrict b3, double* __restrict b4,
                        double* __restrict b5, const double* __restrict accel, std::size_t m, bool fused, const GearCoefficients<double>& k)
{
    if (fused) {
#pragma omp simd
        for (std::size_t i = 0; i < m; ++i) {
            double x1 = x[i], v1 = v[i], a1 = a[i], c3 = b3[i], c4 = b4[i], c5 = b5[i];
            Gear5Scheme::correct(x1, v1, a1, c3, c4, c5, accel[i], k);
            Gear5Scheme::predict(x1, v1, a1, c3, c4, c5, k);
            x[i] = x1; v[i] = v1; a[i] = a1; b3[i] = c3; b4[i] = c4; b5[i] = c5;
        }
    } else {
#pragma omp simd
        for (std::size_t i = 0; i < m; ++i) Gear5Scheme::predict(x[i], v[i], a[i], b3[i], b4[i], b5[i], k);
    }
}

// The pending corrector alone on m values (snapshot and save).
inline void gear_correct_values(double* x, double* v, double* a, double* b3, double* b4, double* b5, const double* accel, std::size_t m,
                                const GearCoefficients<double>& k)
{
    for (std::size_t i = 0; i < m; ++i) Gear5Scheme::correct(x[i], v[i], a[i], b3[i], b4[i], b5[i], accel[i], k);
}

// One pass over the owned particles: the pending corrector (when `fused`), then the predictor. Returns
// whether some particle is now farther than sqrt(lim2) from its position in `built` (or not finite);
// `built` null: no check.
template <bool Rotation>
bool gear_pass(RankParticles& p, const GearCoefficients<double>& k, bool fused, const Vec3d* built, double lim2)
{
    const std::size_t n = p.owned(), m = 3 * n;
    gear_values(flat(p.x), flat(p.v), flat(p.a), flat(p.b3), flat(p.b4), flat(p.b5), flat(p.acc), m, fused, k);
    if constexpr (Rotation) gear_values(flat(p.th), flat(p.w), flat(p.al), flat(p.q3), flat(p.q4), flat(p.q5), flat(p.alc), m, fused, k);
    if (!built) return false;
    const double* __restrict x = flat(p.x);
    const double* __restrict x0 = reinterpret_cast<const double*>(built);
    int far = 0;
#pragma omp simd reduction(| : far)
    for (std::size_t l = 0; l < n; ++l) {
        const double dx = x[3 * l] - x0[3 * l], dy = x[3 * l + 1] - x0[3 * l + 1], dz = x[3 * l + 2] - x0[3 * l + 2];
        far |= int(!(dx * dx + dy * dy + dz * dz <= lim2));  // a NaN compares false: rebuild, so that the search names it
    }
    return far != 0;
}

// The particles as the pending corrector leaves them (a copy; `pending` false: as they are).
template <bool Rotation>
RankParticles corrected(const RankParticles& p, const GearCoefficients<double>& k, bool pending)
{
    RankParticles q = p;
    if (!pending) return q;
    const std::size_t m = 3 * q.owned();
    gear_correct_values(flat(q.x), flat(q.v), flat(q.a), flat(q.b3), flat(q.b4), flat(q.b5), flat(q.acc), m, k);
    if constexpr (Rotation) gear_correct_values(flat(q.th), flat(q.w), flat(q.al), flat(q.q3), flat(q.q4), flat(q.q5), flat(q.alc), m, k);
    return q;
}

} // namespace demmat::mpi
