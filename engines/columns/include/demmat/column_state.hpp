#pragma once
// The particles' state of the arrays variant, the paper's DEMMAT_F90 layout: flat arrays of shape
// (N, 3) stored column by column (x(i, c) at x[c·N + i], as Fortran stores them), the walls, and the
// four phases' work on them that does not depend on the contact store: loading from Setup, the Gear
// predictor and corrector, accumulating one contact's force and torque, and Newton's law. The arrays
// variant and the linked-list variants are both a ColumnStateVariant (below), so a comparison of them
// isolates the contact store.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/gear.hpp"
#include "demmat/integrators.hpp"
#include "demmat/variant.hpp"

namespace demmat {

// ---- predictor and corrector: one loop over all 3N components --------------------------------------
// S is the integrator (integrators.hpp; Gear5Scheme is the paper's gear_predict/gear_correct).

// The six arrays never alias (Fortran assumes as much of its dummy arguments); __restrict says so, and
// lets the compiler vectorise these loops (the element-wise operations, and so the bits, are the same).
template <class S, class T, class K>
void predictor(std::size_t n3, T* __restrict x, T* __restrict v, T* __restrict a, T* __restrict b3, T* __restrict b4,
               const T* __restrict b5, const K& k)
{
    for (std::size_t e = 0; e < n3; ++e) S::predict(x[e], v[e], a[e], b3[e], b4[e], b5[e], k);
}

template <class S, class T, class K>
void corrector(std::size_t n3, T* __restrict x, T* __restrict v, T* __restrict a, T* __restrict b3, T* __restrict b4,
               T* __restrict b5, const T* __restrict a_new, const K& k)
{
    for (std::size_t e = 0; e < n3; ++e) S::correct(x[e], v[e], a[e], b3[e], b4[e], b5[e], a_new[e], k);
}

// Row i of an (N, 3) column-major array.
template <class T>
Vec3<T> get(const T* a, std::size_t n, std::size_t i) { return {a[i], a[n + i], a[2 * n + i]}; }
template <class T>
void add(T* a, std::size_t n, std::size_t i, const Vec3<T>& v)
{
    a[i] += v.x;
    a[n + i] += v.y;
    a[2 * n + i] += v.z;
}

// ---- the state -------------------------------------------------------------------------------------

// Forces and torques are summed in the canonical order of physics.md §6 when the caller does: zero_loads(),
// then pair(i, j) for the pairs in ascending (i, j), then wall(i, w) in wall order, then newton().
// T is the value type (double or float), M the model (model.hpp), S the integrator (integrators.hpp).
template <class T, class M, class S = Gear5Scheme>
class ColumnState {
public:
    void load(const Setup& setup)
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = s.size();
        step_ = s.step;
        coef_ = SchemeCoefficients::make(scene.dt);
        params_ = setup.contact.template as<T>();
        memory_ = setup.memory.template as<T>();
        g_ = cast<T>(scene.gravity);
        walls_ = s.walls;
        dt_ = scene.dt;
        load_gear_columns<T>(s, {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_});
        for (auto* arr : {&f_, &t_, &acc_, &alc_}) arr->assign(3 * n_, T(0));
        r_.resize(n_); m_.resize(n_); I_.resize(n_);
        radius_ = s.radius;
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
        if constexpr (!M::polydisperse)  // one radius and mass: the contacts' coefficients once per run
            if (n_ > 0) {
                mono_pp_ = pair_coefficients(r_[0], r_[0], m_[0], m_[0], params_);
                mono_pw_ = wall_coefficients(r_[0], m_[0], params_);
            }
    }

    std::size_t size() const { return n_; }
    std::size_t wall_count() const { return nw_; }
    const T* x() const { return x_.data(); }  // positions, (N, 3)
    const T* r() const { return r_.data(); }  // radii, (N)
    Vec3<T> wall_point(std::size_t w) const { return {wp_[3 * w], wp_[3 * w + 1], wp_[3 * w + 2]}; }
    Vec3<T> wall_normal(std::size_t w) const { return {wn_[3 * w], wn_[3 * w + 1], wn_[3 * w + 2]}; }

