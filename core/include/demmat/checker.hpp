#pragma once
// The equivalence checker: runs variants side by side from one initial state and compares their
// snapshots bit for bit after every step, reporting the first step, particle, quantity and ulps.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "demmat/variant.hpp"

namespace demmat {

// Distance in units in the last place between two doubles (0 when bitwise equal; +0 and -0 differ
// by 1 here on purpose, since bit identity is what the suite promises).
std::uint64_t ulp_distance(double a, double b);

struct Difference {
    std::int64_t step = 0;
    std::int64_t particle = 0;
    std::string quantity;  // e.g. "velocity.y"
    double a = 0.0, b = 0.0;
    std::uint64_t ulps = 0;
    std::string variant_a, variant_b;
    std::string describe() const;
};

std::optional<Difference> first_difference(const Snapshot& a, const Snapshot& b);

struct CompareReport {
    std::int64_t steps = 0;  // steps compared
    std::optional<Difference> difference;
};

// Runs the named variants in lockstep for `steps` steps from the setup's state; compares every
// variant with the first after each step (and after initialisation, as step `start`).
CompareReport compare_variants(const std::vector<std::string>& names, const Setup& setup, std::int64_t steps);

} // namespace demmat
