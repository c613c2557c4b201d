// The plain-arrays processor, the paper's DEMMAT_F90 in C++: procedural free functions over flat
// arrays of shape (N, 3) stored column by column (x(i, c) at x[c·N + i], as Fortran stores them),
// capacities fixed up front and checked (the paper's "control of overestimation").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"

namespace demmat {
namespace {

using Index = std::int32_t;

// ---- predictor and corrector: one loop over all 3N components --------------------------------------

// The six arrays never alias (Fortran assumes as much of its dummy arguments); __restrict says so, and
// lets the compiler vectorise these loops (the element-wise operations, and so the bits, are the same).
template <class T>
void gear_predictor(std::size_t n3, T* __restrict x, T* __restrict v, T* __restrict a, T* __restrict b3, T* __restrict b4,
                    const T* __restrict b5, const GearCoefficients<T>& k)
{
    for (std::size_t e = 0; e < n3; ++e) gear_predict(x[e], v[e], a[e], b3[e], b4[e], b5[e], k);
}

template <class T>
void gear_corrector(std::size_t n3, T* __restrict x, T* __restrict v, T* __restrict a, T* __restrict b3, T* __restrict b4,
                    T* __restrict b5, const T* __restrict a_new, const GearCoefficients<T>& k)
{
    for (std::size_t e = 0; e < n3; ++e) {
        const T da = a_new[e] - a[e];
        gear_correct(x[e], v[e], a[e], b3[e], b4[e], b5[e], da, k);
    }
}

template <class T>
Vec3<T> get(const T* a, std::size_t n, std::size_t i) { return {a[i], a[n + i], a[2 * n + i]}; }
template <class T>
void add(T* a, std::size_t n, std::size_t i, const Vec3<T>& v)
{
    a[i] += v.x;
    a[n + i] += v.y;
    a[2 * n + i] += v.z;
}

// ---- contact search --------------------------------------------------------------------------------

// Neighbour list: for particle i, its candidate partners j > i in ascending order, at most `cap`.
struct NeighbourList {
    Index cap = 0;
    std::vector<Index> count;    // (N)
    std::vector<Index> partner;  // (N, cap), row i at [i·cap]
};

// Boundary list: for particle i, the walls it may touch, in wall order.
struct BoundaryList {
    Index cap = 0;
    std::vector<Index> count;  // (N)
    std::vector<Index> wall;   // (N, cap)
};

// Every pair (the paper's "no cells"), O(N²).
template <class T>
void search_all_pairs(std::size_t n, const T* x, const T* r, NeighbourList& nl)
{
    CandidateOverflow over;
    for (std::size_t i = 0; i < n; ++i) {
        Index c = 0;
        Index* row = &nl.partner[i * std::size_t(nl.cap)];
        const Vec3<T> xi = get(x, n, i);
        for (std::size_t j = i + 1; j < n; ++j) {
            if (!may_touch(xi, get(x, n, j), r[i], r[j])) continue;
            if (c < nl.cap) row[c] = Index(j);
            ++c;
        }
        over.note(c, i);
        nl.count[i] = std::min(c, nl.cap);
    }
    over.check(nl.cap);
}

// Linked cells (common/linked_cells.hpp); partners j > i stored in ascending order, as the canonical
// order needs. On overflow the search goes on counting so the message can give the value that fits.
template <class T>
void search_cells(std::size_t n, const T* x, const T* r, T edge, LinkedCells& cells, NeighbourList& nl)
{
    cells.build(n, x, x + n, x + 2 * n, edge);
    CandidateOverflow over;
    for (std::size_t i = 0; i < n; ++i) {
        Index c = 0;
        Index* row = &nl.partner[i * std::size_t(nl.cap)];
        const Vec3<T> xi = get(x, n, i);
        const T ri = r[i];
        cells.for_each_above(i, [&](std::size_t j) {
            if (!may_touch(xi, get(x, n, j), ri, r[j])) return;
            if (c < nl.cap) insert_ascending(row, c, Index(j));
            ++c;
        });
        over.note(c, i);
        nl.count[i] = std::min(c, nl.cap);
    }
    over.check(nl.cap);
}

template <class T>
void search_walls(std::size_t n, const T* x, const T* r, std::size_t nw, const T* wp, const T* wn, BoundaryList& bl)
{
    std::fill(bl.count.begin(), bl.count.end(), Index(0));
    for (std::size_t w = 0; w < nw; ++w) {
        const Vec3<T> p{wp[3 * w], wp[3 * w + 1], wp[3 * w + 2]}, nv{wn[3 * w], wn[3 * w + 1], wn[3 * w + 2]};
        for (std::size_t i = 0; i < n; ++i) {
            if (!may_touch_wall(get(x, n, i), r[i], p, nv)) continue;
            Index& c = bl.count[i];
            if (c == bl.cap)  // at most one entry per wall: the walls' count always fits
                throw CapacityError(fmt::format("capacity.wall_contacts_per_particle = {} exceeded: particle {} touches more "
                                                "walls; set it to {} (the number of walls)", bl.cap, i, nw));
            bl.wall[i * std::size_t(bl.cap) + std::size_t(c++)] = Index(w);
        }
    }
}

// ---- the processor ---------------------------------------------------------------------------------

template <class T, class M>
class ArraysVariant final : public Variant {
public:
    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = s.size();
        step_ = s.step;
        gear_ = GearCoefficients<T>::make(scene.dt);
        params_ = setup.contact.template as<T>();
        g_ = cast<T>(scene.gravity);
        walls_ = s.walls;
        dt_ = scene.dt;
        cell_ = T(setup.cell_size);
        for (auto* arr : {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_, &f_, &t_, &acc_, &alc_})
            arr->assign(3 * n_, T(0));
        auto load = [this](std::vector<T>& dst, const std::vector<Vec3d>& src) {
            for (std::size_t i = 0; i < n_; ++i)
                for (int c = 0; c < 3; ++c) dst[c * n_ + i] = T(component(src[i], c));
        };
        load(x_, s.trans.x); load(v_, s.trans.v); load(a_, s.trans.a);
        load(b3_, s.trans.b3); load(b4_, s.trans.b4); load(b5_, s.trans.b5);
        load(th_, s.rot.x); load(w_, s.rot.v); load(al_, s.rot.a);
        load(r3_, s.rot.b3); load(r4_, s.rot.b4); load(r5_, s.rot.b5);
        r_.resize(n_); m_.resize(n_); I_.resize(n_);
        for (std::size_t i = 0; i < n_; ++i) {
            r_[i] = T(s.radius[i]);
            m_[i] = T(setup.mass[i]);
            I_[i] = T(setup.inertia[i]);
        }
        nw_ = walls_.size();
        wp_.assign(3 * nw_, T(0)); wn_.assign(3 * nw_, T(0)); wv_.assign(3 * nw_, T(0));
        for (std::size_t w = 0; w < nw_; ++w)
            for (int c = 0; c < 3; ++c) {
                wn_[3 * w + c] = T(component(walls_[w].normal, c));
                wv_[3 * w + c] = T(component(walls_[w].velocity, c));
            }
        place_walls(step_);
        nl_.cap = Index(scene.capacity.contacts_per_particle);
        nl_.count.assign(n_, 0);
        nl_.partner.assign(n_ * std::size_t(nl_.cap), 0);
        bl_.cap = Index(scene.capacity.wall_contacts_per_particle);
        bl_.count.assign(n_, 0);
        bl_.wall.assign(n_ * std::size_t(bl_.cap), 0);
        cells_.reserve(n_);
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        gear_predictor(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), gear_);
        if constexpr (M::rotation)
            gear_predictor(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), gear_);
        place_walls(step);
    }

    void search() override
    {
        if (cell_ > T(0)) search_cells(n_, x_.data(), r_.data(), cell_, cells_, nl_);
        else search_all_pairs(n_, x_.data(), r_.data(), nl_);
        search_walls(n_, x_.data(), r_.data(), nw_, wp_.data(), wn_.data(), bl_);
    }

    void forces() override
    {
        std::fill(f_.begin(), f_.end(), T(0));
        std::fill(t_.begin(), t_.end(), T(0));
        pp_ = 0;
        pw_ = 0;
        candidates_ = 0;
        const std::size_t n = n_;
        for (std::size_t i = 0; i < n; ++i) {
            const Index* row = &nl_.partner[i * std::size_t(nl_.cap)];
            candidates_ += nl_.count[i];
            for (Index k = 0; k < nl_.count[i]; ++k) {
                const auto j = std::size_t(row[k]);
                ContactForce<T> c;
                if (!particle_contact<M>(get(x_.data(), n, i), get(x_.data(), n, j), get(v_.data(), n, i), get(v_.data(), n, j),
                                         get(w_.data(), n, i), get(w_.data(), n, j), r_[i], r_[j], m_[i], m_[j], params_, c))
                    continue;
                ++pp_;
                add(f_.data(), n, i, c.f_i);
                add(f_.data(), n, j, -c.f_i);
                if constexpr (M::rotation) {
                    add(t_.data(), n, i, c.t_i);
                    add(t_.data(), n, j, c.t_j);
                }
            }
        }
        for (std::size_t i = 0; i < n; ++i) {
            const Index* row = &bl_.wall[i * std::size_t(bl_.cap)];
            for (Index k = 0; k < bl_.count[i]; ++k) {
                const auto w = std::size_t(row[k]);
                ContactForce<T> c;
                if (!wall_contact<M>(get(x_.data(), n, i), get(v_.data(), n, i), get(w_.data(), n, i), r_[i], m_[i],
                                     Vec3<T>{wp_[3 * w], wp_[3 * w + 1], wp_[3 * w + 2]},
                                     Vec3<T>{wn_[3 * w], wn_[3 * w + 1], wn_[3 * w + 2]},
                                     Vec3<T>{wv_[3 * w], wv_[3 * w + 1], wv_[3 * w + 2]}, params_, c))
                    continue;
                ++pw_;
                add(f_.data(), n, i, c.f_i);
                if constexpr (M::rotation) add(t_.data(), n, i, c.t_i);
            }
        }
        const T g[3] = {g_.x, g_.y, g_.z};
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < n; ++i) {
                acc_[c * n + i] = acceleration(f_[c * n + i], m_[i], g[c]);
                if constexpr (M::rotation) alc_[c * n + i] = t_[c * n + i] / I_[i];
            }
    }

    void correct() override
    {
        gear_corrector(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), acc_.data(), gear_);
        if constexpr (M::rotation)
            gear_corrector(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), alc_.data(), gear_);
    }

    void snapshot(Snapshot& out) const override
    {
        out.resize(n_);
        out.step = step_;
        for (std::size_t i = 0; i < n_; ++i) {
            out.position[i] = cast<double>(get(x_.data(), n_, i));
            out.velocity[i] = cast<double>(get(v_.data(), n_, i));
            out.angular_velocity[i] = cast<double>(get(w_.data(), n_, i));
            out.force[i] = cast<double>(get(f_.data(), n_, i));
            out.torque[i] = cast<double>(get(t_.data(), n_, i));
        }
    }

    void save(State& out) const override
    {
        out.resize(n_);
        out.step = step_;
        out.walls = walls_;
        const std::vector<T>* src[12] = {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_};
        std::vector<Vec3d>* dst[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                       &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int k = 0; k < 12; ++k)
            for (std::size_t i = 0; i < n_; ++i) (*dst[k])[i] = cast<double>(get(src[k]->data(), n_, i));
        for (std::size_t i = 0; i < n_; ++i) out.radius[i] = double(r_[i]);
    }

    ContactCounts counts() const override { return {pp_, pw_, candidates_}; }

    std::size_t memory_bytes() const override
    {
        return 19 * 3 * n_ * sizeof(T) + (nl_.partner.size() + nl_.count.size() + bl_.wall.size() + bl_.count.size()) * sizeof(Index) +
               cells_.memory_bytes();
    }

