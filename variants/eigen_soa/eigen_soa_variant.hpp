#pragma once
// The Eigen structure-of-arrays processor: every per-particle vector quantity is one
// Eigen::Array<double, Dynamic, 3, ColMajor> — one allocation holding the x components of all
// particles, then all y components, then all z components (three contiguous component arrays, the same
// layout as the arrays variant and as Fortran stores an (N, 3) array). The predictor and the corrector
// are whole-array Eigen expressions: gear_predict / gear_correct (gear.hpp) are called once per
// quantity with V = that array type, and because the storage is one contiguous block, Eigen evaluates
// each statement as one linear, SIMD-vectorised loop over all 3N components. An element-wise
// expression performs the same operations in the same order for every element as the scalar loop, so
// the trajectory is bit-identical to arrays (no Eigen reduction — sum, dot, norm — stands anywhere a
// fixed summation order matters; minCoeff/maxCoeff in the search are exact in any order).
//
// Why N×3 column-major rather than three ArrayXd per quantity: the same memory layout (three
// contiguous component arrays), but one object per quantity, so one Gear call per quantity instead of
// three, one allocation, and column c is still a contiguous ArrayXd view (f.col(c) / m + g).
//
// The contact phase cannot be written as whole-array expressions: a pair (i, j) gathers two particles'
// components at stride N, calls the shared scalar contact law, and scatter-adds into f and t. The
// neighbour store is CSR (row offsets + partner ids), built by a hashed cell search as in arrays,
// within fixed capacities (scene.capacity) that stop the run with a CapacityError when exceeded.
//
// Under a contact law with memory (physics.md §9) the stretches are Eigen arrays too, in compressed rows
// beside the neighbour store, keyed by partner id (stretch_rows.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"
#include "stretch_rows.hpp"

