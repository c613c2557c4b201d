#include "demmat/features.hpp"

#include <cstdint>
#include <cstring>

namespace demmat {

namespace {
// True for anything but +0.0: a −0 spin or wall velocity changes the sign of a zero somewhere, so it
// counts as present (the general model then runs, bit for bit as before).
bool set(double d)
{
    std::uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    return b != 0;
}
bool set(const Vec3d& v) { return set(v.x) || set(v.y) || set(v.z); }
bool any_set(const std::vector<Vec3d>& a)
{
    for (const Vec3d& v : a)
        if (set(v)) return true;
    return false;
}
} // namespace

ModelFeatures features_of(const Scene& scene, const State& state)
{
    const ContactParams<double> p = scene.contact_params();
    ModelFeatures f;
    f.friction = set(p.mu) && set(p.gamma_t);
    f.rotation = f.friction || any_set(state.rot.v) || any_set(state.rot.a) || any_set(state.rot.b3) ||
                 any_set(state.rot.b4) || any_set(state.rot.b5);
    f.damping = set(p.gamma_n);
    f.walls = !state.walls.empty();
    for (const Wall& w : state.walls) f.moving_walls = f.moving_walls || set(w.velocity);
    for (double r : state.radius)
        if (std::memcmp(&r, &state.radius.front(), sizeof r) != 0) f.polydisperse = true;
    const ModelFeatures law = law_features(scene.contact_model);
    f.restitution_damping = law.restitution_damping;
    f.history = law.history;
    f.rolling = law.rolling;
    return f;
}

ModelFeatures law_features(const ContactModel& law)
{
    ModelFeatures f;
    f.restitution_damping = law.damping != NormalDamping::viscous;
    f.history = law.tangential != TangentialModel::viscous;
    f.rolling = law.rolling != RollingModel::none;
    return f;
}

} // namespace demmat
