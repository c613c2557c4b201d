#include "demmat/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/reference.hpp"

namespace demmat {

double hertz_max_overlap(double mstar, double rstar, double estar, double speed)
{
    return std::pow(15.0 * mstar * speed * speed / (16.0 * estar * std::sqrt(rstar)), 0.4);
}

double hertz_contact_time(double mstar, double rstar, double estar, double speed)
{
    return 2.87 * std::pow(mstar * mstar / (rstar * estar * estar * speed), 0.2);
}

double fastest_wall_speed(const State& state)
{
    double vw = 0.0;
    for (const Wall& w : state.walls) vw = std::max(vw, std::hypot(w.velocity.x, w.velocity.y, w.velocity.z));  // no overflow of v²
    return vw;
}

double explained_speed(const Scene& scene, const State& state)
{
    double v0 = 0.0;
    for (const Vec3d& v : state.trans.v) v0 = std::max(v0, std::hypot(v.x, v.y, v.z));  // 1e200 m/s is refused, not inf
    const Vec3d ext = scene.domain.max - scene.domain.min;
    const double fall = std::sqrt(2.0 * std::sqrt(dot(scene.gravity, scene.gravity)) * std::sqrt(dot(ext, ext)));
    return v0 + fall + fastest_wall_speed(state);
}

double impact_speed_bound(const Scene& scene, const State& state)
{
    const double vp = explained_speed(scene, state);
    return state.size() > 1 ? 2.0 * vp : vp + fastest_wall_speed(state);
}

ContactTime shortest_contact_time(const Scene& scene, const State& state, double speed)
{
    ContactTime out;
    out.speed = speed;
    if (state.size() == 0 || !(speed > 0.0)) return out;
    const double rmin = *std::min_element(state.radius.begin(), state.radius.end());
    const double m = sphere_mass(rmin, scene.material.density);
    const ContactParams<double> p = scene.contact_params();
    out.tc = INFINITY;
    if (state.size() > 1) out.tc = hertz_contact_time(m / 2.0, rmin / 2.0, p.estar_pp(), speed);
    if (!state.walls.empty()) {
        const double tw = hertz_contact_time(m, rmin, p.estar_pw(), speed);
        if (tw < out.tc) {
            out.tc = tw;
            out.wall = true;
        }
    }
    if (!std::isfinite(out.tc)) out.tc = 0.0;  // one grain and no wall: no contact can happen
    return out;
}

double stable_fraction_of_contact_time(Integrator scheme)
{
    // The lower envelope, rounded down, of the limits the stability study measured on the two-body scenes
    // (head-on pair, sphere on a wall; restitution 0.2 … 1, E = 1e5 … 2e11 Pa, double and float) where only
    // the driver's detection and the end of the contact count, in units of the t_c this check uses
    // (results/stability/stability_default.md, docs/stability.md). A bed with viscous friction can need
    // less (its tangential damping is a second stiffness): the warning below covers it.
    switch (scheme) {
    case Integrator::gear5: return 0.09;
    case Integrator::gear3: return 0.35;
    case Integrator::verlet: return 0.25;
    case Integrator::symplectic_euler: return 0.025;
    }
    return 0.025;
}

std::string check_contact_time_step(const Scene& scene, const State& state)
{
    const double v = impact_speed_bound(scene, state);
    const ContactTime ct = shortest_contact_time(scene, state, v);
    if (!(ct.tc > 0.0)) return {};
    const double ratio = scene.dt / ct.tc;
    const double limit = stable_fraction_of_contact_time(scene.integrator.scheme);
    const char* what = ct.wall ? "the smallest grain against a wall" : "two smallest grains";
    if (ratio > limit)
        throw Error(fmt::format("{}: time step {:g} s is {:.3g} of the Hertz contact time {:.3g} s ({} at the scene's largest "
                                "impact speed {:.3g} m/s), above the {} stability limit {} of it: the run would be unstable; "
                                "use dt <= {:.3g} s (or --allow-unstable)",
                                scene.name, scene.dt, ratio, ct.tc, what, v, name(scene.integrator.scheme), limit,
                                std::min(kWarnFractionOfContactTime, limit) * ct.tc));  // within this integrator's limit
    if (ratio > kWarnFractionOfContactTime)
        return fmt::format("time step {:g} s is {:.3g} of the Hertz contact time {:.3g} s ({} at the scene's largest impact "
                           "speed {:.3g} m/s); above {} of it a contact takes fewer than {:.0f} steps and its restitution is inaccurate",
                           scene.dt, ratio, ct.tc, what, v, kWarnFractionOfContactTime, 1.0 / kWarnFractionOfContactTime);
    return {};
}

double elastic_energy(const std::vector<Vec3d>& x, const std::vector<double>& radius, const std::vector<Wall>& walls,
                      std::int64_t step, double dt, const ContactParams<double>& params)
{
    // F = (4/3)E*·sqrt(R*)·h^(3/2) integrates to (2/5)·(4/3)E*·sqrt(R*)·h^(5/2) = (8/15)E*·sqrt(R*)·h^(5/2).
    double e = 0.0;
    for (const auto& [i, j] : contact_pairs(x, radius, false)) {
        const Vec3d d = x[j] - x[i];
        const double h = radius[i] + radius[j] - std::sqrt(dot(d, d));
        const double rstar = radius[i] * radius[j] / (radius[i] + radius[j]);
        e += 0.4 * params.hertz_pp * std::sqrt(rstar) * h * h * std::sqrt(h);
    }
    for (const Wall& w : walls) {
        const Vec3d p = w.point_at(step, dt);
        for (std::size_t i = 0; i < x.size(); ++i) {
            const double h = radius[i] - dot(x[i] - p, w.normal);
            if (h > 0.0) e += 0.4 * params.hertz_pw * std::sqrt(radius[i]) * h * h * std::sqrt(h);
        }
    }
    return e;
}

void check_magnitudes(const Scene& scene, const State& state)
{
    const Precision precision = scene.integrator.precision;
    if (!(scene.dt >= min_time_step(precision)))
        throw Error(fmt::format("{}: time step {:g} s is below {:g} s, where the Gear values' Δt²/2·a underflows in {}", scene.name,
                                scene.dt, min_time_step(precision), name(precision)));
    auto normal = [](double x) { return std::isfinite(x) && x >= std::numeric_limits<double>::min(); };
    for (std::size_t i = 0; i < state.size(); ++i) {
        const double m = sphere_mass(state.radius[i], scene.material.density);
        if (!normal(m) || !normal(sphere_inertia(state.radius[i], m)))
            throw Error(fmt::format("{}: particle {} of radius {:g} m and density {:g} kg/m³ has a mass of {:g} kg, beyond what a double "
                                    "holds (its mass or moment of inertia over- or underflows)", scene.name, i, state.radius[i],
                                    scene.material.density, m));
    }
    const ContactParams<double> p = scene.contact_params();
    if (!normal(p.hertz_pp) || !normal(p.hertz_pw))
        throw Error(fmt::format("{}: the Hertz stiffness (4/3)E* of {:g} Pa is beyond what a double holds (young = {:g} Pa)", scene.name,
                                std::min(p.hertz_pp, p.hertz_pw), scene.material.young));
    double rmin = state.radius.front();
    for (double r : state.radius) rmin = std::min(rmin, r);
    if (!normal(rayleigh_time(scene.material, rmin)))
        throw Error(fmt::format("{}: the Rayleigh time of the smallest grain, {:g} s, is beyond what a double holds (density {:g} kg/m³, "
                                "shear modulus {:g} Pa, radius {:g} m)", scene.name, rayleigh_time(scene.material, rmin),
                                scene.material.density, scene.material.shear_modulus(), rmin));
    const double v = impact_speed_bound(scene, state);
    if (!std::isfinite(v))
        throw Error(fmt::format("{}: the largest impact speed overflows a double (a grain's or a wall's speed near 1e308 m/s)", scene.name));
    const ContactTime ct = shortest_contact_time(scene, state, v);
    if (v > 0.0 && (state.size() > 1 || !state.walls.empty()) && !normal(ct.tc))
        throw Error(fmt::format("{}: the Hertz contact time of young = {:g} Pa at the impact speed {:g} m/s is {:g} s, beyond what a double "
                                "holds", scene.name, scene.material.young, v, ct.tc));
}

std::string check_continued_walls(const Scene& scene, const State& state)
{
    if (scene.state_file.empty()) return {};
    const Vec3d ext = scene.domain.max - scene.domain.min;
    const double tolerance = 1e-12 * std::hypot(ext.x, ext.y, ext.z);
    for (const Wall& w : scene.walls)
        for (const Wall& kept : state.walls) {  // the continued walls: the state's, or the scene's where the state has none
            if (kept.name != w.name) continue;
            const Vec3d p = kept.point_at(state.step, scene.dt);
            if (w.normal == kept.normal && std::abs(dot(w.point - p, kept.normal)) <= tolerance) continue;
            return fmt::format("wall '{}' of the scene (point ({:g}, {:g}, {:g}), normal ({:g}, {:g}, {:g})) is not where the state file "
                               "has it at step {} (point ({:g}, {:g}, {:g}), normal ({:g}, {:g}, {:g})): a continued wall stands where "
                               "the state left it, so the scene's point and normal are not used",
                               w.name, w.point.x, w.point.y, w.point.z, w.normal.x, w.normal.y, w.normal.z, state.step, p.x, p.y, p.z,
                               kept.normal.x, kept.normal.y, kept.normal.z);
        }
    return {};
}

std::string check_time_step(const Scene& scene, const State& state)
{
    check_magnitudes(scene, state);
    double rmin = state.radius.front();
    for (double r : state.radius) rmin = std::min(rmin, r);
    const double tr = rayleigh_time(scene.material, rmin);
    if (scene.dt > tr)
        throw Error(fmt::format("{}: time step {:g} s exceeds the Rayleigh time {:.3g} s of the smallest particle (R = {:g} m): "
                                "the run would be unstable; use dt <= {:.3g} s", scene.name, scene.dt, tr, rmin, 0.2 * tr));
    // The Hertz contact time at the scene's largest impact speed (stability.hpp, docs/stability.md): refused
    // above the integrator's measured stability limit, a warning above kWarnFractionOfContactTime of it.
    const std::string hertz = check_contact_time_step(scene, state);
    if (scene.dt > 0.2 * tr)
        return fmt::format("time step {:g} s is {:.2f} of the Rayleigh time {:.3g} s; above 0.2 of it a run may be inaccurate or unstable{}{}",
                           scene.dt, scene.dt / tr, tr, hertz.empty() ? "" : "; ", hertz);
    return hertz;
}

} // namespace demmat
