#pragma once
// The full dynamic state of a run, in particle-id order: every Gear value for translation and
// rotation, the walls and the step count. A run saved and continued from this state is bit-identical
// to a run that never stopped.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "demmat/scene.hpp"
#include "demmat/vec3.hpp"

namespace demmat {

struct GearState {  // six values per degree of freedom, for all particles
    std::vector<Vec3d> x, v, a, b3, b4, b5;
    void resize(std::size_t n) { x.resize(n); v.resize(n); a.resize(n); b3.resize(n); b4.resize(n); b5.resize(n); }
};

// One live contact's stretches (physics.md §9), keyed by ids, never by a slot: the pair (i, partner),
// i < partner, or particle i and wall index `partner` when `wall`. A state holds them in the canonical
// order (by i; then its particle partners ascending; then its walls in wall order).
struct ContactStretch {
    std::int64_t i = 0;
    std::int64_t partner = 0;
    bool wall = false;
    Vec3d tangential, rolling;  // ξ and ξ_r, metres (zero where the law has no such spring)

    bool operator<(const ContactStretch& o) const
    {
        if (i != o.i) return i < o.i;
        if (wall != o.wall) return !wall;
        return partner < o.partner;
    }
};

struct State {
    std::int64_t step = 0;          // steps taken since the scene's t = 0; time = step·Δt
    double dt = 0.0;
    std::uint64_t fingerprint = 0;  // Scene::fingerprint of the scene that wrote it
    std::vector<double> radius;
    GearState trans;                // position, velocity, acceleration, b3, b4, b5
    GearState rot;                  // orientation, angular velocity, angular acceleration, b3, b4, b5
    std::vector<Wall> walls;
    std::vector<ContactStretch> stretches;  // every live contact's, for a §9 law with memory; else empty

    std::size_t size() const { return radius.size(); }
    void resize(std::size_t n) { radius.resize(n); trans.resize(n); rot.resize(n); }
};

// The twelve Gear arrays of a state (translation x, v, a, b3, b4, b5, then rotation) in the column
// layout of the array-based variants: each an array of 3N, an x block, a y block, a z block, in T.
template <class T>
void load_gear_columns(const State& s, const std::array<std::vector<T>*, 12>& dst)
{
    const std::vector<Vec3d>* src[12] = {&s.trans.x, &s.trans.v, &s.trans.a, &s.trans.b3, &s.trans.b4, &s.trans.b5,
                                         &s.rot.x,   &s.rot.v,   &s.rot.a,   &s.rot.b3,   &s.rot.b4,   &s.rot.b5};
    const std::size_t n = s.size();
    for (int k = 0; k < 12; ++k) {
        dst[k]->assign(3 * n, T(0));
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) (*dst[k])[std::size_t(c) * n + i] = T(component((*src[k])[i], c));
    }
}

} // namespace demmat
