#pragma once
// The fast variant's particles in storage (cell) order: the Gear state as a structure of arrays, each
// vector quantity three contiguous component blocks (x then y then z) as in arrays, the step's forces,
// and the kernels' records. predict()'s pass runs here, a block at a time: the corrector of one step
// fused with the predictor of the next, the displacement check, the records (docs/variants/engine.md).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <vector>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "demmat/contact_law.hpp"
#include "demmat/gear.hpp"
#include "demmat/variant.hpp"
#include "heap_bytes.hpp"
#include "quads.hpp"
#include "team.hpp"

namespace demmat::fast {

// A particle's kinematics as the pair and wall kernels read them, one record per particle: position
// and radius, velocity and mass (the law's coefficients), angular velocity, a quad each, so that a
// lane's particle is three loads of one record, not ten from ten arrays.
struct alignas(sizeof(Quad)) Kin {
    Quad xr;  // x, y, z, R
    Quad v;   // vx, vy, vz, m
    Quad w;   // wx, wy, wz, 0
};

class Particles {
public:
    std::size_t n = 0;
    // Storage slot s holds particle id[s]; pos[i] is the slot of id i.
    std::vector<double> x, v, a, b3, b4, b5, th, w, al, r3, r4, r5;  // (3N) the Gear arrays
    std::vector<double> f, t;                                          // (3N) the last force pass's sums
    std::vector<double> xref;                                          // (3N) positions at the last rebuild
    std::vector<double> r, m, inertia;                                 // (N)
    std::vector<Index> id, pos;                                        // (N)
    std::vector<Kin> kin;                                              // (N) the kernels' records
    // Between correct() and the next predict() the arrays hold the predicted state, f and t its forces;
    // the corrector is pending (applied by the next pass, or by gear_state to what it reads).
    bool corrector_pending = false;

    void init(const Setup& setup)
    {
        const State& s = *setup.state;
        n = s.size();
        gear_ = GearCoefficients<double>::make(setup.scene->dt);
        g_ = setup.scene->gravity;
        load_gear_columns<double>(s, {&x, &v, &a, &b3, &b4, &b5, &th, &w, &al, &r3, &r4, &r5});
        for (auto* arr : {&f, &t, &xref, &tmp_}) arr->assign(3 * n, 0.0);
        r.resize(n); m.resize(n); inertia.resize(n); id.resize(n); pos.resize(n); tmp1_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            r[i] = s.radius[i];
            m[i] = setup.mass[i];
            inertia[i] = setup.inertia[i];
            id[i] = Index(i);
        }
        kin.resize(n);
        corrector_pending = false;
    }

    Vec3d get(const std::vector<double>& arr, std::size_t s) const { return {arr[s], arr[n + s], arr[2 * n + s]}; }
    void put(std::vector<double>& arr, std::size_t s, const Vec3d& u)
    {
        arr[s] = u.x;
        arr[n + s] = u.y;
        arr[2 * n + s] = u.z;
    }
    // Particle s's sums (the first three lanes of each quad) into f and t.
    void store_sum(std::size_t s, const Quad& fs, const Quad& ts)
    {
        for (int c = 0; c < 3; ++c) {
            f[std::size_t(c) * n + s] = fs[c];
            t[std::size_t(c) * n + s] = ts[c];
        }
    }

    // Particles per block of predict()'s pass, whose arrays stay in cache from one step of the pass to
    // the next (integrate() takes at most this many).
    static constexpr std::size_t kPassBlock = 1024;