namespace demmat::eigen_soa {

// The instantiation for a scene with a §9 law (eigen_soa_laws.cpp).
std::unique_ptr<Variant> pick_eigen_soa_law(const Setup& setup);

// Internal linkage, as when the class lived in eigen_soa.cpp alone: each of the two translation units
// that include it (eigen_soa.cpp, the paper's law; eigen_soa_laws.cpp, §9) compiles its own models, and the
// paper's compile exactly as before the laws existed (the same code, instruction for instruction).
namespace {

using Index = std::int32_t;
using Arr3 = Eigen::Array<double, Eigen::Dynamic, 3, Eigen::ColMajor>;         // (N, 3): x | y | z
using Cell3 = Eigen::Array<std::int64_t, Eigen::Dynamic, 3, Eigen::ColMajor>;  // (N, 3) cell coordinates
using Arr1 = Eigen::ArrayXd;                                                   // (N)
using IndexArr = Eigen::Array<Index, Eigen::Dynamic, 1>;

// Gather particle i's vector from the three component columns; scatter-add into them.
inline Vec3d get(const Arr3& a, Eigen::Index i) { return {a.coeff(i, 0), a.coeff(i, 1), a.coeff(i, 2)}; }
inline void add(Arr3& a, Eigen::Index i, const Vec3d& v)
{
    a.coeffRef(i, 0) += v.x;
    a.coeffRef(i, 1) += v.y;
    a.coeffRef(i, 2) += v.z;
}

// ---- contact stores: compressed sparse rows ------------------------------------------------------------

// Candidate partners j > i of particle i are partner[offset[i] .. offset[i+1]), ascending, at most `cap`
// per particle; the partner array is sized N·cap up front (the paper's fixed capacities).
struct NeighbourCSR {
    Index cap = 0;
    IndexArr offset;   // (N + 1)
    IndexArr partner;  // (N·cap)
};

// Walls particle i may touch: wall[offset[i] .. offset[i+1]), in wall order, at most `cap` per particle.
struct WallCSR {
    Index cap = 0;
    IndexArr offset;  // (N + 1)
    IndexArr wall;    // (N·cap)
};

[[noreturn]] void wall_overflow(Eigen::Index i, Index cap, std::size_t walls)
{
    // At most one entry per wall: the number of walls always fits.
    throw CapacityError(fmt::format("capacity.wall_contacts_per_particle = {} exceeded: particle {} touches more "
                                    "walls; set it to {} (the number of walls)", cap, i, walls));
}

// ---- the processor ---------------------------------------------------------------------------------------

template <class M>
class EigenSoaVariant final : public Variant {
public:
    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = Eigen::Index(s.size());
        step_ = s.step;
        dt_ = scene.dt;
        gear_ = setup.gear;
        params_ = setup.contact;
        memory_ = setup.memory;
        g_ = scene.gravity;
        walls_ = s.walls;
        cell_ = setup.cell_size;
        for (Arr3* arr : {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_, &f_, &t_, &acc_, &alc_})
            arr->setZero(n_, 3);
        auto load = [this](Arr3& dst, const std::vector<Vec3d>& src) {
            for (Eigen::Index i = 0; i < n_; ++i)
                for (int c = 0; c < 3; ++c) dst(i, c) = component(src[std::size_t(i)], c);
        };
        load(x_, s.trans.x); load(v_, s.trans.v); load(a_, s.trans.a);
        load(b3_, s.trans.b3); load(b4_, s.trans.b4); load(b5_, s.trans.b5);
        load(th_, s.rot.x); load(w_, s.rot.v); load(al_, s.rot.a);
        load(r3_, s.rot.b3); load(r4_, s.rot.b4); load(r5_, s.rot.b5);
        r_.resize(n_); m_.resize(n_); I_.resize(n_);
        for (Eigen::Index i = 0; i < n_; ++i) {
            r_(i) = s.radius[std::size_t(i)];
            m_(i) = setup.mass[std::size_t(i)];
            I_(i) = setup.inertia[std::size_t(i)];
        }
        nw_ = walls_.size();
        wp_.assign(nw_, Vec3d{});
        place_walls(step_);
        if constexpr (!M::polydisperse)  // one radius and mass: the contacts' coefficients once per run
            if (n_ > 0) {
                mono_pp_ = pair_coefficients(r_(0), r_(0), m_(0), m_(0), params_);
                mono_pw_ = wall_coefficients(r_(0), m_(0), params_);
            }

        nl_.cap = Index(scene.capacity.contacts_per_particle);
        nl_.offset.setZero(n_ + 1);
        nl_.partner.setZero(n_ * nl_.cap);
        if constexpr (M::walls) {  // a model without walls holds no boundary list
            bl_.cap = Index(scene.capacity.wall_contacts_per_particle);
            bl_.offset.setZero(n_ + 1);
            bl_.wall.setZero(n_ * bl_.cap);
        }
        cells_.reserve(std::size_t(n_));
        pp_ = pw_ = candidates_ = 0;
        if constexpr (M::memory) {  // the stretches of a §9 law, carried from the state (none at a fresh start)
            pp_mem_.reset(n_, nl_.cap, M::history, M::rolling);
            pw_mem_.reset(n_, bl_.cap, M::history, M::rolling);
            if (!pp_mem_.load(s.stretches, false) || !pw_mem_.load(s.stretches, true))
                throw CapacityError(fmt::format("the state holds more contacts than capacity.contacts_per_particle = {} or "
                                                "wall_contacts_per_particle = {} allow", nl_.cap, bl_.cap));
        }
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        gear_predict(x_, v_, a_, b3_, b4_, b5_, gear_);  // V = Arr3: five whole-array statements
        if constexpr (M::rotation) gear_predict(th_, w_, al_, r3_, r4_, r5_, gear_);
        if constexpr (M::moving_walls) place_walls(step);  // fixed walls stay where init() put them
    }

    void search() override
    {
        if (n_ == 0) return;
        if (cell_ > 0.0) search_cells();
        else search_all_pairs();
        if constexpr (M::walls) search_walls();
    }

