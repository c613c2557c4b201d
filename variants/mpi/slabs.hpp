#pragma once
// The domain decomposition of the mpi variant: R slabs along one axis, cut at fixed planes chosen at
// init. Rank r owns the particles whose coordinate c along the axis lies in [cut[r], cut[r+1]); the
// first slab reaches down to −∞ and the last up to +∞, so a grain that leaves the domain stays owned.
// A slab's ghosts come from its two neighbours only, which holds while every interior slab is at least
// the interaction range thick (checked at init: a thinner one is refused with a one-line error).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "demmat/vec3.hpp"

namespace demmat::mpi {

// How the cuts are placed: at the quantiles of the particles' coordinates (each slab starts with about
// N/R particles), or evenly over their extent (equal widths: idle ranks where the bed is thin).
enum class Balance { count, even };

struct Slabs {
    int axis = 0;               // 0, 1, 2: x, y, z
    std::vector<double> cuts;   // R + 1 planes; cuts[0] = −∞, cuts[R] = +∞
    double face_area = 0.0;     // m²: the particles' bounding box across the axis at init (a face's area)

    int ranks() const { return int(cuts.size()) - 1; }
    // The rank that owns coordinate c: the last r with cuts[r] <= c (a NaN goes to the last rank; the health
    // checks name it).
    int owner(double c) const
    {
        const auto it = std::upper_bound(cuts.begin() + 1, cuts.end() - 1, c);
        return int(it - (cuts.begin() + 1));
    }
};

// The axis along which the particles' bounding box is longest.
inline int longest_axis(const std::vector<Vec3d>& x)
{
    double lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::numeric_limits<double>::infinity();
        hi[c] = -lo[c];
    }
    for (const Vec3d& p : x)
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], component(p, c));
            hi[c] = std::max(hi[c], component(p, c));
        }
    int best = 0;
    for (int c = 1; c < 3; ++c)
        if (hi[c] - lo[c] > hi[best] - lo[best]) best = c;
    return best;
}

// The thinnest interior slab's width (+∞ when there is none, R <= 2).
inline double thinnest(const Slabs& s)
{
    double w = std::numeric_limits<double>::infinity();
    for (int r = 1; r + 1 < s.ranks(); ++r) w = std::min(w, s.cuts[std::size_t(r) + 1] - s.cuts[std::size_t(r)]);
    return w;
}

// Cuts for `ranks` slabs along `axis`, balanced as asked; when count balancing leaves an interior slab
// thinner than `range` (a dense layer), even widths are tried. Returns an empty message on success,
// else the one-line reason (the process count leaves a slab thinner than the interaction range).
inline std::string plan_slabs(const std::vector<Vec3d>& x, int ranks, double range, Balance balance, Slabs& out)
{
    const double inf = std::numeric_limits<double>::infinity();
    out.axis = longest_axis(x);
    std::vector<double> c;
    c.reserve(x.size());
    for (const Vec3d& p : x) c.push_back(component(p, out.axis));
    std::sort(c.begin(), c.end());
    {
        double span[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 3; ++k) {
            double a = std::numeric_limits<double>::infinity(), b = -a;
            for (const Vec3d& p : x) {
                a = std::min(a, component(p, k));
                b = std::max(b, component(p, k));
            }
            span[k] = x.empty() ? 0.0 : b - a;
        }
        out.face_area = span[(out.axis + 1) % 3] * span[(out.axis + 2) % 3];
    }
    const double lo = c.empty() ? 0.0 : c.front(), hi = c.empty() ? 0.0 : c.back();
    auto make = [&](Balance b) {
        out.cuts.assign(std::size_t(ranks) + 1, 0.0);
        out.cuts.front() = -inf;
        out.cuts.back() = inf;
        for (int r = 1; r < ranks; ++r) {
            if (b == Balance::even || c.empty()) {
                out.cuts[std::size_t(r)] = lo + (hi - lo) * double(r) / double(ranks);
            } else {
                const std::size_t k = c.size() * std::size_t(r) / std::size_t(ranks);
                out.cuts[std::size_t(r)] = k == 0 ? c[0] : 0.5 * (c[k - 1] + c[k]);
            }
        }
    };
    make(balance);
    if (thinnest(out) >= range) return "";
    if (balance == Balance::count) {
        make(Balance::even);
        if (thinnest(out) >= range) return "";
    }
    const char* names = "xyz";
    const int most = std::max(2, int(std::floor((hi - lo) / range)));
    return fmt::format("{} processes leave a slab {:.4g} m thick along {}, thinner than the interaction range {:.4g} m "
                       "(2·R_max); this scene runs on at most {} processes", ranks, thinnest(out), names[out.axis], range, most);
}

} // namespace demmat::mpi