    // The Gear step of particles [b0, b1), at most kPassBlock: the pending corrector (accelerations from
    // the last force pass, a = F/m + g and α = T/I, as Newton's law in arrays) fused with the predictor,
    // or the predictor alone after init. A component block at a time: seven streams in, six out,
    // vectorised. Without rotation (a model with !rotation) the rotational state stays as it is: all
    // zeros, as in arrays. Returns 1 if a particle of the block has moved farther than sqrt(lim2) since
    // the last rebuild (or its position is not finite), else 0: the displacement is taken from each
    // new position as it is stored, in the same loop (a pass of its own would read the positions
    // again).
    template <bool Rotation>
    int integrate(std::size_t b0, std::size_t b1, bool fused, double lim2)
    {
        double d2[kPassBlock];  // each particle's squared displacement since the last rebuild, summed x, y, z
        const double* __restrict xr = xref.data();
        const GearCoefficients<double> k = gear_;
        const double* __restrict mass = m.data();
        const double* __restrict inert = inertia.data();
        for (int c = 0; c < 3; ++c) {
            const std::size_t o = std::size_t(c) * n;
            double* __restrict px = x.data() + o; double* __restrict pv = v.data() + o; double* __restrict pa = a.data() + o;
            double* __restrict p3 = b3.data() + o; double* __restrict p4 = b4.data() + o; double* __restrict p5 = b5.data() + o;
            double* __restrict qx = th.data() + o; double* __restrict qv = w.data() + o; double* __restrict qa = al.data() + o;
            double* __restrict q3 = r3.data() + o; double* __restrict q4 = r4.data() + o; double* __restrict q5 = r5.data() + o;
            const double* __restrict pf = f.data() + o;
            const double* __restrict pt = t.data() + o;
            const double g = component(g_, c);
            const double* __restrict xc = xr + o;
            if (fused) {
#pragma omp simd
                for (std::size_t s = b0; s < b1; ++s) {
                    correct_predict(px[s], pv[s], pa[s], p3[s], p4[s], p5[s], acceleration(pf[s], mass[s], g), k);
                    const double d = px[s] - xc[s];
                    d2[s - b0] = c == 0 ? d * d : d2[s - b0] + d * d;
                }
                if constexpr (Rotation) {
#pragma omp simd
                    for (std::size_t s = b0; s < b1; ++s) correct_predict(qx[s], qv[s], qa[s], q3[s], q4[s], q5[s], pt[s] / inert[s], k);
                }
            } else {
#pragma omp simd
                for (std::size_t s = b0; s < b1; ++s) {
                    gear_predict(px[s], pv[s], pa[s], p3[s], p4[s], p5[s], k);
                    const double d = px[s] - xc[s];
                    d2[s - b0] = c == 0 ? d * d : d2[s - b0] + d * d;
                }
                if constexpr (Rotation) {
#pragma omp simd
                    for (std::size_t s = b0; s < b1; ++s) gear_predict(qx[s], qv[s], qa[s], q3[s], q4[s], q5[s], k);
                }
            }
        }
        int over = 0;
#pragma omp simd reduction(| : over)
        for (std::size_t e = 0; e < b1 - b0; ++e) over |= int(!(d2[e] <= lim2));
        return over;
    }

    // The kernels' records for [lo, hi), from the state arrays: four particles at a time, a quad of each
    // array transposed into their four records (fewer instructions than a record at a time from scalar
    // loads), the rest one by one. Stream (where the target has AVX): the four records' six whole cache
    // lines by non-temporal stores, which do not read each line before writing it, nor keep it in the
    // caches: for a pass over more particles than the caches hold, whose records are gone from them
    // before the force pass reads them anyway (FastOptions::stream_records_from). Such stores are
    // weakly ordered: the thread calls records_fence() before another may read the records.
    template <bool Stream = false>
    void refresh_records(std::size_t lo, std::size_t hi)
    {
        const double* __restrict px = x.data();
        const double* __restrict pv = v.data();
        const double* __restrict pw = w.data();
        const double* __restrict pr = r.data();
        const double* __restrict pm = m.data();
        Kin* __restrict rec = kin.data();
        auto records = [&](std::size_t s, const double* c, const Quad& fourth, Quad Kin::*field) {
            Quad qa, qb, qd, qe = fourth;
            load_quad(qa, c + s);
            load_quad(qb, c + n + s);
            load_quad(qd, c + 2 * n + s);
            transpose4(qa, qb, qd, qe);
#ifdef __AVX__
            if constexpr (Stream) {
                auto stream = [](Quad& to, const Quad& q) { _mm256_stream_pd(reinterpret_cast<double*>(&to), __m256d(q)); };
                stream(rec[s].*field, qa);
                stream(rec[s + 1].*field, qb);
                stream(rec[s + 2].*field, qd);
                stream(rec[s + 3].*field, qe);
                return;
            }
#endif
            rec[s].*field = qa;
            rec[s + 1].*field = qb;
            rec[s + 2].*field = qd;
            rec[s + 3].*field = qe;
        };
        std::size_t s = lo;
        for (; s + 4 <= hi; s += 4) {
            Quad radii, masses;
            load_quad(radii, pr + s);
            load_quad(masses, pm + s);
            records(s, px, radii, &Kin::xr);
            records(s, pv, masses, &Kin::v);
            records(s, pw, Quad{}, &Kin::w);
        }
        for (; s < hi; ++s) {
            rec[s].xr = Quad{px[s], px[n + s], px[2 * n + s], pr[s]};
            rec[s].v = Quad{pv[s], pv[n + s], pv[2 * n + s], pm[s]};
            rec[s].w = Quad{pw[s], pw[n + s], pw[2 * n + s], 0.0};
        }
    }

