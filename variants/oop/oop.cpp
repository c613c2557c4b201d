// The pure object-oriented processor, the paper's DEMMAT_CPP: every particle is an object that holds
// all of its own state and predicts and corrects itself, every wall is a plane object, and contacts
// are resolved through the objects, each particle holding pointers to its neighbours.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bodies.hpp"
#include "demmat/registry.hpp"
#include "neighbour_search.hpp"

namespace demmat {
namespace oop {
namespace {

class Assembly final : public Variant {
public:
    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        step_ = s.step;
        dt_ = scene.dt;
        gear_ = setup.gear;
        law_ = setup.contact;
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

        if (setup.cell_size > 0.0) search_ = std::make_unique<CellSearch>(setup.cell_size);
        else search_ = std::make_unique<AllPairsSearch>();
        tally_ = {};
        candidates_ = 0;
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
    }

    ContactCounts counts() const override { return {tally_.particle, tally_.wall, candidates_}; }

    std::size_t memory_bytes() const override
    {
        std::size_t bytes = particles_.capacity() * sizeof(SphericalParticle) + planes_.capacity() * sizeof(Plane);
        for (const SphericalParticle& p : particles_) bytes += p.heap_bytes();
        return bytes + (search_ ? search_->memory_bytes() : 0);
    }

private:
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    Gear gear_;
    Law law_;
    Vec3d gravity_;
    std::vector<SphericalParticle> particles_;  // in id order
    std::vector<Plane> planes_;                 // in wall order
    std::unique_ptr<NeighbourSearch> search_;
    ContactTally tally_;
    std::int64_t candidates_ = 0;
};

} // namespace
} // namespace oop

void register_variant_oop(Registry& r)
{
    r.add({"oop", "pure object-oriented: particle and plane objects, pointer neighbour lists (the paper's DEMMAT_CPP)",
           [] { return std::make_unique<oop::Assembly>(); }});
}

} // namespace demmat