    void forces() override
    {
        f_.setZero();
        t_.setZero();
        pp_ = 0;
        pw_ = 0;
        candidates_ = n_ > 0 ? nl_.offset(n_) : 0;
        if constexpr (law) {
            law_contacts();
        } else {
            // Pairs in ascending (i, j): for each particle, partners k < p arrive in ascending k from the
            // earlier rows, then its own row's partners l > p ascending — the canonical order (physics.md §6).
            for (Eigen::Index i = 0; i < n_; ++i) {
                const Index begin = nl_.offset(i), end = nl_.offset(i + 1);
                if (begin == end) continue;
                const Vec3d xi = get(x_, i), vi = get(v_, i), wi = get(w_, i);
                const double ri = r_(i), mi = m_(i);
                for (Index k = begin; k < end; ++k) {
                    const Eigen::Index j = nl_.partner(k);
                    ContactForce<double> c;
                    if (!particle_contact<M>(xi, get(x_, j), vi, get(v_, j), wi, get(w_, j), ri, r_(j), mi, m_(j), params_, mono_pp_, c))
                        continue;
                    ++pp_;
                    add(f_, i, c.f_i);
                    add(f_, j, -c.f_i);
                    if constexpr (M::rotation) {
                        add(t_, i, c.t_i);
                        add(t_, j, c.t_j);
                    }
                }
            }
            if constexpr (M::walls)
                for (Eigen::Index i = 0; i < n_; ++i) {
                    for (Index k = bl_.offset(i), end = bl_.offset(i + 1); k < end; ++k) {
                        const auto w = std::size_t(bl_.wall(k));
                        ContactForce<double> c;
                        if (!wall_contact<M>(get(x_, i), get(v_, i), get(w_, i), r_(i), m_(i), wp_[w], walls_[w].normal,
                                             walls_[w].velocity, params_, mono_pw_, c))
                            continue;
                        ++pw_;
                        add(f_, i, c.f_i);
                        if constexpr (M::rotation) add(t_, i, c.t_i);
                    }
                }
        }
        // Newton with gravity, whole columns: a = F/m + g (division, then addition, as acceleration()).
        const double g[3] = {g_.x, g_.y, g_.z};
        for (int c = 0; c < 3; ++c) {
            acc_.col(c) = f_.col(c) / m_ + g[c];
            if constexpr (M::rotation) alc_.col(c) = t_.col(c) / I_;
        }
    }

    void correct() override
    {
        // Δa = a_c − a_p evaluated into its own storage (in place over a_c, which is not needed after),
        // never a lazy expression over a_, which gear_correct modifies.
        acc_ -= a_;
        gear_correct(x_, v_, a_, b3_, b4_, b5_, acc_, gear_);
        if constexpr (M::rotation) {
            alc_ -= al_;
            gear_correct(th_, w_, al_, r3_, r4_, r5_, alc_, gear_);
        }
    }

    void snapshot(Snapshot& out) const override
    {
        out.resize(std::size_t(n_));
        out.step = step_;
        for (Eigen::Index i = 0; i < n_; ++i) {
            const auto k = std::size_t(i);
            out.position[k] = get(x_, i);
            out.velocity[k] = get(v_, i);
            out.angular_velocity[k] = get(w_, i);
            out.force[k] = get(f_, i);
            out.torque[k] = get(t_, i);
        }
    }

    void save(State& out) const override
    {
        out.resize(std::size_t(n_));
        out.step = step_;
        out.walls = walls_;
        const Arr3* src[12] = {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_};
        std::vector<Vec3d>* dst[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                       &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int q = 0; q < 12; ++q)
            for (Eigen::Index i = 0; i < n_; ++i) (*dst[q])[std::size_t(i)] = get(*src[q], i);
        for (Eigen::Index i = 0; i < n_; ++i) out.radius[std::size_t(i)] = r_(i);
        out.stretches.clear();
        if constexpr (M::memory) {
            pp_mem_.save(out.stretches, false);
            pw_mem_.save(out.stretches, true);
            std::sort(out.stretches.begin(), out.stretches.end());  // the canonical order: by particle, pairs, then walls
        }
    }

