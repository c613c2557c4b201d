// Fuzzes the state reader: parse_state on arbitrary bytes (what load_state does after reading the file).
// A state that loads must save to the same bytes.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include "demmat/state.hpp"
#include "demmat/state_file.hpp"
#include "fuzz_common.hpp"

using namespace demmat;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    fuzz::expect_clean([&] {
        const State s = parse_state(bytes, "fuzz.state");
        // Round trip (rare: the checksum must match): the writer reproduces the file exactly.
        const auto file = std::filesystem::temp_directory_path() / ("demmat_fuzz_" + std::to_string(::getpid()) + ".state");
        save_state(s, file);
        std::ifstream in(file, std::ios::binary);
        const std::string again((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::filesystem::remove(file);
        if (again != bytes) fuzz::defect("a state that loads does not save to the same bytes");
    });
    return 0;
}
