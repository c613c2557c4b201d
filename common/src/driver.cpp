#include "demmat/driver.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/reference.hpp"
#include "demmat/registry.hpp"
#include "demmat/stability.hpp"

namespace demmat {

Setup Setup::make(const Scene& scene, const State& state)
{
    Setup s;
    s.scene = &scene;
    s.state = &state;
    s.contact = scene.contact_params();
    s.memory = memory_params(scene);
    s.gear = GearCoefficients<double>::make(scene.dt);
    const std::size_t n = state.size();
    s.mass.resize(n);
    s.inertia.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        s.mass[i] = sphere_mass(state.radius[i], scene.material.density);
        s.inertia[i] = sphere_inertia(state.radius[i], s.mass[i]);
        s.radius_max = std::max(s.radius_max, state.radius[i]);
    }
    s.cell_size = scene.search.method == SearchMethod::cells ? scene.search.cell_size * s.radius_max : 0.0;
    return s;
}

void Registry::add(VariantInfo info)
{
    if (info.unavailable)
        if (std::string why = info.unavailable(); !why.empty()) {
            unavailable_.emplace_back(info.name, std::move(why));
            return;
        }
    info.create = [make = std::move(info.create), name = info.name] {  // a variant knows its name, for messages
        auto v = make();
        v->set_registered_name(name);
        return v;
    };
    variants_.push_back(std::move(info));
}

const VariantInfo& Registry::find(std::string_view name) const
{
    for (const auto& v : variants_)
        if (v.name == name) return v;
    for (const auto& [n, why] : unavailable_)
        if (n == name) throw Error(fmt::format("variant '{}' cannot run here: {}", name, why));
    throw Error(fmt::format("unknown variant '{}' (known: {})", name, fmt::join(names(), ", ")));
}

std::vector<std::string> Registry::names() const
{
    std::vector<std::string> out;
    for (const auto& v : variants_) out.push_back(v.name);
    return out;
}

KineticEnergy kinetic_energy_parts(const Snapshot& s, const Setup& setup)
{
    KineticEnergy e;
    for (std::size_t i = 0; i < s.position.size(); ++i) {
        e.translational += 0.5 * setup.mass[i] * dot(s.velocity[i], s.velocity[i]);
        e.rotational += 0.5 * setup.inertia[i] * dot(s.angular_velocity[i], s.angular_velocity[i]);
    }
    return e;
}

PhaseTimes measure_steps(Driver& driver, std::int64_t warmup, std::int64_t steps, const std::function<void(std::int64_t)>& after_step)
{
    for (std::int64_t k = 0; k < warmup; ++k) driver.step();
    const PhaseTimes before = driver.times();
    driver.run(steps, after_step);  // with the health checks: a blown-up run is not measured
    return (driver.times() - before).per_step(steps);
}

double kinetic_energy(const Snapshot& s, const Setup& setup)
{
    const KineticEnergy e = kinetic_energy_parts(s, setup);
    return e.translational + e.rotational;
}