    // Orders this thread's streamed records (refresh_records<true>) before whatever it stores next.
    static void records_fence()
    {
#ifdef __AVX__
        _mm_sfence();
#endif
    }

    // Particle s's six Gear values (x, v, a, b3, b4, b5) for translation or rotation, as the step's
    // corrector leaves them: the arrays' own while no corrector is pending, else the corrector applied to
    // them here, by the same acceleration() and gear_correct as the fused pass (integrate()).
    std::array<Vec3d, 6> gear_state(bool rotation, std::size_t s) const
    {
        const std::vector<double>* src[6] = {&x, &v, &a, &b3, &b4, &b5};
        if (rotation) {
            const std::vector<double>* rot[6] = {&th, &w, &al, &r3, &r4, &r5};
            std::copy(rot, rot + 6, src);
        }
        std::array<Vec3d, 6> g;
        for (int c = 0; c < 3; ++c) {
            const std::size_t e = std::size_t(c) * n + s;
            double q[6];
            for (int k = 0; k < 6; ++k) q[k] = (*src[k])[e];
            if (corrector_pending) {
                const double da = (rotation ? t[e] / inertia[s] : acceleration(f[e], m[s], component(g_, c))) - q[2];
                gear_correct(q[0], q[1], q[2], q[3], q[4], q[5], da, gear_);
            }
            for (int k = 0; k < 6; ++k) component(g[std::size_t(k)], c) = q[k];
        }
        return g;
    }

    // The new storage order: slot s takes the particle that was at from(s), whose id is id_of(s).
    template <class From, class Id>
    void permute(From&& from, Id&& id_of, bool parallel)
    {
        for (auto* arr : {&x, &v, &a, &b3, &b4, &b5, &th, &w, &al, &r3, &r4, &r5}) {
            std::vector<double>& col = *arr;
            double* dst = tmp_.data();
            const double* src = col.data();
            in_team(parallel, [&] {
#pragma omp for schedule(static)
                for (std::size_t s = 0; s < n; ++s) {
                    const std::size_t o = from(s);
                    dst[s] = src[o];
                    dst[n + s] = src[n + o];
                    dst[2 * n + s] = src[2 * n + o];
                }
            });
            col.swap(tmp_);
        }
        for (auto* arr : {&r, &m, &inertia}) {
            for (std::size_t s = 0; s < n; ++s) tmp1_[s] = (*arr)[from(s)];
            arr->swap(tmp1_);
        }
        for (std::size_t s = 0; s < n; ++s) {
            id[s] = id_of(s);
            pos[std::size_t(id[s])] = Index(s);
        }
    }

    std::size_t bytes() const
    {
        return heap_bytes(x, v, a, b3, b4, b5, th, w, al, r3, r4, r5, f, t, xref, r, m, inertia, id, pos, kin, tmp_, tmp1_);
    }

private:
    // The corrector and then the predictor on one component of one degree of freedom (integrate()).
    [[gnu::always_inline]] static void correct_predict(double& x, double& v, double& a, double& b3, double& b4, double& b5, double accel,
                                                       const GearCoefficients<double>& k)
    {
        double x1 = x, v1 = v, a1 = a, b31 = b3, b41 = b4, b51 = b5;
        const double da = accel - a1;
        gear_correct(x1, v1, a1, b31, b41, b51, da, k);
        gear_predict(x1, v1, a1, b31, b41, b51, k);
        x = x1; v = v1; a = a1; b3 = b31; b4 = b41; b5 = b51;
    }

    GearCoefficients<double> gear_;
    Vec3d g_;
    std::vector<double> tmp_, tmp1_;  // (3N), (N) scratch for permute
};

} // namespace demmat::fast
