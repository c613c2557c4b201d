// The contact law's names, description and fingerprint (physics.md §9); the scene's [contact] table is
// read by the harness (contact_model_toml.cpp).
#include "demmat/contact_model.hpp"

#include <fmt/format.h>

namespace demmat {

const char* name(NormalDamping d)
{
    switch (d) {
    case NormalDamping::tsuji: return "tsuji";
    case NormalDamping::restitution: return "restitution";
    case NormalDamping::viscous: break;
    }
    return "viscous";
}
const char* name(TangentialModel t)
{
    switch (t) {
    case TangentialModel::linear_history: return "linear_history";
    case TangentialModel::mindlin: return "mindlin";
    case TangentialModel::viscous: break;
    }
    return "viscous";
}
const char* name(RollingModel r) { return r == RollingModel::sds ? "sds" : "none"; }
const char* name(StretchUpdate u) { return u == StretchUpdate::trapezoidal ? "trapezoidal" : "first_order"; }

std::string ContactModel::describe() const
{
    std::string s = fmt::format("damping {}", name(damping));
    if (damping != NormalDamping::viscous) s += fmt::format(" (restitution = {})", restitution);
    s += fmt::format(", tangential {}", name(tangential));
    if (tangential == TangentialModel::linear_history)
        s += fmt::format(" (kt = {} N/m, tangential_damping_ratio = {})", kt, tangential_damping_ratio);
    if (tangential == TangentialModel::mindlin) s += fmt::format(" (tangential_damping_ratio = {})", tangential_damping_ratio);
    s += fmt::format(", rolling {}", name(rolling));
    if (rolling == RollingModel::sds)
        s += fmt::format(" (kr = {} N/m, rolling_damping = {} N·s/m, rolling_friction = {})", kr, rolling_damping, rolling_friction);
    if (stretch_update != StretchUpdate::first_order) s += fmt::format(", stretch update {}", name(stretch_update));
    return s;
}

std::string ContactModel::toml() const
{
    if (is_paper()) return {};
    std::string o = "[contact]                          # the contact law (physics.md §9)\n";
    o += fmt::format("damping = \"{}\"\n", name(damping));
    if (damping != NormalDamping::viscous) o += fmt::format("restitution = {}\n", restitution);
    o += fmt::format("tangential = \"{}\"\n", name(tangential));
    if (tangential == TangentialModel::linear_history) o += fmt::format("kt = {}\n", kt);
    if (tangential != TangentialModel::viscous) o += fmt::format("tangential_damping_ratio = {}\n", tangential_damping_ratio);
    o += fmt::format("rolling = \"{}\"\n", name(rolling));
    if (rolling == RollingModel::sds)
        o += fmt::format("kr = {}\nrolling_damping = {}\nrolling_friction = {}\n", kr, rolling_damping, rolling_friction);
    if (stretch_update != StretchUpdate::first_order) o += fmt::format("stretch_update = \"{}\"\n", name(stretch_update));
    return o;
}

std::vector<double> ContactModel::fingerprint_values() const
{
    if (is_paper()) return {};
    std::vector<double> v{double(int(damping)), restitution, double(int(tangential)), kt, tangential_damping_ratio, double(int(rolling)),
                          kr, rolling_damping, rolling_friction};
    if (stretch_update != StretchUpdate::first_order) v.push_back(double(int(stretch_update)));  // older fingerprints unchanged
    return v;
}

} // namespace demmat
