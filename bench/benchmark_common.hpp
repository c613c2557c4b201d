#pragma once
// What the Google Benchmark programs (bench_suite.cpp, bench_features.cpp) share: taking their own
// options out of argv, and the provenance of their results.
//
// Their results carry the same provenance block as every other demmat result
// (provenance_json(), output.hpp: commit, "dirty" a boolean, compiler, flags, build type, CPU, host, date),
// as "provenance" at the top of the JSON that --benchmark_out writes. (Google Benchmark's own context
// holds strings only, so the block is added to the file after the run.)
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/output.hpp"

namespace demmat {

// Takes the program's own options, --KEY=VALUE, out of argv (Google Benchmark rejects what it does not
// know): own(KEY, VALUE) applies one and returns true, or returns false to leave the argument to Google
// Benchmark. On an Error (a bad value) prints "program: message" and returns false.
inline bool take_own_options(int& argc, char** argv, const char* program,
                             const std::function<bool(std::string_view key, const char* value)>& own)
{
    try {
        int out = 1;
        for (int i = 1; i < argc; ++i) {
            const char* eq = std::strchr(argv[i], '=');
            if (!(std::strncmp(argv[i], "--", 2) == 0 && eq && own(std::string_view(argv[i], std::size_t(eq - argv[i])), eq + 1)))
                argv[out++] = argv[i];
        }
        argc = out;
        return true;
    } catch (const Error& e) {
        std::cerr << program << ": " << e.what() << "\n";
        return false;
    }
}

// The file --benchmark_out=FILE names when its format is JSON (the default), else empty. Call before
// benchmark::Initialize, which consumes the flags.
inline std::string benchmark_json_out(int argc, char** argv)
{
    std::string file, format = "json";
    for (int i = 1; i < argc; ++i) {
        if (std::strncmp(argv[i], "--benchmark_out=", 16) == 0) file = argv[i] + 16;
        if (std::strncmp(argv[i], "--benchmark_out_format=", 23) == 0) format = argv[i] + 23;
    }
    return format == "json" ? file : std::string();
}

// Adds {"provenance": provenance_json()} to the JSON results file (nothing when `file` is empty).
inline void add_provenance(const std::string& file)
{
    if (file.empty()) return;
    std::ifstream in(file);
    nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object()) throw Error(file + ": not the JSON results file Google Benchmark writes");
    j["provenance"] = provenance_json();
    write_atomically(file, j.dump(2) + "\n");
}

} // namespace demmat