    void predict(std::int64_t step)
    {
        step_ = step;
        predictor<S>(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), coef_);
        if constexpr (M::rotation)
            predictor<S>(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), coef_);
        if constexpr (M::moving_walls) place_walls(step);  // fixed walls stay where load() put them
    }

    void zero_loads()
    {
        std::fill(f_.begin(), f_.end(), T(0));
        std::fill(t_.begin(), t_.end(), T(0));
    }

    // The contact of particles i < j, if any, added to both: f_j = -f_i, and the torque of each.
    bool pair(std::size_t i, std::size_t j)
    {
        if constexpr (law) {  // a §9 law without memory (restitution damping alone): no stretch to carry
            Stretch<T> none;
            return pair(i, j, none);
        }
        const std::size_t n = n_;
        ContactForce<T> c;
        if (!particle_contact<M>(get(x_.data(), n, i), get(x_.data(), n, j), get(v_.data(), n, i), get(v_.data(), n, j),
                                 get(w_.data(), n, i), get(w_.data(), n, j), r_[i], r_[j], m_[i], m_[j], params_, mono_pp_, c))
            return false;
        add_pair(i, j, c);
        return true;
    }
    // The same under a §9 law (contact_memory.hpp), with the pair's stretches `s` carried in and out.
    bool pair(std::size_t i, std::size_t j, Stretch<T>& s)
    {
        const std::size_t n = n_;
        ContactForce<T> c;
        if (!particle_contact_memory<M>(get(x_.data(), n, i), get(x_.data(), n, j), get(v_.data(), n, i), get(v_.data(), n, j),
                                        get(w_.data(), n, i), get(w_.data(), n, j), r_[i], r_[j], m_[i], m_[j], params_, memory_, s,
                                        true, c))
            return false;
        add_pair(i, j, c);
        return true;
    }

    // The contact of particle i with wall w, if any, added to i.
    bool wall(std::size_t i, std::size_t w)
    {
        if constexpr (law) {
            Stretch<T> none;
            return wall(i, w, none);
        }
        const std::size_t n = n_;
        ContactForce<T> c;
        if (!wall_contact<M>(get(x_.data(), n, i), get(v_.data(), n, i), get(w_.data(), n, i), r_[i], m_[i], wall_point(w),
                             wall_normal(w), wall_velocity(w), params_, mono_pw_, c))
            return false;
        add_wall(i, c);
        return true;
    }
    bool wall(std::size_t i, std::size_t w, Stretch<T>& s)
    {
        const std::size_t n = n_;
        ContactForce<T> c;
        if (!wall_contact_memory<M>(get(x_.data(), n, i), get(v_.data(), n, i), get(w_.data(), n, i), r_[i], m_[i], wall_point(w),
                                    wall_normal(w), wall_velocity(w), params_, memory_, s, true, c))
            return false;
        add_wall(i, c);
        return true;
    }

    // a = F/m + g, α = T/I.
    void newton()
    {
        const std::size_t n = n_;
        const T g[3] = {g_.x, g_.y, g_.z};
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < n; ++i) {
                acc_[c * n + i] = acceleration(f_[c * n + i], m_[i], g[c]);
                if constexpr (M::rotation) alc_[c * n + i] = t_[c * n + i] / I_[i];
            }
    }

    void correct()
    {
        corrector<S>(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), acc_.data(), coef_);
        if constexpr (M::rotation)
            corrector<S>(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), alc_.data(), coef_);
    }

    void snapshot(Snapshot& out) const
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

    void save(State& out) const
    {
        out.resize(n_);
        out.step = step_;
        out.walls = walls_;
        const std::vector<T>* src[12] = {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_};
        std::vector<Vec3d>* dst[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                       &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int k = 0; k < 12; ++k)
            for (std::size_t i = 0; i < n_; ++i) (*dst[k])[i] = cast<double>(get(src[k]->data(), n_, i));
        out.radius = radius_;  // the given radii, not r_ rounded to T: a continued run derives the same masses
    }

    std::size_t memory_bytes() const { return 19 * 3 * n_ * sizeof(T); }

private:
    static constexpr bool law = M::restitution_damping || M::history || M::rolling;  // a §9 law, not the paper's

    Vec3<T> wall_velocity(std::size_t w) const { return {wv_[3 * w], wv_[3 * w + 1], wv_[3 * w + 2]}; }
    void add_pair(std::size_t i, std::size_t j, const ContactForce<T>& c)
    {
        add(f_.data(), n_, i, c.f_i);
        add(f_.data(), n_, j, -c.f_i);
        if constexpr (M::rotation) {
            add(t_.data(), n_, i, c.t_i);
            add(t_.data(), n_, j, c.t_j);
        }
    }
    void add_wall(std::size_t i, const ContactForce<T>& c)
    {
        add(f_.data(), n_, i, c.f_i);
        if constexpr (M::rotation) add(t_.data(), n_, i, c.t_i);
    }

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
    using SchemeCoefficients = typename S::template Coefficients<T>;  // the integrator's per-run constants
    SchemeCoefficients coef_;
    ContactParams<T> params_;
    MemoryParams<T> memory_;  // the §9 law's constants (zero for the paper's law)
    Coefficients<T> mono_pp_, mono_pw_;  // monodisperse models: the one pair's and wall contact's coefficients
    Vec3<T> g_;
    std::vector<Wall> walls_;
    std::vector<T> x_, v_, a_, b3_, b4_, b5_, th_, w_, al_, r3_, r4_, r5_;  // (N, 3) each
    std::vector<T> f_, t_, acc_, alc_;                                      // (N, 3) each
    std::vector<T> r_, m_, I_;                                              // (N)
    std::vector<double> radius_;                                            // (N) as given, for save()
    std::vector<T> wp_, wn_, wv_;                                           // (3, walls)
};

// A variant over a ColumnState: the phases and queries that do not touch the contact store. A subclass
// adds the store: init (calling state_.load), search, forces (setting pp_, pw_, candidates_), memory_bytes.
template <class T, class M, class S = Gear5Scheme>
class ColumnStateVariant : public Variant {
public:
    void predict(std::int64_t step) override { state_.predict(step); }
    void correct() override { state_.correct(); }
    void snapshot(Snapshot& out) const override { state_.snapshot(out); }
    void save(State& out) const override { state_.save(out); }
    ContactCounts counts() const override { return {pp_, pw_, candidates_}; }
    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

protected:
    ColumnState<T, M, S> state_;
    std::int64_t pp_ = 0, pw_ = 0, candidates_ = 0;  // the last forces phase's contact counts
};

} // namespace demmat