    ContactCounts counts() const override { return {pp_, pw_, candidates_}; }
    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

    std::size_t memory_bytes() const override
    {
        const auto n = std::size_t(n_);
        return 16 * 3 * n * sizeof(double) + 3 * n * sizeof(double) +
               std::size_t(nl_.offset.size() + nl_.partner.size() + bl_.offset.size() + bl_.wall.size()) * sizeof(Index) +
               cells_.memory_bytes() + wp_.size() * sizeof(Vec3d) + stretch_bytes();
    }

private:
    std::size_t stretch_bytes() const
    {
        if constexpr (M::memory) return pp_mem_.memory_bytes() + pw_mem_.memory_bytes();
        else return 0;
    }

    // Row i of a stretch store: the previous evaluation's, to read by key, and this one's begun.
    template <class Store>
    static auto row_reader(Store& store, Eigen::Index i)
    {
        if constexpr (M::memory) {
            store.begin_row(i);
            return store.reader(i);
        } else {
            return 0;  // a law without memory has no stretch to read
        }
    }

    // A law of physics.md §9: as the paper's law in forces(), with each live contact's stretches taken from the
    // previous evaluation by partner and written to this one's rows (a law without memory has none).
    void law_contacts()
    {
        for (Eigen::Index i = 0; i < n_; ++i) {
            [[maybe_unused]] auto old = row_reader(pp_mem_, i);
            const Vec3d xi = get(x_, i), vi = get(v_, i), wi = get(w_, i);
            const double ri = r_(i), mi = m_(i);
            for (Index k = nl_.offset(i), end = nl_.offset(i + 1); k < end; ++k) {
                const Index j = nl_.partner(k);
                Stretch<double> s;
                if constexpr (M::memory) s = old.take(j);
                ContactForce<double> c;
                if (!particle_contact_memory<M>(xi, get(x_, j), vi, get(v_, j), wi, get(w_, j), ri, r_(j), mi, m_(j), params_, memory_, s,
                                                true, c))
                    continue;
                ++pp_;
                if constexpr (M::memory) pp_mem_.put(j, s);
                add(f_, i, c.f_i);
                add(f_, j, -c.f_i);
                add(t_, i, c.t_i);
                add(t_, j, c.t_j);
            }
        }
        for (Eigen::Index i = 0; i < n_; ++i) {
            [[maybe_unused]] auto old = row_reader(pw_mem_, i);
            for (Index k = bl_.offset(i), end = bl_.offset(i + 1); k < end; ++k) {
                const Index w = bl_.wall(k);
                Stretch<double> s;
                if constexpr (M::memory) s = old.take(w);
                ContactForce<double> c;
                if (!wall_contact_memory<M>(get(x_, i), get(v_, i), get(w_, i), r_(i), m_(i), wp_[std::size_t(w)],
                                            walls_[std::size_t(w)].normal, walls_[std::size_t(w)].velocity, params_, memory_, s, true, c))
                    continue;
                ++pw_;
                if constexpr (M::memory) pw_mem_.put(w, s);
                add(f_, i, c.f_i);
                add(t_, i, c.t_i);
            }
        }
        if constexpr (M::memory) {
            pp_mem_.finish_evaluation();
            pw_mem_.finish_evaluation();
        }
    }

    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < nw_; ++w) wp_[w] = walls_[w].point_at(step, dt_);
    }

    // Every pair (the paper's "no cells"), O(N²).
    void search_all_pairs()
    {
        Index* part = nl_.partner.data();
        Index used = 0;
        CandidateOverflow over;
        for (Eigen::Index i = 0; i < n_; ++i) {
            nl_.offset(i) = used;
            Index c = 0;
            const Vec3d xi = get(x_, i);
            for (Eigen::Index j = i + 1; j < n_; ++j) {
                if (!may_touch(xi, get(x_, j), r_(i), r_(j))) continue;
                if (c < nl_.cap) part[used + c] = Index(j);
                ++c;
            }
            over.note(c, i);
            used += std::min(c, nl_.cap);
        }
        nl_.offset(n_) = used;
        over.check(nl_.cap);
    }

    // Linked cells (core/include/demmat/linked_cells.hpp) on the three position columns; partners j > i stored
    // ascending in the particle's compressed row, as the canonical order needs.
    void search_cells()
    {
        cells_.build(std::size_t(n_), x_.col(0).data(), x_.col(1).data(), x_.col(2).data(), cell_);
        Index* part = nl_.partner.data();
        Index used = 0;
        CandidateOverflow over;
        for (Eigen::Index i = 0; i < n_; ++i) {
            nl_.offset(i) = used;
            Index* row = part + used;
            Index c = 0;
            const Vec3d xi = get(x_, i);
            const double ri = r_(i);
            cells_.for_each_above(std::size_t(i), [&](std::size_t j) {
                if (!may_touch(xi, get(x_, Eigen::Index(j)), ri, r_(Eigen::Index(j)))) return;
                if (c < nl_.cap) insert_ascending(row, c, Index(j));
                ++c;
            });
            over.note(c, std::size_t(i));
            used += std::min(c, nl_.cap);
        }
        nl_.offset(n_) = used;
        over.check(nl_.cap);
    }

    void search_walls()
    {
        // Rows are per particle (CSR), so particles are the outer loop here; an overflow names the
        // particle arrays (walls outer) would name: the lowest id at the lowest overflowing wall.
        Index used = 0;
        std::size_t over_wall = nw_;
        Eigen::Index over_particle = -1;
        for (Eigen::Index i = 0; i < n_; ++i) {
            bl_.offset(i) = used;
            Index c = 0;
            const Vec3d xi = get(x_, i);
            for (std::size_t w = 0; w < nw_; ++w) {
                if (!may_touch_wall(xi, r_(i), wp_[w], walls_[w].normal)) continue;
                if (c == bl_.cap) {
                    if (w < over_wall) { over_wall = w; over_particle = i; }
                    break;
                }
                bl_.wall(used + c++) = Index(w);
            }
            used += c;
        }
        bl_.offset(n_) = used;
        if (over_particle >= 0) wall_overflow(over_particle, bl_.cap, nw_);
    }

    static constexpr bool law = M::restitution_damping || M::history || M::rolling;  // a §9 law, not the paper's

    Eigen::Index n_ = 0;
    std::size_t nw_ = 0;
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    double cell_ = 0.0;
    GearCoefficients<double> gear_;
    ContactParams<double> params_;
    MemoryParams<double> memory_;  // the §9 law's constants (zero for the paper's law)
    Coefficients<double> mono_pp_, mono_pw_;  // monodisperse models: the one pair's and wall contact's coefficients
    Vec3d g_;
    std::vector<Wall> walls_;
    std::vector<Vec3d> wp_;                                          // wall points at the current step
    Arr3 x_, v_, a_, b3_, b4_, b5_;                                  // translation Gear values
    Arr3 th_, w_, al_, r3_, r4_, r5_;                                // rotation Gear values
    Arr3 f_, t_;                                                     // contact force and torque sums
    Arr3 acc_, alc_;                                                 // a_c, α_c; Δa, Δα in correct()
    Arr1 r_, m_, I_;                                                 // radius, mass, inertia
    NeighbourCSR nl_;
    WallCSR bl_;
    LinkedCells cells_;
    // A §9 law with memory: the stretches of pairs (partners j > i) and of wall contacts; nothing otherwise.
    struct NoStretches {};
    [[no_unique_address]] std::conditional_t<M::memory, StretchRows, NoStretches> pp_mem_, pw_mem_;
    std::int64_t pp_ = 0, pw_ = 0, candidates_ = 0;
};

} // namespace
} // namespace demmat::eigen_soa
