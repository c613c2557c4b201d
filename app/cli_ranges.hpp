#pragma once
// Range checks for the numeric options of `demmat`, with messages a person can read: the value as
// typed and the range in plain numbers (CLI11's own range validators print the limits of a double in
// full, 309 digits, and its integer conversion clamps 10^20 to 2^63 - 1 without a word).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace demmat {

// Step counts up to 2^53: beyond that a step is not exact in a double (time = step·Δt).
inline constexpr std::int64_t kMaxSteps = std::int64_t(1) << 53;

// The most threads an option accepts: 4 per processor (oversubscription can still be studied, beyond it
// a threaded variant only times the scheduler: its threads wait at every barrier), never above 4096.
inline int max_thread_count()
{
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    return int(std::min(4096u, 4u * cores));
}
inline std::string thread_limit_reason()
{
    return fmt::format("at most 4 per processor, {} processors here", std::max(1u, std::thread::hardware_concurrency()));
}

namespace cli_detail {
// The value as typed, shortened if long (a 400-digit number is not repeated in full).
inline std::string shown(const std::string& text) { return text.size() <= 24 ? text : text.substr(0, 20) + "..."; }
} // namespace cli_detail

// An integer in [lo, hi]; `why` (optional) says where the limit comes from.
inline CLI::Validator integer_in(std::int64_t lo, std::int64_t hi, std::string why = {})
{
    auto check = [lo, hi, why](std::string& text) -> std::string {
        std::int64_t v = 0;
        const char* begin = text.data();
        const char* end = begin + text.size();
        const auto [stop, ec] = std::from_chars(begin, end, v);
        const bool digits = stop == end && !text.empty();
        if ((ec == std::errc::result_out_of_range && digits) || (ec == std::errc() && digits && (v < lo || v > hi)))
            return fmt::format("{} is out of range ({} to {}{}{})", cli_detail::shown(text), lo, hi, why.empty() ? "" : ": ", why);
        if (ec != std::errc() || !digits) return fmt::format("'{}' is not an integer", cli_detail::shown(text));
        return {};
    };
    return CLI::Validator(check, fmt::format("INT in [{}, {}]", lo, hi));
}

// A finite number >= lo (or > lo when `open`).
inline CLI::Validator number_from(double lo, bool open)
{
    auto check = [lo, open](std::string& text) -> std::string {
        char* stop = nullptr;
        const double v = std::strtod(text.c_str(), &stop);
        if (text.empty() || stop != text.c_str() + text.size()) return fmt::format("'{}' is not a number", cli_detail::shown(text));
        if (!std::isfinite(v)) return fmt::format("{} is not a finite number", cli_detail::shown(text));
        if (open ? !(v > lo) : !(v >= lo)) return fmt::format("{} must be {} {:g}", cli_detail::shown(text), open ? ">" : ">=", lo);
        return {};
    };
    return CLI::Validator(check, fmt::format("NUMBER {} {:g}", open ? ">" : ">=", lo));
}

// A file or folder name: given, so not empty (`--json ''` would otherwise silently write nothing).
inline CLI::Validator path_given()
{
    return CLI::Validator([](std::string& text) -> std::string { return text.empty() ? "an empty name; give a file or folder name" : ""; },
                          "PATH");
}

} // namespace demmat
