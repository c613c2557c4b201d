#pragma once
// Reference computations on a state, independent of any variant: the contact set (every pair, or a
// sorted cell list for large N) and the forces summed in the canonical order. Used for the initial
// accelerations, the driver's health checks and the tests' brute-force cross-checks.
#include <cstdint>
#include <utility>
#include <vector>

#include "demmat/contact_law.hpp"
#include "demmat/contact_memory.hpp"
#include "demmat/model.hpp"
#include "demmat/scene.hpp"
#include "demmat/vec3.hpp"

namespace demmat {

using Pair = std::pair<std::int64_t, std::int64_t>;  // (i, j), i < j

// All pairs with h > 0 as the contact law computes it, sorted by (i, j). O(N²) when brute_force,
// otherwise a sorted cell list with cells of 2·R_max.
std::vector<Pair> contact_pairs(const std::vector<Vec3d>& x, const std::vector<double>& radius, bool brute_force);

// Forces and torques on every particle, in the canonical order of physics.md §6.
void reference_forces(const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w,
                      const std::vector<double>& radius, const std::vector<double>& mass,
                      const std::vector<Wall>& walls, std::int64_t step, double dt,
                      const ContactParams<double>& params, std::vector<Vec3d>& force, std::vector<Vec3d>& torque);

// The same under a law of physics.md §9 (`law`: its flags, law_features), every contact with zero
// stretches that are not advanced: the rule for the t = 0 accelerations (a fresh start has no history).
void reference_forces_law(const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w,
                          const std::vector<double>& radius, const std::vector<double>& mass,
                          const std::vector<Wall>& walls, std::int64_t step, double dt, const ContactParams<double>& params,
                          const MemoryParams<double>& memory, const ModelFeatures& law, std::vector<Vec3d>& force,
                          std::vector<Vec3d>& torque);

} // namespace demmat
