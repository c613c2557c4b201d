// The scene's [contact] table (docs/scene-format.md): which law of physics.md §9 a run uses.
#include "contact_model_toml.hpp"
#include "demmat/scene_toml.hpp"
#include "toml_numbers.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "demmat/error.hpp"

namespace demmat {

namespace {

// The table's keys, each read at most once; a key the chosen models do not read is an error.
class ContactTable {
public:
    ContactTable(const toml::value& v, std::string label) : v_(v), label_(std::move(label))
    {
        if (!v_.is_table()) fail("'contact' must be a table ([contact])");
    }
    [[noreturn]] void fail(const std::string& msg) const { throw Error(fmt::format("{}: {}", label_, msg)); }
    bool has(const std::string& key) const { return v_.as_table().count(key) != 0; }

    template <class E>
    E model(const std::string& key, std::initializer_list<E> all)
    {
        if (!has(key)) return *all.begin();
        used_.insert(key);
        const auto& x = v_.as_table().at(key);
        const std::string got = x.is_string() ? x.as_string().str : std::string();
        std::string expected;
        for (E e : all) {
            if (got == name(e)) return e;
            expected += (expected.empty() ? "" : ", ") + std::string(name(e));
        }
        if (!x.is_string()) fail(fmt::format("'contact.{}' must be a string ({})", key, expected));
        fail(fmt::format("unknown contact.{} '{}' (expected {})", key, printable(got), expected));
    }
    // A number the chosen model needs: missing, not a number or not finite is an error naming the key.
    double number(const std::string& key, const std::string& needed_by)
    {
        if (!has(key)) fail(fmt::format("missing key 'contact.{}' (needed by {})", key, needed_by));
        used_.insert(key);
        const auto& x = v_.as_table().at(key);
        if (!x.is_floating() && !x.is_integer()) fail(fmt::format("'contact.{}' must be a number", key));
        if (const std::string problem = toml_number_problem(x, "contact." + key); !problem.empty()) fail(problem);
        return x.is_floating() ? x.as_floating() : double(x.as_integer());
    }
    double positive(const std::string& key, const std::string& needed_by)
    {
        const double d = number(key, needed_by);
        if (!(d > 0.0)) fail(fmt::format("'contact.{}' must be > 0 (got {})", key, d));
        return d;
    }
    double non_negative(const std::string& key, const std::string& needed_by)
    {
        const double d = number(key, needed_by);
        if (d < 0.0) fail(fmt::format("'contact.{}' must be >= 0 (got {})", key, d));
        return d;
    }
    void close(const ContactModel& m) const
    {
        static const std::set<std::string> known = {"damping", "restitution", "tangential", "kt", "tangential_damping_ratio",
                                                    "rolling", "kr", "rolling_damping", "rolling_friction",
                                                    "stretch_update"};
        for (const auto& [key, _] : v_.as_table()) {
            if (used_.count(key)) continue;
            if (!known.count(key)) fail(fmt::format("unknown key '{}' in [contact]", printable(key)));
            fail(fmt::format("'contact.{}' is not used by this law ({})", key, m.describe()));
        }
    }

private:
    static std::string printable(const std::string& s)
    {
        std::string out;
        for (unsigned char c : s) out += (c < 0x20 || c == 0x7F) ? fmt::format("\\x{:02x}", c) : std::string(1, char(c));
        return out;
    }
    const toml::value& v_;
    std::string label_;
    std::set<std::string> used_;
};

} // namespace

ContactModel parse_contact_model(const toml::value& v, const std::string& label)
{
    ContactTable t(v, label);
    ContactModel m;
    m.damping = t.model("damping", {NormalDamping::viscous, NormalDamping::tsuji, NormalDamping::restitution});
    m.tangential = t.model("tangential", {TangentialModel::viscous, TangentialModel::linear_history, TangentialModel::mindlin});
    m.rolling = t.model("rolling", {RollingModel::none, RollingModel::sds});
    if (m.damping != NormalDamping::viscous) {
        const std::string by = fmt::format("damping = \"{}\"", name(m.damping));
        m.restitution = t.number("restitution", by);
        if (!(m.restitution > 0.0 && m.restitution <= 1.0))
            t.fail(fmt::format("'contact.restitution' must lie in (0, 1] (got {})", m.restitution));
    }
    if (m.tangential != TangentialModel::viscous) {
        const std::string by = fmt::format("tangential = \"{}\"", name(m.tangential));
        if (m.tangential == TangentialModel::linear_history) m.kt = t.positive("kt", by);
        m.tangential_damping_ratio = t.non_negative("tangential_damping_ratio", by);
    }
    if (m.rolling == RollingModel::sds) {
        m.kr = t.positive("kr", "rolling = \"sds\"");
        m.rolling_damping = t.non_negative("rolling_damping", "rolling = \"sds\"");
        m.rolling_friction = t.non_negative("rolling_friction", "rolling = \"sds\"");
    }
    if (m.has_spring()) m.stretch_update = t.model("stretch_update", {StretchUpdate::first_order, StretchUpdate::trapezoidal});
    t.close(m);
    return m;
}

ContactModel contact_model_from_options(const std::vector<std::string>& key_values)
{
    std::string text = "[contact]\n";
    for (const std::string& kv : key_values) {
        const auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0)
            throw Error(fmt::format("--contact '{}': expected KEY=VALUE (keys as in the scene's [contact] table)", kv));
        const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
        for (char c : key)
            if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) throw Error(fmt::format("--contact '{}': not a key", kv));
        char* end = nullptr;
        errno = 0;
        const double parsed = std::strtod(value.c_str(), &end);
        const bool number = !value.empty() && *end == '\0';
        // toml11 would read 1e400 as the largest double and 1e-400 as 0 without a word.
        if (number && errno == ERANGE && (std::abs(parsed) > 1.0 || parsed == 0.0))
            throw Error(fmt::format("--contact {}: {} is beyond the range of a double", kv, value));
        std::string quoted = "\"";
        for (char c : value) {
            if (static_cast<unsigned char>(c) < 0x20) throw Error(fmt::format("--contact '{}': control character in the value", key));
            if (c == '"' || c == '\\') quoted += '\\';
            quoted += c;
        }
        text += key + " = " + (number ? value : quoted + "\"") + "\n";
    }
    toml::value root;
    try {
        std::istringstream in(text);
        root = toml::parse(in, "--contact");
    } catch (const std::exception&) {
        throw Error("--contact: the options do not make a valid [contact] table (a key given twice, or a malformed number)");
    }
    return parse_contact_model(root.at("contact"), "--contact");
}

} // namespace demmat
