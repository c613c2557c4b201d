// Fuzzes the scene reader: parse_scene on arbitrary text, then for scenes that parse, the validation of
// their particles (initial_state: radii, overlaps, walls, the forces at t = 0) and of the time step, and
// the round trip through scene_to_toml (what `demmat scene` writes must read back to the same scene).
#include <cstddef>
#include <cstdint>
#include <string>

#include "demmat/scene.hpp"
#include "demmat/scene_toml.hpp"
#include "demmat/stability.hpp"
#include "demmat/state.hpp"
#include "demmat/state_file.hpp"
#include "fuzz_common.hpp"

using namespace demmat;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    fuzz::expect_clean([&] {
        Scene s = parse_scene(text, "fuzz.toml");
        const std::string once = scene_to_toml(s);
        const Scene back = parse_scene(once, "round-trip.toml");
        if (scene_to_toml(back) != once) fuzz::defect("scene_to_toml does not read back to the same scene:\n" + once);
        // Validation allocates per particle: keep generated scenes small (the parser is what is fuzzed).
        if (!s.state_file.empty()) return;  // no file system access
        if (s.grid && s.grid->count > 2000) return;
        const State st = initial_state(s);
        check_time_step(s, st);
    });
    return 0;
}