Driver::Driver(Variant& variant, const Setup& setup) : variant_(variant), setup_(setup), step_(setup.state->step)
{
    // The one place that refuses an integrator or precision a variant would otherwise silently ignore.
    const IntegratorChoice& choice = setup.scene->integrator;
    const std::string who = variant_.registered_name().empty() ? "this variant" : fmt::format("variant '{}'", variant_.registered_name());
    if (!variant_.supports(choice))
        throw Error(fmt::format("{} integrates with gear5 in double only, not {} (the arrays variant runs every integrator and precision)",
                                who, choice.describe()));
    const ContactModel& law = setup.scene->contact_model;
    if (!variant_.supports(law))
        throw Error(fmt::format("{} computes the paper's contact law only, not {} (the arrays variant runs the laws of physics.md §9)",
                                who,
                                law.describe()));
    variant_.init(setup_);
    const Scene& scene = *setup.scene;
    if (scene.checks.max_speed > 0.0) {
        speed_bound_ = scene.checks.max_speed;
    } else {
        // Ten times the fastest speed the scene can explain (stability.hpp).
        speed_bound_ = 10.0 * explained_speed(scene, *setup.state) + 1.0;
    }
    // Energy-growth check (docs/stability.md): the start energy and what gravity may add to it.
    const State& st = *setup.state;
    energy_check_ = std::none_of(st.walls.begin(), st.walls.end(), [](const Wall& w) { return w.moving(); });
    if (energy_check_) {
        x0_ = st.trans.x;
        double ke = 0.0, mass = 0.0;
        for (std::size_t i = 0; i < st.size(); ++i) {
            ke += 0.5 * setup.mass[i] * dot(st.trans.v[i], st.trans.v[i]) + 0.5 * setup.inertia[i] * dot(st.rot.v[i], st.rot.v[i]);
            mass += setup.mass[i];
        }
        energy0_ = ke + elastic_energy(st.trans.x, st.radius, st.walls, st.step, scene.dt, setup.contact);
        // A floor for scenes that start at rest without gravity: a millionth of the grains' energy at 0.1 m/s.
        energy_floor_ = 1e-6 * 0.5 * mass * 0.01;
    }
}

void Driver::step()
{
    try {
        timed_step();
    } catch (const InstabilityError& e) {
        if (e.step() >= 0) throw;
        // Raised inside a phase (e.g. the cell search met a runaway position): add the step and the hint.
        throw InstabilityError(fmt::format("step {}: {} ({})", step_, e.what(), stability_hint()), step_, e.particle());
    }
}

std::string Driver::stability_hint() const
{
    const State& st = *setup_.state;
    const double rmin = st.radius.empty() ? 0.0 : *std::min_element(st.radius.begin(), st.radius.end());
    const ContactTime ct = shortest_contact_time(*setup_.scene, st, impact_speed_bound(*setup_.scene, st));
    std::string hertz;
    if (ct.tc > 0.0)
        hertz = fmt::format(", the Hertz contact time at the largest impact speed {:.3g} m/s is {:.3g} s and {} is stable up to "
                            "{} of it (docs/stability.md)", ct.speed, ct.tc, name(setup_.scene->integrator.scheme),
                            stable_fraction_of_contact_time(setup_.scene->integrator.scheme));
    return fmt::format("Δt = {:g} s; the Rayleigh time of the smallest particle is {:.3g} s, a step of at most 0.2 of it is "
                       "usually stable{}", setup_.scene->dt, rayleigh_time(setup_.scene->material, rmin), hertz);
}

void Driver::timed_step()
{
    using clock = std::chrono::steady_clock;
    ++step_;
    const auto t0 = clock::now();
    variant_.predict(step_);
    const auto t1 = clock::now();
    variant_.search();
    const auto t2 = clock::now();
    variant_.forces();
    const auto t3 = clock::now();
    variant_.correct();
    const auto t4 = clock::now();
    times_.predict += std::chrono::duration<double>(t1 - t0).count();
    times_.search += std::chrono::duration<double>(t2 - t1).count();
    times_.forces += std::chrono::duration<double>(t3 - t2).count();
    times_.correct += std::chrono::duration<double>(t4 - t3).count();
    ++steps_taken_;
}

void Driver::run(std::int64_t steps, const std::function<void(std::int64_t)>& after_step)
{
    const int interval = setup_.scene->checks.interval;
    for (std::int64_t k = 1; k <= steps; ++k) {
        step();
        if (interval > 0 && (steps_taken_ % interval == 0 || k == steps)) {
            check_health();
            variant_.rejoin();
        }
        if (after_step) after_step(k);
    }
}

