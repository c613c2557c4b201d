#pragma once
// The domain decomposition of the mpi variant: a grid of dims[0] × dims[1] × dims[2] = R bricks, cut at
// fixed planes chosen at init. Rank r = i + dims[0]·(j + dims[1]·k) owns the particles whose centre lies
// in brick (i, j, k): cuts[a][i_a] <= x_a < cuts[a][i_a + 1] on each axis a. The first and last cut of
// every axis are ∓∞, so a grain that leaves the domain stays owned. A brick's ghosts come from the
// bricks around it, in one stage per axis (rank_halo.hpp), which holds while every interior brick is at
// least the interaction range thick along each cut axis (checked at init: a process count that allows
// no such grid is refused with a one-line error).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "demmat/vec3.hpp"

namespace demmat::mpi {

// How the cuts are placed along each axis: at the quantiles of the particles' coordinates (each brick
// row starts with about N/dims particles), or evenly over their extent (equal widths: idle ranks where the
// bed is thin).
enum class Balance { count, even };

struct Bricks {
    std::array<int, 3> dims = {1, 1, 1};
    std::array<std::vector<double>, 3> cuts = {std::vector<double>{-INFINITY, INFINITY}, {-INFINITY, INFINITY}, {-INFINITY, INFINITY}};
    std::array<double, 3> area = {0.0, 0.0, 0.0};  // m²: the particles' bounding box across each axis at init

    int ranks() const { return dims[0] * dims[1] * dims[2]; }
    // The brick index along axis a of coordinate c: the last i with cuts[a][i] <= c (a NaN goes to the
    // last; the health checks name it).
    int index(int a, double c) const
    {
        const std::vector<double>& k = cuts[std::size_t(a)];
        return int(std::upper_bound(k.begin() + 1, k.end() - 1, c) - (k.begin() + 1));
    }
    int owner(const Vec3d& x) const { return rank_at({index(0, x.x), index(1, x.y), index(2, x.z)}); }
    int rank_at(const std::array<int, 3>& i) const { return i[0] + dims[0] * (i[1] + dims[1] * i[2]); }
    std::array<int, 3> coordinates(int rank) const { return {rank % dims[0], rank / dims[0] % dims[1], rank / (dims[0] * dims[1])}; }
    // The rank next to `rank` along axis a (step −1 or +1), or −1 past the end.
    int neighbour(int rank, int a, int step) const
    {
        std::array<int, 3> i = coordinates(rank);
        i[std::size_t(a)] += step;
        return i[std::size_t(a)] < 0 || i[std::size_t(a)] >= dims[std::size_t(a)] ? -1 : rank_at(i);
    }
    // Rank's brick along axis a: [low, high).
    double low(int rank, int a) const { return cuts[std::size_t(a)][std::size_t(coordinates(rank)[std::size_t(a)])]; }
    double high(int rank, int a) const { return cuts[std::size_t(a)][std::size_t(coordinates(rank)[std::size_t(a)]) + 1]; }
    // The mean over ranks of the area a rank shares with its neighbours (m²): the cut planes, twice each.
    double shared_area_per_rank() const
    {
        double s = 0.0;
        for (std::size_t a = 0; a < 3; ++a) s += double(dims[a] - 1) * area[a];
        return 2.0 * s / double(ranks());
    }
    std::string grid() const { return fmt::format("{}x{}x{}", dims[0], dims[1], dims[2]); }
};

namespace detail {

// The thinnest interior brick along one axis's cuts (+∞ when there is none, fewer than 3 bricks).
inline double thinnest(const std::vector<double>& cuts)
{
    double w = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i + 2 < cuts.size(); ++i) w = std::min(w, cuts[i + 1] - cuts[i]);
    return w;
}

// `parts` bricks along an axis of sorted coordinates c, balanced as asked.
inline std::vector<double> cut_axis(const std::vector<double>& c, int parts, Balance balance)
{
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> out(std::size_t(parts) + 1, 0.0);
    out.front() = -inf;
    out.back() = inf;
    const double lo = c.empty() ? 0.0 : c.front(), hi = c.empty() ? 0.0 : c.back();
    for (int r = 1; r < parts; ++r) {
        if (balance == Balance::even || c.empty()) {
            out[std::size_t(r)] = lo + (hi - lo) * double(r) / double(parts);
        } else {
            const std::size_t k = c.size() * std::size_t(r) / std::size_t(parts);
            out[std::size_t(r)] = k == 0 ? c[0] : 0.5 * (c[k - 1] + c[k]);
        }
    }
    return out;
}

// The bricks of grid `dims`, each interior one at least `range` thick (count-balanced cuts where they
// allow it, else even ones); false when they cannot be.
inline bool fit_grid(const std::array<std::vector<double>, 3>& c, const std::array<double, 3>& area, const std::array<int, 3>& dims,
                      double range, Balance balance, Bricks& out)
{
    Bricks b;
    b.dims = dims;
    b.area = area;
    for (std::size_t a = 0; a < 3; ++a) {
        b.cuts[a] = cut_axis(c[a], dims[a], balance);
        if (thinnest(b.cuts[a]) < range && balance == Balance::count) b.cuts[a] = cut_axis(c[a], dims[a], Balance::even);
        if (thinnest(b.cuts[a]) < range) return false;
    }
    out = b;
    return true;
}

// The grid of `ranks` bricks whose cut planes have the least area (among equals, the fewest axes cut:
// fewer messages per step); false when every grid leaves a brick too thin.
inline bool best_grid(const std::array<std::vector<double>, 3>& c, const std::array<double, 3>& area, int ranks, double range, Balance balance,
                      Bricks& out)
{
    bool found = false;
    double best = std::numeric_limits<double>::infinity();
    for (int p0 = 1; p0 <= ranks; ++p0) {
        if (ranks % p0) continue;
        for (int p1 = 1; p1 <= ranks / p0; ++p1) {
            if ((ranks / p0) % p1) continue;
            const std::array<int, 3> dims = {p0, p1, ranks / p0 / p1};
            Bricks b;
            if (!fit_grid(c, area, dims, range, balance, b)) continue;
            double cost = 0.0;
            for (std::size_t a = 0; a < 3; ++a) cost += double(dims[a] - 1) * area[a];
            cost *= 1.0 + 1e-9 * double((dims[0] > 1) + (dims[1] > 1) + (dims[2] > 1));
            if (cost < best) {
                best = cost;
                out = b;
                found = true;
            }
        }
    }
    return found;
}

} // namespace detail