private:
    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < nw_; ++w) {
            const Vec3d p = walls_[w].point_at(step, dt_);
            for (int c = 0; c < 3; ++c) wp_[3 * w + c] = T(component(p, c));
        }
    }

    std::size_t n_ = 0, nw_ = 0;
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    T cell_ = T(0);
    GearCoefficients<T> gear_;
    ContactParams<T> params_;
    Vec3<T> g_;
    std::vector<Wall> walls_;
    std::vector<T> x_, v_, a_, b3_, b4_, b5_, th_, w_, al_, r3_, r4_, r5_;  // (N, 3) each
    std::vector<T> f_, t_, acc_, alc_;                                      // (N, 3) each
    std::vector<T> r_, m_, I_;                                              // (N)
    std::vector<T> wp_, wn_, wv_;                                           // (3, walls)
    NeighbourList nl_;
    BoundaryList bl_;
    LinkedCells cells_;
    std::int64_t pp_ = 0, pw_ = 0, candidates_ = 0;
};

} // namespace

void register_variant_arrays(Registry& r)
{
    r.add({"arrays", "plain arrays, procedural, Fortran-90 style (the paper's DEMMAT_F90)",
           [] { return std::make_unique<ArraysVariant<double, FullModel>>(); }});
}

} // namespace demmat
