// The Fortran 90 port of the arrays processor (the paper's DEMMAT_F90), demmat_f90.f90, driven through
// its bind(C) entry points. This class only moves data across the language boundary and turns the
// Fortran status codes into the exceptions (and messages) of the arrays variant.
#include <cstdint>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"
#include "demmat/variant.hpp"

extern "C" {
void* demmat_f90_create();
void demmat_f90_destroy(void* h);
void demmat_f90_init(void* h, int n, int nw, int cap, int wcap, double cell, const double* radius, const double* mass,
                     const double* inertia, const double* gear, const double* wn, const double* wv, const double* grav,
                     const double* coef, const double* contact);
void demmat_f90_set_walls(void* h, const double* wp);
void demmat_f90_predict(void* h, const double* wp);
void demmat_f90_search(void* h, int* status, std::int64_t* info, std::int64_t* particle);
void demmat_f90_forces(void* h);
void demmat_f90_correct(void* h);
void demmat_f90_get(void* h, int which, double* out);
void demmat_f90_counts(void* h, std::int64_t* out);
}

namespace demmat {
namespace {

class F90Variant final : public Variant {
public:
    F90Variant() : h_(demmat_f90_create()) {}
    ~F90Variant() override { demmat_f90_destroy(h_); }
    F90Variant(const F90Variant&) = delete;
    F90Variant& operator=(const F90Variant&) = delete;

    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = s.size();
        step_ = s.step;
        dt_ = scene.dt;
        walls_ = s.walls;
        cap_ = scene.capacity.contacts_per_particle;
        wcap_ = scene.capacity.wall_contacts_per_particle;
        const std::vector<Vec3d>* src[12] = {&s.trans.x, &s.trans.v, &s.trans.a, &s.trans.b3, &s.trans.b4, &s.trans.b5,
                                             &s.rot.x,   &s.rot.v,   &s.rot.a,   &s.rot.b3,   &s.rot.b4,   &s.rot.b5};
        std::vector<double> gear(12 * 3 * n_);  // (N, 3, 12) column-major
        for (int k = 0; k < 12; ++k)
            for (int c = 0; c < 3; ++c)
                for (std::size_t i = 0; i < n_; ++i) gear[(k * 3 + c) * n_ + i] = component((*src[k])[i], c);
        const std::size_t nw = walls_.size();
        std::vector<double> wn(3 * nw), wv(3 * nw);
        for (std::size_t w = 0; w < nw; ++w)
            for (int c = 0; c < 3; ++c) {
                wn[3 * w + c] = component(walls_[w].normal, c);
                wv[3 * w + c] = component(walls_[w].velocity, c);
            }
        const GearCoefficients<double>& k = setup.gear;
        const double coef[8] = {k.dt, k.half_dt2, k.two_over_dt2, k.cx, k.cv, k.c3, k.c4, k.c5};
        const ContactParams<double>& p = setup.contact;
        const double contact[5] = {p.hertz_pp, p.hertz_pw, p.gamma_n, p.gamma_t, p.mu};
        const double grav[3] = {scene.gravity.x, scene.gravity.y, scene.gravity.z};
        demmat_f90_init(h_, int(n_), int(nw), cap_, wcap_, setup.cell_size, s.radius.data(), setup.mass.data(),
                        setup.inertia.data(), gear.data(), wn.data(), wv.data(), grav, coef, contact);
        radius_ = s.radius;
        demmat_f90_set_walls(h_, wall_points(step_).data());
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        demmat_f90_predict(h_, wall_points(step).data());
    }

    void search() override
    {
        int status = 0;
        std::int64_t info = 0, particle = -1;
        demmat_f90_search(h_, &status, &info, &particle);
        switch (status) {
        case 0: return;
        case 1:
            throw CapacityError(fmt::format("capacity.contacts_per_particle = {} exceeded: particle {} has {} candidate "
                                            "partners; set it to at least {} in the scene", cap_, particle, info, info));
        case 2:
            throw CapacityError(fmt::format("capacity.wall_contacts_per_particle = {} exceeded: particle {} touches more "
                                            "walls; set it to {} (the number of walls)", wcap_, particle, walls_.size()));
        default:
            throw InstabilityError(fmt::format("particle {} has a non-finite or runaway position (found by the cell search)", particle),
                                   -1, particle);
        }
    }

    void forces() override { demmat_f90_forces(h_); }
    void correct() override { demmat_f90_correct(h_); }

    void snapshot(Snapshot& out) const override
    {
        out.resize(n_);
        out.step = step_;
        std::vector<Vec3d>* dst[5] = {&out.position, &out.velocity, &out.angular_velocity, &out.force, &out.torque};
        const int which[5] = {1, 2, 8, 13, 14};
        for (int k = 0; k < 5; ++k) fetch(which[k], *dst[k]);
    }

    void save(State& out) const override
    {
        out.resize(n_);
        out.step = step_;
        out.walls = walls_;
        std::vector<Vec3d>* dst[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                       &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int k = 0; k < 12; ++k) fetch(k + 1, *dst[k]);
        for (std::size_t i = 0; i < n_; ++i) out.radius[i] = radius_[i];
    }

    ContactCounts counts() const override
    {
        std::int64_t c[4];
        demmat_f90_counts(h_, c);
        return {c[0], c[1], c[2]};
    }

    std::size_t memory_bytes() const override
    {
        std::int64_t c[4];
        demmat_f90_counts(h_, c);
        return std::size_t(c[3]);
    }

private:
    std::vector<double> wall_points(std::int64_t step) const
    {
        std::vector<double> wp(3 * walls_.size() + 3);
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            const Vec3d p = walls_[w].point_at(step, dt_);
            for (int c = 0; c < 3; ++c) wp[3 * w + c] = component(p, c);
        }
        return wp;
    }

    void fetch(int which, std::vector<Vec3d>& dst) const
    {
        buf_.resize(3 * n_ + 1);
        demmat_f90_get(h_, which, buf_.data());
        dst.resize(n_);
        for (std::size_t i = 0; i < n_; ++i) dst[i] = {buf_[i], buf_[n_ + i], buf_[2 * n_ + i]};
    }

    void* h_ = nullptr;
    std::size_t n_ = 0;
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    int cap_ = 0, wcap_ = 0;
    std::vector<Wall> walls_;
    std::vector<double> radius_;
    mutable std::vector<double> buf_;
};

} // namespace

void register_variant_f90(Registry& r)
{
    r.add({"f90", "Fortran 90 port of the arrays processor (the paper's DEMMAT_F90), driven through bind(C)",
           [] { return std::make_unique<F90Variant>(); }});
}

} // namespace demmat
