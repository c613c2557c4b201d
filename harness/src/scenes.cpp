#include "demmat/scenes.hpp"

#include <cmath>

#include "demmat/error.hpp"

#include <fmt/format.h>

namespace demmat {

namespace {
Scene paper_material_scene()
{
    Scene s;
    s.material = Material{1000.0, 0.3e6, 0.30, 0.11e6, 60.0, 60.0, 0.6};  // Table 1 of the paper
    s.dt = 1e-5;
    s.gravity = {0.0, 0.0, -10.0};
    return s;
}
} // namespace

Scene paper_scene(std::int64_t count, std::uint64_t seed)
{
    Scene s = paper_material_scene();
    s.name = count == 1000 ? "paper" : fmt::format("paper_{}", count);
    s.domain = {{0.0, 0.0, 0.0}, {2.0, 2.0, 2.0}};
    s.walls = box_walls(s.domain);
    GridGenerator g;
    g.count = count;
    g.radius_min = 0.003;
    g.radius_max = 0.005;
    g.speed_min = 0.0;
    g.speed_max = 1.0;
    g.seed = seed;
    s.grid = g;
    return s;
}

Scene dense_bed_scene(std::int64_t count, std::uint64_t seed, std::int64_t max_layers)
{
    Scene s = paper_scene(count, seed);
    s.name = fmt::format("dense_bed_{}", count);
    // A cube of sites up to max_layers (12: N = 1728); beyond, wider, not taller. Grains of this soft
    // material (E = 3·10⁵ Pa) start with random speeds up to 1 m/s and fall as the lattice collapses; the
    // deepest overlap while settling grows with the depth: 0.49 of the smaller radius at 20 layers
    // (N = 8000; a bed of 16000 passed the health bound of 0.5), 0.42 at 16 (N = 16000), 0.31–0.42 at 12
    // (N = 10³–10⁵). A fixed depth also keeps the pressure profile, hence the contacts per grain, alike
    // across N.
    if (max_layers < 1) throw Error(fmt::format("dense bed: at most {} layers is not a bed (need at least 1)", max_layers));
    auto side = std::int64_t(std::ceil(std::cbrt(double(count)) - 1e-9));
    if (side > max_layers) side = std::int64_t(std::ceil(std::sqrt(double(count) / double(max_layers)) - 1e-9));
    const std::int64_t nz = (count + side * side - 1) / (side * side);
    const double spacing = 2.1 * s.grid->radius_max;
    s.grid->cells[0] = side;
    s.grid->cells[1] = side;
    s.grid->cells[2] = nz;
    s.grid->spacing = spacing;
    s.domain = {{0.0, 0.0, 0.0}, {double(side) * spacing, double(side) * spacing, double(nz) * spacing}};
    s.walls = box_walls(s.domain);
    return s;
}

Scene settled_scene(const Scene& settled, const std::filesystem::path& state_file)
{
    Scene s = settled;
    s.name = settled.name + "_settled";
    s.grid.reset();
    s.particles.clear();
    s.state_file = state_file;
    for (Wall& w : s.walls) w.velocity = {};
    return s;
}

Scene compression_scene(const Scene& settled, const std::filesystem::path& state_file, double speed)
{
    Scene s = settled_scene(settled, state_file);
    s.name = settled.name + "_compression";
    for (Wall& w : s.walls)
        if (w.name == "x_max") w.velocity = {-speed, 0.0, 0.0};
    return s;
}

Scene head_on_scene(double speed, double radius)
{
    Scene s = paper_material_scene();
    s.name = "head_on";
    s.gravity = {0.0, 0.0, 0.0};
    s.material.gamma_n = 0.0;
    s.material.gamma_t = 0.0;
    s.material.mu = 0.0;
    s.domain = {{-0.05, -0.05, -0.05}, {0.05, 0.05, 0.05}};
    const double gap = 0.0005;
    s.particles.push_back({radius, {-(radius + gap / 2), 0.0, 0.0}, {speed / 2, 0.0, 0.0}, {}});
    s.particles.push_back({radius, {radius + gap / 2, 0.0, 0.0}, {-speed / 2, 0.0, 0.0}, {}});
    return s;
}

Scene drop_scene(double gap, double radius)
{
    Scene s = paper_material_scene();
    s.name = "drop";
    s.domain = {{-0.05, -0.05, 0.0}, {0.05, 0.05, 0.1}};
    s.walls = {box_face(s.domain, "z_min")};
    s.particles.push_back({radius, {0.0, 0.0, radius + gap}, {}, {}});
    return s;
}

} // namespace demmat
