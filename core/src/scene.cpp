// The scene's derived quantities (contact constants, fingerprint, box walls, time scales); reading and
// writing a scene file is the harness's (scene_toml.cpp).
#include "demmat/scene.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "demmat/error.hpp"

namespace demmat {

double rayleigh_time(const Material& m, double radius)
{
    return 3.14159265358979323846 * radius * std::sqrt(m.density / m.shear_modulus()) / (0.1631 * m.poisson + 0.8766);
}

std::vector<Wall> box_walls(const Box& box)
{
    std::vector<Wall> w;
    for (const char* f : {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"}) w.push_back(box_face(box, f));
    return w;
}

Wall box_face(const Box& box, const std::string& face)
{
    static const std::map<std::string, std::pair<int, bool>> faces = {
        {"x_min", {0, false}}, {"x_max", {0, true}}, {"y_min", {1, false}},
        {"y_max", {1, true}},  {"z_min", {2, false}}, {"z_max", {2, true}}};
    auto it = faces.find(face);
    if (it == faces.end()) throw Error(fmt::format("unknown box face '{}' (expected x_min, x_max, y_min, y_max, z_min or z_max)", face));
    const auto [axis, upper] = it->second;
    Wall w;
    w.name = face;
    w.point = upper ? box.max : box.min;
    component(w.normal, axis) = upper ? -1.0 : 1.0;
    return w;
}

ContactParams<double> Scene::contact_params() const
{
    const Material& p = material;
    const Material& w = wall_mat();
    const double e_pp = 1.0 / ((1.0 - p.poisson * p.poisson) / p.young + (1.0 - p.poisson * p.poisson) / p.young);
    // A rigid wall adds nothing to 1/E* (physics.md §9); a wall of a material, its (1 − ν²)/E.
    const double wall_term = w.rigid ? 0.0 : (1.0 - w.poisson * w.poisson) / w.young;
    const double e_pw = 1.0 / ((1.0 - p.poisson * p.poisson) / p.young + wall_term);
    ContactParams<double> c;
    c.hertz_pp = 4.0 / 3.0 * e_pp;
    c.hertz_pw = 4.0 / 3.0 * e_pw;
    c.gamma_n = p.gamma_n;
    c.gamma_t = p.gamma_t;
    c.mu = p.mu;
    return c;
}

std::uint64_t Scene::fingerprint(std::size_t particle_count) const
{
    // FNV-1a over the physics that a saved state depends on, from the state format's offset basis
    // (docs/state-format.md: not the standard one, kept so that saved states stay readable).
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (std::size_t k = 0; k < n; ++k) { h ^= b[k]; h *= 1099511628211ull; }
    };
    auto mixd = [&](double d) { mix(&d, sizeof d); };
    for (const Material* m : {&material, &wall_mat()})
        for (double d : {m->density, m->young, m->poisson, m->gamma_n, m->gamma_t, m->mu}) mixd(d);
    if (wall_mat().rigid) mixd(-1.0);  // only a scene with a rigid wall mixes this in: every other fingerprint stays
    for (double d : contact_model.fingerprint_values()) mixd(d);  // none for the paper's law
    mixd(dt);
    mixd(gravity.x); mixd(gravity.y); mixd(gravity.z);
    const std::uint64_t n = particle_count;
    mix(&n, sizeof n);
    return h;
}

} // namespace demmat
