#pragma once
// The bodies of the object-oriented processor: a spherical particle that holds all of its own state
// and integrates itself, and a plane wall. Both are Bodies, the things a sphere can collide with
// (the paper treats walls "as particles with infinite radius and mass"); a contact is resolved by the
// body, through the shared contact law. Every class is a template on the model M (model.hpp): the paper's
// law runs the full model, a law of physics.md §9 the full model with its flags.
//
// Under a law with memory a contact remembers its springs (contacts.hpp): a particle's neighbour is a
// PairContact that owns the springs between the two, and when the search rebuilds the neighbour list
// each new contact takes the springs of the old one with the same partner, found by the partner's id.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "contacts.hpp"
#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/gear.hpp"
#include "demmat/model.hpp"
#include "demmat/scene.hpp"
#include "demmat/state.hpp"
#include "demmat/vec3.hpp"

namespace demmat::oop {

using Gear = GearCoefficients<double>;

// The constants of the contact law: the paper's, and those of a §9 law (zero for the paper's).
struct Law {
    ContactParams<double> contact;
    MemoryParams<double> memory;
};

template <class M>
class SphericalParticle;

// Something a sphere can collide with.
template <class M>
class Body {
public:
    virtual ~Body() = default;

    // Conservative pre-test for the contact search: true whenever the contact law can find `sphere` in
    // contact with this body (and for a few pairs it will reject).
    virtual bool near(const SphericalParticle<M>& sphere) const = 0;
    // Resolves the contact between this body and `sphere` through the shared law and applies the loads
    // to both. For two spheres this body is the one with the lower id. False when they do not touch.
    // The paper's law:
    virtual bool interact(SphericalParticle<M>& sphere, const Law& law) = 0;
    // A law of physics.md §9, with the contact's springs, which a live contact advances and an open one forgets:
    virtual bool interact(SphericalParticle<M>& sphere, const Law& law, Springs<M>& springs) = 0;

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

template <class M>
class SphericalParticle final : public Body<M> {
    using Model = M;

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
        if constexpr (beyond_paper<M>) {
            Springs<M> none{};
            return interact(other, law, none);
        } else {
            ContactForce<double> c;
            if (!particle_contact<Model>(position(), other.position(), velocity(), other.velocity(), angular_velocity(),
                                         other.angular_velocity(), radius_, other.radius_, mass_, other.mass_, law.contact, c))
                return false;
            add_load(c.f_i, c.t_i);
            other.add_load(-c.f_i, c.t_j);
            return true;
        }
    }

    bool interact(SphericalParticle& other, const Law& law, Springs<M>& springs) override
    {
        if constexpr (!beyond_paper<M>) {
            return interact(other, law);
        } else {
            ContactForce<double> c;
            Stretch<double> scratch;
            const bool touch = particle_contact_memory<Model>(position(), other.position(), velocity(), other.velocity(),
                                                              angular_velocity(), other.angular_velocity(), radius_, other.radius_,
                                                              mass_, other.mass_, law.contact, law.memory,
                                                              springs.stretch_or(scratch), true, c);
            springs.note(touch);
            if (!touch) return false;
            add_load(c.f_i, c.t_i);
            other.add_load(-c.f_i, c.t_j);
            return true;
        }
    }

    // Resolves this particle's contacts with its neighbours (higher ids, ascending) and then with the
    // walls near it (in wall order). Called for the particles in id order, this sums every particle's
    // loads in the canonical order (physics.md §6).
    ContactTally resolve_contacts(const Law& law)
    {
        ContactTally tally;
        if constexpr (M::memory) {
            for (PairContact<M>& c : neighbours_) tally.particle += interact(*c.partner, law, c.springs);
            for (WallContact<M>& c : boundary_) tally.wall += c.wall->interact(*this, law, c.springs);
        } else {
            for (SphericalParticle* other : neighbours_) tally.particle += interact(*other, law);
            for (Body<M>* wall : boundary_) tally.wall += wall->interact(*this, law);
        }
        return tally;
    }

