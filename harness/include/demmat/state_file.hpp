#pragma once
// State files (binary, docs/state-format.md) and the initial state a scene describes.
#include <filesystem>
#include <string>
#include <vector>

#include "demmat/scene.hpp"
#include "demmat/state.hpp"

namespace demmat {

// Binary state file (format in docs/state-format.md); written to a temporary file and renamed.
void save_state(const State& state, const std::filesystem::path& file);
State load_state(const std::filesystem::path& file);
// The same from the file's bytes (label names the source in messages); every damage is an Error.
State parse_state(const std::string& bytes, const std::string& label);

// Walls of a run that starts from a saved state: a wall the state knows keeps its position; if the
// scene gives it another velocity, its motion is re-anchored at the state's step (a new stage, such as
// compression after settling). A wall the state does not know starts where the scene puts it.
std::vector<Wall> continue_walls(const Scene& scene, const State& saved);

// The initial state of a scene: its particles (generated, listed or loaded), its walls, and at t = 0
// the accelerations a = F/m + g, α = T/I from the initial positions and velocities (b3 = b4 = b5 = 0).
// Validates the particles (radii, overlaps, walls) and throws Error with one line on bad input.
State initial_state(const Scene& scene);

// The t = 0 accelerations of a state that starts afresh (design.md, decision 4): a = F(x, v)/m + g and
// α = T/I, the forces and torques summed in the canonical order by the reference code (reference.hpp).
// Sets trans.a and rot.a; the other Gear values are left as they are.
void initial_accelerations(const Scene& scene, State& state);

} // namespace demmat
