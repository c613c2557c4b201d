#pragma once
// The bodies of the object-oriented processor: a spherical particle that holds all of its own state
// and integrates itself, and a plane wall. Both are Bodies, the things a sphere can collide with
// (the paper treats walls "as particles with infinite radius and mass"); a contact is resolved by the
// body, through the shared contact law.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/gear.hpp"
#include "demmat/model.hpp"
#include "demmat/scene.hpp"
#include "demmat/state.hpp"
#include "demmat/vec3.hpp"

namespace demmat::oop {

using Model = FullModel;
using Law = ContactParams<double>;
using Gear = GearCoefficients<double>;

class SphericalParticle;

// Something a sphere can collide with.
class Body {
public:
    virtual ~Body() = default;

    // Conservative pre-test for the contact search: true whenever the contact law can find `sphere` in
    // contact with this body (and for a few pairs it will reject).
    virtual bool near(const SphericalParticle& sphere) const = 0;
    // Resolves the contact between this body and `sphere` through the shared law and applies the loads
    // to both. For two spheres this body is the one with the lower id. False when they do not touch.
    virtual bool interact(SphericalParticle& sphere, const Law& law) = 0;

protected:
    Body() = default;
    Body(const Body&) = default;
    Body(Body&&) = default;
    Body& operator=(const Body&) = default;
    Body& operator=(Body&&) = default;
};

// One vector degree of freedom (position or orientation) in the 5th-order Gear scheme: the value, its
// first and second derivatives and the three scaled higher derivatives.
struct GearVector {
    Vec3d x, v, a, b3, b4, b5;

    GearVector() = default;
    GearVector(const GearState& s, std::size_t i) : x(s.x[i]), v(s.v[i]), a(s.a[i]), b3(s.b3[i]), b4(s.b4[i]), b5(s.b5[i]) {}

    void predict(const Gear& k) { gear_predict(x, v, a, b3, b4, b5, k); }
    void correct(const Vec3d& a_new, const Gear& k)
    {
        const Vec3d da = a_new - a;
        gear_correct(x, v, a, b3, b4, b5, da, k);
    }
    void store(GearState& s, std::size_t i) const
    {
        s.x[i] = x; s.v[i] = v; s.a[i] = a;
        s.b3[i] = b3; s.b4[i] = b4; s.b5[i] = b5;
    }
};

// How many contacts one particle resolved (with h > 0).
struct ContactTally {
    std::int64_t particle = 0;
    std::int64_t wall = 0;
};

class SphericalParticle final : public Body {
public:
    SphericalParticle(std::int32_t id, double radius, double mass, double inertia, const GearVector& translation,
                      const GearVector& rotation)
        : id_(id), radius_(radius), mass_(mass), inertia_(inertia), translation_(translation), rotation_(rotation)
    {
    }

    std::int32_t id() const { return id_; }
    double radius() const { return radius_; }
    double mass() const { return mass_; }
    double inertia() const { return inertia_; }
    const Vec3d& position() const { return translation_.x; }
    const Vec3d& velocity() const { return translation_.v; }
    const Vec3d& angular_velocity() const { return rotation_.v; }
    const Vec3d& force() const { return force_; }
    const Vec3d& torque() const { return torque_; }
    const GearVector& translation() const { return translation_; }
    const GearVector& rotation() const { return rotation_; }

    // ---- integration -------------------------------------------------------------------------------
    void predict(const Gear& k)
    {
        translation_.predict(k);
        if constexpr (Model::rotation) rotation_.predict(k);
    }

    void reset_loads()
    {
        force_ = Vec3d{};
        torque_ = Vec3d{};
    }

    void add_load(const Vec3d& f, const Vec3d& t)
    {
        force_ += f;
        if constexpr (Model::rotation) torque_ += t;
    }

    // Newton's second law with gravity: a = F/m + g, α = T/I.
    void apply_newton(const Vec3d& gravity)
    {
        acceleration_ = {acceleration(force_.x, mass_, gravity.x), acceleration(force_.y, mass_, gravity.y),
                         acceleration(force_.z, mass_, gravity.z)};
        if constexpr (Model::rotation) angular_acceleration_ = torque_ / inertia_;
    }

