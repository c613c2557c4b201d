#include "demmat/reference.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace demmat {

namespace {

bool law_says_contact(const Vec3d& xi, const Vec3d& xj, double ri, double rj)
{
    // Exactly the law's test: h = ri + rj - d > 0 with d = sqrt(dx·dx).
    const Vec3d dx = xj - xi;
    const double d = std::sqrt(dot(dx, dx));
    return ri + rj - d > 0.0;
}

} // namespace

std::vector<Pair> contact_pairs(const std::vector<Vec3d>& x, const std::vector<double>& radius, bool brute_force)
{
    const auto n = std::int64_t(x.size());
    std::vector<Pair> out;
    if (brute_force || n < 64) {
        for (std::int64_t i = 0; i < n; ++i)
            for (std::int64_t j = i + 1; j < n; ++j)
                if (law_says_contact(x[i], x[j], radius[i], radius[j])) out.emplace_back(i, j);
        return out;
    }
    // Sorted cell list: cells of 2·R_max keyed by integer coordinates, looked up by binary search, so
    // memory does not depend on the extent of the domain.
    const double edge = 2.0 * *std::max_element(radius.begin(), radius.end());
    using Key = std::array<std::int64_t, 3>;
    std::vector<std::pair<Key, std::int64_t>> cells;
    cells.resize(std::size_t(n));
    for (std::int64_t i = 0; i < n; ++i)
        cells[i] = {{std::int64_t(std::floor(x[i].x / edge)), std::int64_t(std::floor(x[i].y / edge)),
                     std::int64_t(std::floor(x[i].z / edge))}, i};
    std::sort(cells.begin(), cells.end());
    for (std::int64_t i = 0; i < n; ++i) {
        const Key k{std::int64_t(std::floor(x[i].x / edge)), std::int64_t(std::floor(x[i].y / edge)),
                    std::int64_t(std::floor(x[i].z / edge))};
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const Key q{k[0] + dx, k[1] + dy, k[2] + dz};
                    auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(q, std::int64_t(-1)));
                    for (; it != cells.end() && it->first == q; ++it) {
                        const std::int64_t j = it->second;
                        if (j > i && law_says_contact(x[i], x[j], radius[i], radius[j])) out.emplace_back(i, j);
                    }
                }
    }
    std::sort(out.begin(), out.end());
    return out;
}

namespace {
// Forces and torques in the canonical order, each contact by `pair(i, j, out)` and `wall(i, p, wall, out)`.
template <class PairLaw, class WallLaw>
void sum_forces(const std::vector<Vec3d>& x, const std::vector<double>& radius, const std::vector<Wall>& walls, std::int64_t step,
                double dt, std::vector<Vec3d>& force, std::vector<Vec3d>& torque, PairLaw&& pair, WallLaw&& wall_law)
{
    const std::size_t n = x.size();
    force.assign(n, Vec3d{});
    torque.assign(n, Vec3d{});
    // Pairs sorted by (i, j) and visited in that order give every particle its canonical order:
    // partners k < p ascending (as the j of earlier pairs), then partners l > p ascending.
    for (const auto& [i, j] : contact_pairs(x, radius, false)) {
        ContactForce<double> c;
        if (!pair(std::size_t(i), std::size_t(j), c)) continue;
        force[i] += c.f_i;
        force[j] += -c.f_i;
        torque[i] += c.t_i;
        torque[j] += c.t_j;
    }
    for (const Wall& wall : walls) {
        const Vec3d p = wall.point_at(step, dt);
        for (std::size_t i = 0; i < n; ++i) {
            ContactForce<double> c;
            if (!wall_law(i, p, wall, c)) continue;
            force[i] += c.f_i;
            torque[i] += c.t_i;
        }
    }
}
} // namespace

void reference_forces(const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w,
                      const std::vector<double>& radius, const std::vector<double>& mass,
                      const std::vector<Wall>& walls, std::int64_t step, double dt,
                      const ContactParams<double>& params, std::vector<Vec3d>& force, std::vector<Vec3d>& torque)
{
    sum_forces(
        x, radius, walls, step, dt, force, torque,
        [&](std::size_t i, std::size_t j, ContactForce<double>& c) {
            return particle_contact<FullModel>(x[i], x[j], v[i], v[j], w[i], w[j], radius[i], radius[j], mass[i], mass[j], params, c);
        },
        [&](std::size_t i, const Vec3d& p, const Wall& wall, ContactForce<double>& c) {
            return wall_contact<FullModel>(x[i], v[i], w[i], radius[i], mass[i], p, wall.normal, wall.velocity, params, c);
        });
}

void reference_forces_law(const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w,
                          const std::vector<double>& radius, const std::vector<double>& mass,
                          const std::vector<Wall>& walls, std::int64_t step, double dt, const ContactParams<double>& params,
                          const MemoryParams<double>& memory, const ModelFeatures& law, std::vector<Vec3d>& force,
                          std::vector<Vec3d>& torque)
{
    ModelFeatures need = ModelFeatures::full();
    need.restitution_damping = law.restitution_damping;
    need.history = law.history;
    need.rolling = law.rolling;
    with_law_model(need, [&]<class M>() {
        if constexpr (M::restitution_damping || M::history || M::rolling)  // with_law_model's paper branch is never taken
        sum_forces(
            x, radius, walls, step, dt, force, torque,
            [&](std::size_t i, std::size_t j, ContactForce<double>& c) {
                Stretch<double> zero;
                return particle_contact_memory<M>(x[i], x[j], v[i], v[j], w[i], w[j], radius[i], radius[j], mass[i], mass[j], params,
                                                  memory, zero, false, c);
            },
            [&](std::size_t i, const Vec3d& p, const Wall& wall, ContactForce<double>& c) {
                Stretch<double> zero;
                return wall_contact_memory<M>(x[i], v[i], w[i], radius[i], mass[i], p, wall.normal, wall.velocity, params, memory, zero,
                                              false, c);
            });
    });
}

} // namespace demmat
