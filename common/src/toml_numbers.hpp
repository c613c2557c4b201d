#pragma once
// Numbers from toml11 as the file writes them: toml11 reads 1e400 as the largest double and 1e-400 as 0
// without a word, so the readers (scene.cpp, contact_model.cpp) check a literal's text and quote it.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <toml.hpp>

namespace demmat {

// The text of a value as the file writes it (toml11's location), or the value printed when unknown;
// control characters shown as \xNN, for one-line messages.
inline std::string toml_written(const toml::value& x)
{
    const auto where = x.location();
    std::string text;
    if (where.column() >= 1 && where.region() >= 1 && where.column() - 1 + where.region() <= where.line_str().size())
        text = where.line_str().substr(where.column() - 1, where.region());
    else
        text = x.is_floating() ? fmt::format("{}", x.as_floating()) : x.is_integer() ? std::to_string(x.as_integer()) : "?";
    std::string out;
    for (unsigned char c : text) out += (c < 0x20 || c == 0x7F) ? fmt::format("\\x{:02x}", c) : std::string(1, char(c));
    return out;
}

// Why the number `x` (an integer or a float) cannot be taken as read, naming it `name`, or "" when it can:
// not finite, beyond the range of a double, or below it (a non-zero literal read as 0).
inline std::string toml_number_problem(const toml::value& x, const std::string& name)
{
    const double d = x.is_floating() ? x.as_floating() : double(x.as_integer());
    const std::string text = toml_written(x);
    if (!std::isfinite(d)) return fmt::format("'{}' must be finite (got {})", name, text);
    if (!x.is_floating()) return {};
    std::string plain;
    for (char c : text)
        if (c != '_') plain += c;
    errno = 0;
    const double exact = std::strtod(plain.c_str(), nullptr);
    if (errno == ERANGE && std::abs(exact) > 1.0) return fmt::format("'{}' = {} is beyond the range of a double (about 1.8e308)", name, text);
    if (d == 0.0 && plain.find_first_of("123456789") < plain.find_first_of("eE"))
        return fmt::format("'{}' = {} is below the range of a double (it would read as 0)", name, text);
    return {};
}

} // namespace demmat
