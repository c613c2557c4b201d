#pragma once
// The suite's standard scenes, built in code so that `demmat scene` writes them as editable files and
// tests use exactly the same definitions.
#include <cstdint>
#include <filesystem>

#include "demmat/scene.hpp"

namespace demmat {

// The paper's literal test, stage 1 (physics.md §7): 1000 particles (or `count`) at the centres of a
// regular grid filling a 2 m closed box, random speeds in [0, 1] m/s, free compaction under gravity.
Scene paper_scene(std::int64_t count = 1000, std::uint64_t seed = 1);

// A dense-bed family for any N: the paper's material, a closed box sized to the grains (a lattice of
// nx·ny·nz sites 2.1·R_max apart, nx = ny = ceil(cbrt N), at most max_layers deep: wider beyond
// N = max_layers³), so cost per particle compares across N.
inline constexpr std::int64_t dense_bed_max_layers = 12;  // why 12: scenes.cpp
Scene dense_bed_scene(std::int64_t count, std::uint64_t seed = 1, std::int64_t max_layers = dense_bed_max_layers);

// A settled state as a scene of its own, every wall still (the benchmarks' settled bed).
Scene settled_scene(const Scene& settled, const std::filesystem::path& state_file);
// Stage 2 of the paper's test from a settled state: the x_max wall moves inwards at `speed` m/s.
Scene compression_scene(const Scene& settled, const std::filesystem::path& state_file, double speed = 0.5);

// Two-body validation scenes: a head-on pair at relative speed `speed` (no gravity, no walls), and a
// sphere released at rest `gap` metres above a wall under gravity.
Scene head_on_scene(double speed = 1.0, double radius = 0.004);
Scene drop_scene(double gap = 0.001, double radius = 0.004);

} // namespace demmat