// The bricks for `ranks` processes over the particles at x: the grid `dims` if given (non-zero), else
// detail::best_grid's. Returns an empty message on success, else the one-line reason: the grid asked for
// does not fit, or every grid of that many bricks leaves one thinner than the interaction range (with
// the most processes this scene runs on).
inline std::string plan_bricks(const std::vector<Vec3d>& x, int ranks, double range, Balance balance, const std::array<int, 3>& dims,
                               Bricks& out)
{
    std::array<std::vector<double>, 3> c;
    std::array<double, 3> span = {0.0, 0.0, 0.0};
    for (std::size_t a = 0; a < 3; ++a) {
        c[a].reserve(x.size());
        for (const Vec3d& p : x) c[a].push_back(component(p, int(a)));
        std::sort(c[a].begin(), c[a].end());
        span[a] = c[a].empty() ? 0.0 : c[a].back() - c[a].front();
    }
    const std::array<double, 3> area = {span[1] * span[2], span[0] * span[2], span[0] * span[1]};
    const std::string extent = fmt::format("the particles' extent {:.4g} × {:.4g} × {:.4g} m", span[0], span[1], span[2]);
    if (dims[0] > 0) {
        if (dims[0] * dims[1] * dims[2] != ranks)
            return fmt::format("the grid {}x{}x{} has {} bricks, not one per process ({})", dims[0], dims[1], dims[2], dims[0] * dims[1] * dims[2], ranks);
        if (detail::fit_grid(c, area, dims, range, balance, out)) return "";
        return fmt::format("the grid {}x{}x{} leaves a brick thinner than the interaction range {:.4g} m (2·R_max + skin) over {}", dims[0],
                           dims[1], dims[2], range, extent);
    }
    if (detail::best_grid(c, area, ranks, range, balance, out)) return "";
    int most = ranks - 1;
    Bricks scratch;
    while (most > 1 && !detail::best_grid(c, area, most, range, balance, scratch)) --most;
    return fmt::format("{} processes leave a brick thinner than the interaction range {:.4g} m (2·R_max + skin) in every grid of {} "
                       "bricks over {}; this scene runs on at most {} processes",
                       ranks, range, ranks, extent, most);
}

} // namespace demmat::mpi