    void correct(const Gear& k)
    {
        translation_.correct(acceleration_, k);
        if constexpr (Model::rotation) rotation_.correct(angular_acceleration_, k);
    }

    // ---- contacts ----------------------------------------------------------------------------------
    bool near(const SphericalParticle& other) const override
    {
        return may_touch(position(), other.position(), radius_, other.radius_);
    }

    bool interact(SphericalParticle& other, const Law& law) override
    {
        ContactForce<double> c;
        if (!particle_contact<Model>(position(), other.position(), velocity(), other.velocity(), angular_velocity(),
                                     other.angular_velocity(), radius_, other.radius_, mass_, other.mass_, law, c))
            return false;
        add_load(c.f_i, c.t_i);
        other.add_load(-c.f_i, c.t_j);
        return true;
    }

    // Resolves this particle's contacts with its neighbours (higher ids, ascending) and then with the
    // walls near it (in wall order). Called for the particles in id order, this sums every particle's
    // loads in the canonical order (physics.md §6).
    ContactTally resolve_contacts(const Law& law)
    {
        ContactTally tally;
        for (SphericalParticle* other : neighbours_) tally.particle += interact(*other, law);
        for (Body* wall : boundary_) tally.wall += wall->interact(*this, law);
        return tally;
    }

    // ---- neighbour lists, rebuilt by the contact search ------------------------------------------------
    const std::vector<SphericalParticle*>& neighbours() const { return neighbours_; }
    const std::vector<Body*>& boundary() const { return boundary_; }
    void clear_neighbours() { neighbours_.clear(); }
    void add_neighbour(SphericalParticle* other) { neighbours_.push_back(other); }
    void sort_neighbours()
    {
        std::sort(neighbours_.begin(), neighbours_.end(),
                  [](const SphericalParticle* a, const SphericalParticle* b) { return a->id() < b->id(); });
    }
    void clear_boundary() { boundary_.clear(); }
    void add_boundary(Body* wall) { boundary_.push_back(wall); }

    std::size_t heap_bytes() const
    {
        return neighbours_.capacity() * sizeof(SphericalParticle*) + boundary_.capacity() * sizeof(Body*);
    }

private:
    std::int32_t id_;
    double radius_, mass_, inertia_;
    GearVector translation_;  // position, velocity, acceleration, b3, b4, b5
    GearVector rotation_;     // orientation, angular velocity, angular acceleration, b3, b4, b5
    Vec3d force_, torque_;
    Vec3d acceleration_, angular_acceleration_;     // from this step's loads, for the corrector
    std::vector<SphericalParticle*> neighbours_;    // candidate partners with a higher id, ascending
    std::vector<Body*> boundary_;                   // walls it may touch, in wall order
};

// A plane wall through a point with a unit normal into the domain, possibly moving at a constant
// velocity; its point for a step is computed from the step count (Wall::point_at), so it never drifts.
class Plane final : public Body {
public:
    explicit Plane(const Wall& wall) : wall_(wall), point_(wall.point), normal_(wall.normal), velocity_(wall.velocity) {}

    const Wall& description() const { return wall_; }
    const Vec3d& point() const { return point_; }

    void move_to(std::int64_t step, double dt) { point_ = wall_.point_at(step, dt); }

    bool near(const SphericalParticle& sphere) const override
    {
        return may_touch_wall(sphere.position(), sphere.radius(), point_, normal_);
    }

    bool interact(SphericalParticle& sphere, const Law& law) override
    {
        ContactForce<double> c;
        if (!wall_contact<Model>(sphere.position(), sphere.velocity(), sphere.angular_velocity(), sphere.radius(), sphere.mass(),
                                 point_, normal_, velocity_, law, c))
            return false;
        sphere.add_load(c.f_i, c.t_i);
        return true;
    }

private:
    Wall wall_;  // as given (reference point and step), for saving
    Vec3d point_, normal_, velocity_;
};

} // namespace demmat::oop
