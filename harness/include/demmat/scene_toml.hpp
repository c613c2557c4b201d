#pragma once
// Scene files (TOML, docs/scene-format.md): reading, validating and writing the scene a run describes.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "demmat/contact_model.hpp"
#include "demmat/scene.hpp"

namespace demmat {

// The largest scene file read (1 GiB): a TOML scene is text a person edits; toml11 holds several times
// the text in memory, and a list of 10^6 particles is about 200 MB (larger sets come from a state file
// or the grid generator). The cap also stops a device such as /dev/zero at once (io.hpp, read_input_file).
inline constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t(1) << 30;

Scene load_scene(const std::filesystem::path& file);
// A command's --integrator/--precision (either may be empty: unchanged), replacing the scene's
// [integrator] before anything depends on it (the time-step check compares Δt with the chosen scheme's
// stability limit); an unknown name is a one-line error.
void override_integrator(Scene& s, const std::string& integrator, const std::string& precision);
Scene parse_scene(const std::string& toml_text, const std::string& label);
std::string scene_to_toml(const Scene& scene);

// The [contact] table itself is read by parse_contact_model (harness/src/contact_model_toml.hpp).

// `demmat scene --contact KEY=VALUE …`: the same keys and checks as the table.
ContactModel contact_model_from_options(const std::vector<std::string>& key_values);

} // namespace demmat