void Driver::check_health()
{
    variant_.snapshot(scratch_);
    const Scene& scene = *setup_.scene;
    const State& st = *setup_.state;
    const std::string hint = stability_hint();
    auto finite = [](const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    const std::size_t n = scratch_.position.size();
    // A derived bound also allows free fall since the start: a grain that left the domain through a side
    // without a wall falls on (docs/stability.md); the energy check below bounds real growth tightly.
    const double bound = scene.checks.max_speed > 0.0 ? speed_bound_
        : speed_bound_ + 10.0 * std::sqrt(dot(scene.gravity, scene.gravity)) * double(step_ - st.step) * scene.dt;
    for (std::size_t i = 0; i < n; ++i) {
        if (!finite(scratch_.position[i]) || !finite(scratch_.velocity[i]) || !finite(scratch_.angular_velocity[i]))
            throw InstabilityError(fmt::format("step {}: particle {} has a non-finite position or velocity (NaN or Inf): "
                                               "the run is unstable ({})", step_, i, hint), step_, std::int64_t(i));
        const double speed = std::sqrt(dot(scratch_.velocity[i], scratch_.velocity[i]));
        if (speed > bound)
            throw InstabilityError(fmt::format("step {}: particle {} moves at {:.3g} m/s, above the bound {:.3g} m/s "
                                               "(energy runaway; {})", step_, i, speed, bound, hint), step_, std::int64_t(i));
    }
    const double ratio = scene.checks.max_overlap_ratio;
    for (const Wall& w : st.walls) {
        const Vec3d p = w.point_at(step_, scene.dt);
        for (std::size_t i = 0; i < n; ++i) {
            const double s = dot(scratch_.position[i] - p, w.normal);
            if (s < 0.0)
                throw InstabilityError(fmt::format("step {}: particle {} passed through wall '{}' ({})", step_, i, w.name, hint),
                                       step_, std::int64_t(i));
            largest_overlap_ratio_ = std::max(largest_overlap_ratio_, (st.radius[i] - s) / st.radius[i]);
            if ((st.radius[i] - s) > ratio * st.radius[i])
                throw InstabilityError(fmt::format("step {}: particle {} overlaps wall '{}' by {:.3g} of its radius, above "
                                                   "the bound {} ({})", step_, i, w.name, (st.radius[i] - s) / st.radius[i], ratio, hint),
                                       step_, std::int64_t(i));
        }
    }
    const auto pairs = contact_pairs(scratch_.position, st.radius, false);
    for (const auto& [i, j] : pairs) {
        const Vec3d d = scratch_.position[j] - scratch_.position[i];
        const double h = st.radius[i] + st.radius[j] - std::sqrt(dot(d, d));
        const double r = std::min(st.radius[i], st.radius[j]);
        largest_overlap_ratio_ = std::max(largest_overlap_ratio_, h / r);
        if (h > ratio * r)
            throw InstabilityError(fmt::format("step {}: particles {} and {} overlap by {:.3g} of the smaller radius, above "
                                               "the bound {} ({})", step_, i, j, h / r, ratio, hint), step_, i);
    }
    if (energy_check_) {
        // Kinetic + elastic energy against the start energy plus the work gravity has done since.
        double work = 0.0, worst = -1.0;
        std::int64_t who = 0;
        for (std::size_t i = 0; i < n; ++i) {
            work += setup_.mass[i] * dot(scene.gravity, scratch_.position[i] - x0_[i]);
            const double ke = 0.5 * setup_.mass[i] * dot(scratch_.velocity[i], scratch_.velocity[i]);
            if (ke > worst) { worst = ke; who = std::int64_t(i); }
        }
        const double e = kinetic_energy(scratch_, setup_) +
                         elastic_energy(scratch_.position, st.radius, st.walls, step_, scene.dt, setup_.contact);
        const double supply = energy0_ + work;
        const double bound = supply + kEnergyGrowthTolerance * (energy0_ + std::abs(work)) + energy_floor_;
        if (!(e <= bound))
            throw InstabilityError(fmt::format("step {}: kinetic + elastic energy {:.4g} J exceeds the start energy plus the work of "
                                               "gravity, {:.4g} J, by more than {:g} % (energy growth; particle {} holds the most kinetic energy; {})",
                                               step_, e, supply, 100.0 * kEnergyGrowthTolerance, who, hint), step_, who);
    }
}

} // namespace demmat
