// Host-side messages of the cuda variant (both backends): the errors its search reports through the
// status words, worded as the arrays variant words them.
#include <fmt/format.h>

#include "demmat/error.hpp"
#include "gpu_variant.hpp"

namespace demmat::gpu {

void throw_status(const unsigned long long (&status)[kStatusWords], std::uint32_t cap_above, std::uint32_t row_cap,
                  std::uint32_t cap_walls, std::size_t walls)
{
    auto count = [](unsigned long long w) { return std::int64_t(w >> 32); };
    auto particle = [](unsigned long long w) { return std::int64_t(0xffffffffu - (w & 0xffffffffu)); };
    if (const auto w = status[kRunaway])
        throw InstabilityError(fmt::format("particle {} has a non-finite or runaway position (found by the cell search)", w - 1), -1,
                               std::int64_t(w - 1));
    if (const auto w = status[kAboveOverflow])
        throw CapacityError(fmt::format("capacity.contacts_per_particle = {} exceeded: particle {} has {} candidate partners; set it "
                                        "to at least {} in the scene", cap_above, particle(w), count(w), count(w)));
    if (const auto w = status[kRowOverflow])
        throw CapacityError(fmt::format("capacity.contacts_per_particle = {} exceeded: particle {} has {} candidate partners in all "
                                        "(the cuda variant stores both sides, twice the capacity); set it to at least {} in the scene",
                                        cap_above, particle(w), count(w), (count(w) + 1) / 2));
    if (const auto w = status[kWallOverflow])
        throw CapacityError(fmt::format("capacity.wall_contacts_per_particle = {} exceeded: particle {} touches more walls; set it to "
                                        "{} (the number of walls)", cap_walls, particle(w), walls));
    (void)row_cap;
}

void throw_state_overflow(std::uint32_t cap, bool wall, std::int64_t particle)
{
    if (wall)
        throw CapacityError(fmt::format("the state holds more wall contacts of particle {} than capacity.wall_contacts_per_particle = {}",
                                        particle, cap));
    throw CapacityError(fmt::format("the state holds more contacts of particle {} than the cuda variant's rows of {} (both sides, twice "
                                    "capacity.contacts_per_particle = {})", particle, cap, cap / 2));
}

void check_size(std::size_t particles, std::size_t walls)
{
    if (walls > std::size_t(kMaxWalls))
        throw Error(fmt::format("the cuda variant runs scenes of at most {} walls; this one has {}", kMaxWalls, walls));
    if (particles >= 0xffffffffu)
        throw Error(fmt::format("the cuda variant runs at most {} particles; this scene has {}", 0xffffffffu - 1, particles));
}

} // namespace demmat::gpu