    // ---- neighbour lists, rebuilt by the contact search ------------------------------------------------
    // Under a law with memory the lists of the last step are kept aside while the new ones are built, and
    // remember() then hands each persisting contact its springs (a no-op for a law without memory).
    const std::vector<Neighbour<M>>& neighbours() const { return neighbours_; }
    const std::vector<WallNeighbour<M>>& boundary() const { return boundary_; }
    void clear_neighbours()
    {
        if constexpr (M::memory) previous_.neighbours.swap(neighbours_);
        neighbours_.clear();
    }
    void add_neighbour(SphericalParticle* other)
    {
        if constexpr (M::memory) neighbours_.push_back({other, {}});
        else neighbours_.push_back(other);
    }
    void sort_neighbours()
    {
        std::sort(neighbours_.begin(), neighbours_.end(),
                  [](const Neighbour<M>& a, const Neighbour<M>& b) { return partner_of(a)->id() < partner_of(b)->id(); });
    }
    void clear_boundary()
    {
        if constexpr (M::memory) previous_.boundary.swap(boundary_);
        boundary_.clear();
    }
    void add_boundary(Body<M>* wall)
    {
        if constexpr (M::memory) boundary_.push_back({wall, {}});
        else boundary_.push_back(wall);
    }
    // Called once the neighbours (sorted) and the boundary are complete.
    void remember()
    {
        if constexpr (M::memory) {
            recall_springs(previous_.neighbours, neighbours_);
            recall_springs(previous_.boundary, boundary_);
        }
    }
    // The springs a saved state gives a contact (before the first search, which keeps them if it finds the
    // contact again).
    void restore_neighbour(SphericalParticle* other, const Stretch<double>& s) { neighbours_.push_back({other, {s, true}}); }
    void restore_boundary(Body<M>* wall, const Stretch<double>& s) { boundary_.push_back({wall, {s, true}}); }

    std::size_t heap_bytes() const
    {
        std::size_t lists = neighbours_.capacity() * sizeof(Neighbour<M>) + boundary_.capacity() * sizeof(WallNeighbour<M>);
        if constexpr (M::memory)
            lists += previous_.neighbours.capacity() * sizeof(Neighbour<M>) + previous_.boundary.capacity() * sizeof(WallNeighbour<M>);
        return lists;
    }

private:
    std::int32_t id_;
    double radius_, mass_, inertia_;
    GearVector translation_;  // position, velocity, acceleration, b3, b4, b5
    GearVector rotation_;     // orientation, angular velocity, angular acceleration, b3, b4, b5
    Vec3d force_, torque_;
    Vec3d acceleration_, angular_acceleration_;     // from this step's loads, for the corrector
    std::vector<Neighbour<M>> neighbours_;          // candidate partners with a higher id, ascending
    std::vector<WallNeighbour<M>> boundary_;        // walls it may touch, in wall order
    // Under a law with memory, the last step's lists while the search builds the new ones; nothing otherwise.
    struct NoLists {};
    struct Lists {
        std::vector<Neighbour<M>> neighbours;
        std::vector<WallNeighbour<M>> boundary;
    };
    [[no_unique_address]] std::conditional_t<M::memory, Lists, NoLists> previous_;
};

// A plane wall through a point with a unit normal into the domain, possibly moving at a constant
// velocity; its point for a step is computed from the step count (Wall::point_at), so it never drifts.
template <class M>
class Plane final : public Body<M> {
    using Model = M;

public:
    explicit Plane(const Wall& wall) : wall_(wall), point_(wall.point), normal_(wall.normal), velocity_(wall.velocity) {}

    const Wall& description() const { return wall_; }
    const Vec3d& point() const { return point_; }

    void move_to(std::int64_t step, double dt) { point_ = wall_.point_at(step, dt); }

    bool near(const SphericalParticle<M>& sphere) const override
    {
        return may_touch_wall(sphere.position(), sphere.radius(), point_, normal_);
    }

    bool interact(SphericalParticle<M>& sphere, const Law& law) override
    {
        if constexpr (beyond_paper<M>) {
            Springs<M> none{};
            return interact(sphere, law, none);
        } else {
            ContactForce<double> c;
            if (!wall_contact<Model>(sphere.position(), sphere.velocity(), sphere.angular_velocity(), sphere.radius(), sphere.mass(),
                                     point_, normal_, velocity_, law.contact, c))
                return false;
            sphere.add_load(c.f_i, c.t_i);
            return true;
        }
    }

    bool interact(SphericalParticle<M>& sphere, const Law& law, Springs<M>& springs) override
    {
        if constexpr (!beyond_paper<M>) {
            return interact(sphere, law);
        } else {
            ContactForce<double> c;
            Stretch<double> scratch;
            const bool touch = wall_contact_memory<Model>(sphere.position(), sphere.velocity(), sphere.angular_velocity(),
                                                          sphere.radius(), sphere.mass(), point_, normal_, velocity_, law.contact,
                                                          law.memory, springs.stretch_or(scratch), true, c);
            springs.note(touch);
            if (!touch) return false;
            sphere.add_load(c.f_i, c.t_i);
            return true;
        }
    }

private:
    Wall wall_;  // as given (reference point and step), for saving
    Vec3d point_, normal_, velocity_;
};

} // namespace demmat::oop
