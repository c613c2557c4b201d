#pragma once
// The object-oriented processor, the paper's DEMMAT_CPP: every particle is an object that holds all of
// its own state and predicts and corrects itself, every wall is a plane object, and contacts are
// resolved through the objects, each particle holding pointers to its neighbours. Under a contact law
// with memory (physics.md §9) each neighbour is a contact object that owns its springs (contacts.hpp).
// Instantiated in oop.cpp (the paper's law) and oop_laws.cpp (the laws of §9).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bodies.hpp"
#include "demmat/registry.hpp"
#include "neighbour_search.hpp"

namespace demmat::oop {

// M: the model (model.hpp): the paper's full model, or the full model with a §9 law's flags.
template <class M>
class Assembly final : public Variant {
    using SphericalParticle = oop::SphericalParticle<M>;
    using Plane = oop::Plane<M>;

public:
    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        step_ = s.step;
        dt_ = scene.dt;
        gear_ = setup.gear;
        law_ = {setup.contact, setup.memory};
        gravity_ = scene.gravity;

        particles_.clear();
        particles_.reserve(s.size());  // never grows afterwards: neighbour pointers stay valid
        for (std::size_t i = 0; i < s.size(); ++i)
            particles_.emplace_back(std::int32_t(i), s.radius[i], setup.mass[i], setup.inertia[i], GearVector(s.trans, i),
                                    GearVector(s.rot, i));

        planes_.clear();
        planes_.reserve(s.walls.size());
        for (const Wall& w : s.walls) planes_.emplace_back(w);
        for (Plane& plane : planes_) plane.move_to(step_, dt_);

        if (setup.cell_size > 0.0) search_ = std::make_unique<CellSearch<M>>(setup.cell_size);
        else search_ = std::make_unique<AllPairsSearch<M>>();
        tally_ = {};
        candidates_ = 0;
        if constexpr (M::memory)  // the contacts of a saved state, with their springs (none at a fresh start)
            for (const ContactStretch& c : s.stretches) {
                SphericalParticle& p = particles_[std::size_t(c.i)];
                const Stretch<double> springs{c.tangential, c.rolling};
                if (c.wall) p.restore_boundary(&planes_[std::size_t(c.partner)], springs);
                else p.restore_neighbour(&particles_[std::size_t(c.partner)], springs);
            }
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        for (SphericalParticle& p : particles_) p.predict(gear_);
        for (Plane& plane : planes_) plane.move_to(step, dt_);
    }

    void search() override
    {
        candidates_ = search_->update(particles_);
        for (SphericalParticle& p : particles_) {
            p.clear_boundary();
            for (Plane& plane : planes_)
                if (plane.near(p)) p.add_boundary(&plane);
            p.remember();
        }
    }

    void forces() override
    {
        for (SphericalParticle& p : particles_) p.reset_loads();
        tally_ = {};
        for (SphericalParticle& p : particles_) {  // id order: the canonical summation order
            const ContactTally t = p.resolve_contacts(law_);
            tally_.particle += t.particle;
            tally_.wall += t.wall;
        }
        for (SphericalParticle& p : particles_) p.apply_newton(gravity_);
    }

    void correct() override
    {
        for (SphericalParticle& p : particles_) p.correct(gear_);
    }

    void snapshot(Snapshot& out) const override
    {
        out.resize(particles_.size());
        out.step = step_;
        for (const SphericalParticle& p : particles_) {
            const auto i = std::size_t(p.id());
            out.position[i] = p.position();
            out.velocity[i] = p.velocity();
            out.angular_velocity[i] = p.angular_velocity();
            out.force[i] = p.force();
            out.torque[i] = p.torque();
        }
    }

    void save(State& out) const override
    {
        out.resize(particles_.size());
        out.step = step_;
        out.walls.clear();
        for (const Plane& plane : planes_) out.walls.push_back(plane.description());
        for (const SphericalParticle& p : particles_) {
            const auto i = std::size_t(p.id());
            out.radius[i] = p.radius();
            p.translation().store(out.trans, i);
            p.rotation().store(out.rot, i);
        }
        out.stretches.clear();
        if constexpr (M::memory)  // particles in id order, each its partners ascending, then its walls: the canonical order
            for (const SphericalParticle& p : particles_) {
                for (const PairContact<M>& c : p.neighbours())
                    if (c.springs.live) out.stretches.push_back({p.id(), c.partner->id(), false, c.springs.stretch.t, c.springs.stretch.r});
                for (const WallContact<M>& c : p.boundary())
                    if (c.springs.live) out.stretches.push_back({p.id(), wall_index(c.wall), true, c.springs.stretch.t, c.springs.stretch.r});
            }
    }

    ContactCounts counts() const override { return {tally_.particle, tally_.wall, candidates_}; }
    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

    std::size_t memory_bytes() const override
    {
        std::size_t bytes = particles_.capacity() * sizeof(SphericalParticle) + planes_.capacity() * sizeof(Plane);
        for (const SphericalParticle& p : particles_) bytes += p.heap_bytes();
        return bytes + (search_ ? search_->memory_bytes() : 0);
    }

private:
    std::int64_t wall_index(const Body<M>* wall) const
    {
        const auto it = std::find_if(planes_.begin(), planes_.end(), [&](const Plane& p) { return &p == wall; });
        return it - planes_.begin();
    }

    std::int64_t step_ = 0;
    double dt_ = 0.0;
    Gear gear_;
    Law law_;
    Vec3d gravity_;
    std::vector<SphericalParticle> particles_;  // in id order
    std::vector<Plane> planes_;                 // in wall order
    std::unique_ptr<NeighbourSearch<M>> search_;
    ContactTally tally_;
    std::int64_t candidates_ = 0;
};

// The instantiation for a scene with a §9 law (oop_laws.cpp).
std::unique_ptr<Variant> pick_oop_law(const Setup& setup);

} // namespace demmat::oop
