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
    // A sorted cell list: cells of 2·R_max keyed by integer coordinates, sorted lexicographically, so
    // memory does not depend on the extent of the domain. The health checks run it on every interval
    // of steps, at any N (10^7 on a GPU), so it is linear after the sort: home cells are visited in key
    // order, and each of the nine neighbour rows (dx, dy) is found by a cursor that only moves forward.
    double rmax = 0.0;  // of the radii a contact can have: a NaN radius touches nothing
    for (double r : radius) rmax = r > rmax ? r : rmax;
    if (rmax == 0.0) return out;  // no radius above zero: h = R_i + R_j - d > 0 holds for no pair
    const double edge = 2.0 * rmax;
    struct Item {
        std::array<std::int64_t, 3> cell;
        std::int64_t id;
    };
    // Clamped far out, so that any finite position has a cell: clamped particles share a cell and are
    // tested exactly, which keeps the set a superset. A NaN coordinate touches nothing (h > 0 is false).
    constexpr double kFar = 4.0e18;
    auto cell_of = [&](double c) { return std::int64_t(std::clamp(std::floor(c / edge), -kFar, kFar)); };
    std::vector<Item> items;
    items.reserve(std::size_t(n));
    for (std::int64_t i = 0; i < n; ++i) {
        const Vec3d& p = x[i];
        if (std::isnan(p.x) || std::isnan(p.y) || std::isnan(p.z)) continue;
        items.push_back({{cell_of(p.x), cell_of(p.y), cell_of(p.z)}, i});
    }
    std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.cell < b.cell; });
    const std::size_t m = items.size();
    std::array<std::size_t, 9> cursor{};  // per row (dx, dy): the first item not below the row's start
    std::vector<std::int64_t> count(std::size_t(n) + 1, 0);
    std::vector<Pair> found;
    for (std::size_t a = 0; a < m;) {
        const auto home = items[a].cell;
        std::size_t b = a;
        while (b < m && items[b].cell == home) ++b;
        int row = 0;
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy, ++row) {
                const std::array<std::int64_t, 3> lo{home[0] + dx, home[1] + dy, home[2] - 1};
                const std::array<std::int64_t, 3> hi{home[0] + dx, home[1] + dy, home[2] + 1};
                std::size_t& c = cursor[std::size_t(row)];
                while (c < m && items[c].cell < lo) ++c;
                for (std::size_t q = c; q < m && items[q].cell <= hi; ++q)
                    for (std::size_t p = a; p < b; ++p) {
                        const std::int64_t i = items[p].id, j = items[q].id;
                        if (j > i && law_says_contact(x[i], x[j], radius[i], radius[j])) {
                            found.emplace_back(i, j);
                            ++count[std::size_t(i) + 1];
                        }
                    }
            }
        a = b;
    }
    // Sorted by (i, j): a counting sort by i, then each particle's few partners.
    for (std::size_t i = 0; i < std::size_t(n); ++i) count[i + 1] += count[i];
    out.resize(found.size());
    for (const Pair& pr : found) out[std::size_t(count[std::size_t(pr.first)]++)] = pr;
    for (auto it = out.begin(); it != out.end();) {
        auto e = it;
        while (e != out.end() && e->first == it->first) ++e;
        std::sort(it, e);
        it = e;
    }
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
