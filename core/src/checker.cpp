#include "demmat/checker.hpp"

#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "demmat/driver.hpp"
#include "demmat/registry.hpp"

namespace demmat {

std::uint64_t ulp_distance(double a, double b)
{
    // Map the bits to a monotone integer line (negative numbers reversed), then subtract.
    auto ordered = [](double d) {
        std::int64_t i;
        std::memcpy(&i, &d, sizeof d);
        return i < 0 ? std::int64_t(0x8000000000000000ull) - i : i;
    };
    const std::int64_t x = ordered(a), y = ordered(b);
    if (std::memcmp(&a, &b, sizeof a) == 0) return 0;
    const std::uint64_t d = x > y ? std::uint64_t(x) - std::uint64_t(y) : std::uint64_t(y) - std::uint64_t(x);
    return d == 0 ? 1 : d;  // +0 and -0: different bits, one apart
}

std::string Difference::describe() const
{
    return fmt::format("step {}: particle {} {} differs: {} = {:.17g}, {} = {:.17g} ({} ulp)", step, particle, quantity,
                       variant_a, a, variant_b, b, ulps);
}

std::optional<Difference> first_difference(const Snapshot& a, const Snapshot& b)
{
    const std::pair<const char*, const std::vector<Vec3d> Snapshot::*> fields[] = {
        {"position", &Snapshot::position}, {"velocity", &Snapshot::velocity}, {"angular_velocity", &Snapshot::angular_velocity},
        {"force", &Snapshot::force},       {"torque", &Snapshot::torque}};
    const char* axes[] = {"x", "y", "z"};
    if (a.position.size() != b.position.size()) {
        Difference d;
        d.quantity = fmt::format("particle count ({} against {})", a.position.size(), b.position.size());
        return d;
    }
    // Particle-major so that the report names the lowest particle id that differs.
    for (std::size_t i = 0; i < a.position.size(); ++i)
        for (const auto& [name, member] : fields)
            for (int c = 0; c < 3; ++c) {
                const double x = component((a.*member)[i], c), y = component((b.*member)[i], c);
                if (std::memcmp(&x, &y, sizeof x) != 0) {
                    Difference d;
                    d.step = a.step;
                    d.particle = std::int64_t(i);
                    d.quantity = fmt::format("{}.{}", name, axes[c]);
                    d.a = x;
                    d.b = y;
                    d.ulps = ulp_distance(x, y);
                    return d;
                }
            }
    return std::nullopt;
}

CompareReport compare_variants(const std::vector<std::string>& names, const Setup& setup, std::int64_t steps)
{
    std::vector<std::unique_ptr<Variant>> variants;
    std::vector<std::unique_ptr<Driver>> drivers;
    for (const auto& n : names) {
        variants.push_back(registry().find(n).create());
        drivers.push_back(std::make_unique<Driver>(*variants.back(), setup));
    }
    CompareReport report;
    std::vector<Snapshot> snaps(names.size());
    for (std::int64_t k = 0; k <= steps; ++k) {
        if (k > 0)
            for (auto& d : drivers) d->step();
        for (std::size_t v = 0; v < names.size(); ++v) {
            variants[v]->snapshot(snaps[v]);
            snaps[v].step = drivers[v]->current_step();
        }
        for (std::size_t v = 1; v < names.size(); ++v)
            if (auto d = first_difference(snaps[0], snaps[v])) {
                d->variant_a = names[0];
                d->variant_b = names[v];
                report.difference = d;
                report.steps = k;
                return report;
            }
        report.steps = k;
    }
    return report;
}

} // namespace demmat
