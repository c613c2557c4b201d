#pragma once
// The scene: everything a run needs besides the particles' dynamic state, read from a TOML file a
// user can edit (format in docs/scene-format.md).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/contact_model.hpp"
#include "demmat/integrators.hpp"
#include "demmat/vec3.hpp"

namespace demmat {

struct Material {
    double density = 1000.0;  // kg/m³
    double young = 0.3e6;     // Pa
    double poisson = 0.30;
    double shear = 0.0;       // Pa; 0 = E/(2(1+ν)); used for the Rayleigh time only
    double gamma_n = 60.0;    // 1/s
    double gamma_t = 60.0;    // 1/s
    double mu = 0.6;
    // A wall only: infinitely stiff (LAMMPS's `rigid`), so it adds nothing to E* and G* (physics.md §9);
    // its other constants are unused. Written as `[wall_material] rigid = true` (docs/scene-format.md).
    bool rigid = false;

    double shear_modulus() const { return shear > 0.0 ? shear : young / (2.0 * (1.0 + poisson)); }
};

struct Box {
    Vec3d min, max;
};

// A plane wall through point_at(step) with unit normal pointing into the domain. A moving wall's point
// is p_ref + v·((step − ref_step)·Δt), computed from integers so it never drifts (physics.md §4).
struct Wall {
    std::string name;
    Vec3d point;            // position at ref_step
    Vec3d normal;           // unit, into the domain
    Vec3d velocity;         // m/s, zero for a fixed wall
    std::int64_t ref_step = 0;

    bool moving() const { return !(velocity == Vec3d{}); }
    Vec3d point_at(std::int64_t step, double dt) const
    {
        const double t = double(step - ref_step) * dt;
        return {point.x + velocity.x * t, point.y + velocity.y * t, point.z + velocity.z * t};
    }
};

enum class SearchMethod { cells, all_pairs };

struct SearchParams {
    SearchMethod method = SearchMethod::cells;
    double cell_size = 2.0;  // cell edge in units of R_max (2 = the paper's optimum, the largest diameter)
};

// Fixed capacities (the paper's "control of overestimation"): overflowing one stops the run with a
// message naming the capacity and the value that would fit.
struct Capacity {
    int contacts_per_particle = 32;       // particle–particle contacts stored per particle (partners j > i)
    int wall_contacts_per_particle = 6;   // particle–wall contacts per particle
};

// Run-time checks for blow-ups (done by the driver between steps, outside the timed phases).
struct Checks {
    int interval = 100;               // steps between checks; 0 disables
    double max_overlap_ratio = 0.5;   // overlap / smaller radius above which a run is stopped
    double max_speed = 0.0;           // m/s; 0 = derived from the scene (see driver.cpp)
};

// How the initial particles are made.
struct GridGenerator {
    std::int64_t count = 0;
    double radius_min = 0.0, radius_max = 0.0;
    double speed_min = 0.0, speed_max = 0.0;
    std::uint64_t seed = 1;
    std::int64_t cells[3] = {0, 0, 0};  // lattice; 0 = ceil(cbrt(count)) per axis
    double spacing = 0.0;               // m; 0 = fill the domain evenly
};

struct ParticleInit {
    double radius = 0.0;
    Vec3d position, velocity, angular_velocity;
};

struct Scene {
    std::string name;
    std::filesystem::path source;  // file it was read from (empty when built in code)
    Material material;
    std::optional<Material> wall_material;  // choice: walls have the particles' material unless given
    Vec3d gravity{0.0, 0.0, -10.0};
    double dt = 1e-5;
    Box domain;
    std::vector<Wall> walls;
    SearchParams search;
    Capacity capacity;
    Checks checks;
    IntegratorChoice integrator;  // [integrator]; default gear5 in double (docs/accuracy.md)
    ContactModel contact_model;   // [contact]; default the paper's law (physics.md §2, §9)

    // Exactly one of these is the particle source.
    std::optional<GridGenerator> grid;
    std::vector<ParticleInit> particles;
    std::filesystem::path state_file;  // resolved against the scene file's folder

    const Material& wall_mat() const { return wall_material ? *wall_material : material; }
    ContactParams<double> contact_params() const;
    // Identifies the physics a state belongs to (materials, Δt, gravity, particle count).
    std::uint64_t fingerprint(std::size_t particle_count) const;
};

// The six faces of a box as walls, normals into the box, named x_min … z_max.
std::vector<Wall> box_walls(const Box& box);
Wall box_face(const Box& box, const std::string& face);

// Shared per-particle properties, written once (physics.md §1).
inline double sphere_mass(double radius, double density) { return density * (4.0 / 3.0) * 3.14159265358979323846 * radius * radius * radius; }
inline double sphere_inertia(double radius, double mass) { return 0.4 * mass * radius * radius; }

// Time scales (physics.md §8).
double rayleigh_time(const Material& m, double radius);

} // namespace demmat
