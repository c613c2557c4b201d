#pragma once
// The harness side of a variant written in another language (Fortran 90, Object Pascal): the port
// exposes C-compatible entry points over its own state, and this one class moves data across the
// language boundary and turns the port's status codes into the exceptions, with the messages, of the
// arrays variant. A port supplies its entry points as a PortApi; the physics stays in the port, which
// mirrors common/'s kernels operation for operation.
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/variant.hpp"

namespace demmat {

// The entry points of a port. init receives: n, walls, the two capacities, the cell edge (0: every
// pair), radius, mass, inertia (N each), the 12 Gear arrays as (N, 3, 12) column-major, wall normals and
// velocities (3 per wall), gravity (3), the Gear coefficients (dt, dt²/2, 2/dt², c0·dt²/2, c1·dt/2,
// c3·dt²/2, c4·dt²/2, c5·dt²/2, and the bound of the rule for negligible derivatives, gear.hpp) and the contact constants (hertz_pp, hertz_pw, γn, γt, μ, may_touch's
// margin). search reports status 0 (ok), 1 (pair capacity: info = the value that fits), 2 (wall
// capacity) or 3 (a runaway position), with the particle. get(which) writes an (N, 3) array: 1–12 the
// Gear arrays in State order, 13 force, 14 torque. counts writes particle–particle, particle–wall,
// candidates and bytes held.
template <class Handle>
struct PortApi {
    Handle (*create)();
    bool (*created)(Handle);
    std::string (*creation_error)();
    void (*destroy)(Handle);
    void (*init)(Handle, int n, int nw, int cap, int wcap, double cell, const double* radius, const double* mass,
                 const double* inertia, const double* gear, const double* wn, const double* wv, const double* grav,
                 const double* coef, const double* contact);
    void (*set_walls)(Handle, const double* wall_points);
    void (*predict)(Handle, const double* wall_points);
    void (*search)(Handle, int* status, std::int64_t* info, std::int64_t* particle);
    void (*forces)(Handle);
    void (*correct)(Handle);
    void (*get)(Handle, int which, double* out);
    void (*counts)(Handle, std::int64_t* out);
};

template <class Handle>
class PortVariant final : public Variant {
public:
    explicit PortVariant(const PortApi<Handle>& api) : api_(api), h_(api.create())
    {
        if (!api_.created(h_)) throw Error(api_.creation_error());
    }
    ~PortVariant() override { api_.destroy(h_); }
    PortVariant(const PortVariant&) = delete;
    PortVariant& operator=(const PortVariant&) = delete;

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
        const double coef[9] = {k.dt, k.half_dt2, k.two_over_dt2, k.cx, k.cv, k.c3, k.c4, k.c5, negligible_derivative<double>()};
        const ContactParams<double>& p = setup.contact;
        // The last entry is may_touch's margin, passed as a double so no port parses a decimal literal.
        const double contact[6] = {p.hertz_pp, p.hertz_pw, p.gamma_n, p.gamma_t, p.mu, kMayTouchMargin};
        const double grav[3] = {scene.gravity.x, scene.gravity.y, scene.gravity.z};
        api_.init(h_, int(n_), int(nw), cap_, wcap_, setup.cell_size, s.radius.data(), setup.mass.data(),
                        setup.inertia.data(), gear.data(), wn.data(), wv.data(), grav, coef, contact);
        radius_ = s.radius;
        api_.set_walls(h_, wall_points(step_).data());
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        api_.predict(h_, wall_points(step).data());
    }

    void search() override
    {
        int status = 0;
        std::int64_t info = 0, particle = -1;
        api_.search(h_, &status, &info, &particle);
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

    void forces() override { api_.forces(h_); }
    void correct() override { api_.correct(h_); }

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
        api_.counts(h_, c);
        return {c[0], c[1], c[2]};
    }

    std::size_t memory_bytes() const override
    {
        std::int64_t c[4];
        api_.counts(h_, c);
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
        api_.get(h_, which, buf_.data());
        dst.resize(n_);
        for (std::size_t i = 0; i < n_; ++i) dst[i] = {buf_[i], buf_[n_ + i], buf_[2 * n_ + i]};
    }

    const PortApi<Handle>& api_;
    Handle h_;
    std::size_t n_ = 0;
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    int cap_ = 0, wcap_ = 0;
    std::vector<Wall> walls_;
    std::vector<double> radius_;
    mutable std::vector<double> buf_;
};

} // namespace demmat
