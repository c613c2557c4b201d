#include "demmat/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml.hpp>

#include "contact_model_toml.hpp"
#include "toml_numbers.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/stability.hpp"

namespace demmat {

namespace {

constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();  // capacities, counts: stored as int

// s with control characters shown as \xNN, for one-line messages.
std::string printable(const std::string& s)
{
    std::string out;
    for (unsigned char c : s) out += (c < 0x20 || c == 0x7F) ? fmt::format("\\x{:02x}", c) : std::string(1, char(c));
    return out;
}

// A view of one TOML table that knows its path for messages and rejects keys it was not asked about
// (a misspelt key is an error, not a silently ignored setting).
class Table {
public:
    Table(const toml::value& v, std::string path, std::string label) : v_(v), path_(std::move(path)), label_(std::move(label))
    {
        if (!v_.is_table()) fail(fmt::format("'{}' must be a table", path_));
    }
    ~Table() noexcept(false)
    {
        if (std::uncaught_exceptions()) return;
        close();
    }
    // Rejects the keys nobody asked about. Tables held in a vector (tables()) must be closed explicitly:
    // an exception from a destructor that a vector runs is std::terminate (found by fuzz/fuzz_scene).
    void close()
    {
        if (closed_) return;
        closed_ = true;
        for (const auto& [key, _] : v_.as_table())
            if (!used_.count(key)) fail(fmt::format("unknown key '{}' in {}", printable(key), where()));
    }
    bool has(const std::string& key) const { return v_.as_table().count(key) != 0; }
    const toml::value& raw(const std::string& key)
    {
        used_.insert(key);
        auto it = v_.as_table().find(key);
        if (it == v_.as_table().end()) fail(fmt::format("missing key '{}' in {}", key, where()));
        return it->second;
    }
    Table table(const std::string& key) { return Table(raw(key), qualified(key), label_); }

    double number(const std::string& key)
    {
        const auto& x = raw(key);
        if (!x.is_floating() && !x.is_integer()) fail(fmt::format("'{}' must be a number", qualified(key)));
        return value_of(x, qualified(key));
    }
    double number(const std::string& key, double fallback) { return has(key) ? number(key) : fallback; }
    // A value > 0, and normal: a subnormal density or modulus underflows the masses and stiffnesses made from it.
    double positive(const std::string& key, double fallback)
    {
        const double d = number(key, fallback);
        if (!(d > 0.0)) fail(fmt::format("'{}' must be > 0 (got {})", qualified(key), shown(key, d)));
        if (d < std::numeric_limits<double>::min())
            fail(fmt::format("'{}' = {} is below the smallest normal double, {:g}", qualified(key), shown(key, d), std::numeric_limits<double>::min()));
        return d;
    }
    double non_negative(const std::string& key, double fallback)
    {
        const double d = number(key, fallback);
        if (d < 0.0) fail(fmt::format("'{}' must be >= 0 (got {})", qualified(key), shown(key, d)));
        return d;
    }
    // The value of `key` as the file writes it (the number that was read when the key is absent).
    std::string shown(const std::string& key, double d) const
    {
        return has(key) ? written(v_.as_table().at(key)) : fmt::format("{}", d);
    }
    double value_of(const toml::value& x, const std::string& name) const
    {
        if (const std::string problem = toml_number_problem(x, name); !problem.empty()) fail(problem);
        return x.is_floating() ? x.as_floating() : double(x.as_integer());
    }
    static std::string written(const toml::value& x) { return toml_written(x); }
    // An integer in [lo, hi]. The message quotes the number as written: toml11 clamps a literal beyond
    // 64 bits to the nearest limit, and a narrowing cast would wrap (4294967297 into an int is 1).
    std::int64_t integer(const std::string& key, std::int64_t fallback, std::int64_t lo, std::int64_t hi)
    {
        if (!has(key)) return fallback;
        const auto& x = raw(key);
        if (!x.is_integer()) fail(fmt::format("'{}' must be an integer", qualified(key)));
        const std::int64_t v = x.as_integer();
        const std::string text = written(x);
        std::string digits;
        for (char c : text)
            if (c != '_' && c != '+') digits += c;
        const bool clamped = (v == std::numeric_limits<std::int64_t>::max() || v == std::numeric_limits<std::int64_t>::min()) &&
                             digits != std::to_string(v);
        if (clamped || v < lo || v > hi)
            fail(fmt::format("'{}' = {} is out of range ({} to {})", qualified(key), text, lo, hi));
        return v;
    }
    bool boolean(const std::string& key, bool fallback)
    {
        if (!has(key)) return fallback;
        const auto& x = raw(key);
        if (!x.is_boolean()) fail(fmt::format("'{}' must be true or false", qualified(key)));
        return x.as_boolean();
    }
    std::string string(const std::string& key, const std::string& fallback)
    {
        if (!has(key)) return fallback;
        const auto& x = raw(key);
        if (!x.is_string()) fail(fmt::format("'{}' must be a string", qualified(key)));
        for (unsigned char c : x.as_string().str)  // strings appear in one-line messages
            if (c < 0x20 || c == 0x7F) fail(fmt::format("'{}' must not hold control characters", qualified(key)));
        return x.as_string().str;
    }
    std::vector<double> numbers(const std::string& key, std::size_t n)
    {
        const auto& x = raw(key);
        if (!x.is_array() || x.as_array().size() != n)
            fail(fmt::format("'{}' must be an array of {} numbers", qualified(key), n));
        std::vector<double> out;
        for (const auto& e : x.as_array()) {
            if (!e.is_floating() && !e.is_integer()) fail(fmt::format("'{}' must be an array of {} numbers", qualified(key), n));
            out.push_back(value_of(e, qualified(key)));
        }
        return out;
    }
    Vec3d vec(const std::string& key)
    {
        const auto v = numbers(key, 3);
        return {v[0], v[1], v[2]};
    }
    Vec3d vec(const std::string& key, Vec3d fallback) { return has(key) ? vec(key) : fallback; }
    std::vector<Table> tables(const std::string& key)
    {
        const auto& x = raw(key);
        if (!x.is_array()) fail(fmt::format("'{}' must be an array of tables ([[{}]])", qualified(key), key));
        std::vector<Table> out;
        out.reserve(x.as_array().size());  // no reallocation: a moved-from Table must never be checked
        std::size_t k = 0;
        for (const auto& e : x.as_array()) out.emplace_back(e, fmt::format("{}[{}]", qualified(key), k++), label_);
        return out;
    }
    const std::string& path() const { return path_; }
    [[noreturn]] void fail(const std::string& msg) const { throw Error(fmt::format("{}: {}", label_, msg)); }
    std::string qualified(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

private:
    std::string where() const { return path_.empty() ? "the top level" : "[" + path_ + "]"; }
    const toml::value& v_;
    std::string path_, label_;
    std::set<std::string> used_;
    bool closed_ = false;
};

Material read_material_keys(Table& t)
{
    Material m;
    m.density = t.positive("density", m.density);
    m.young = t.positive("young", m.young);
    m.poisson = t.number("poisson", m.poisson);
    if (!(m.poisson > -1.0 && m.poisson < 0.5)) t.fail(fmt::format("'{}' must lie in (-1, 0.5) (got {})", t.qualified("poisson"), m.poisson));
    m.shear = t.non_negative("shear", 0.0);
    m.gamma_n = t.non_negative("gamma_n", m.gamma_n);
    m.gamma_t = t.non_negative("gamma_t", m.gamma_t);
    m.mu = t.non_negative("mu", m.mu);
    return m;
}

Material read_material(Table t) { return read_material_keys(t); }

// [wall_material]: a material, or `rigid = true` alone (a rigid wall has no elastic constants to give).
Material read_wall_material(Table t)
{
    if (!t.boolean("rigid", false)) return read_material_keys(t);
    for (const char* key : {"density", "young", "poisson", "shear", "gamma_n", "gamma_t", "mu"})
        if (t.has(key))
            t.fail(fmt::format("'{}' has no meaning for a rigid wall (rigid = true: it adds nothing to E* and G*; damping and "
                               "friction are the particles')",
                               t.qualified(key)));
    Material m;
    m.rigid = true;
    return m;
}

Vec3d unit(Vec3d n, const Table& t)
{
    // Scaled by its largest component first, so that neither n·n overflows (1e200) nor underflows (1e-200):
    // any non-zero vector gives a unit normal.
    const double big = std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)});
    if (!(big > 0.0)) t.fail(fmt::format("'{}' must be a non-zero vector", t.qualified("normal")));
    n = n / big;
    return n / std::sqrt(dot(n, n));
}

// TOML parse errors from toml11 span several lines; keep the first line and the line number.
std::string one_line(const std::string& what)
{
    std::istringstream in(what);
    std::string line, first, where;
    std::getline(in, first);
    while (std::getline(in, line)) {
        const auto arrow = line.find("-->");
        if (arrow != std::string::npos && where.empty()) where = line.substr(arrow + 4);
        const auto bar = line.find(" | ");
        if (bar != std::string::npos && where.find(':') == std::string::npos) {
            std::string num = line.substr(0, bar);
            num.erase(0, num.find_first_not_of(' '));
            if (!num.empty() && std::isdigit(static_cast<unsigned char>(num[0]))) where += ":" + num;
        }
    }
    if (first.rfind("[error] ", 0) == 0) first = first.substr(8);
    return where.empty() ? first : fmt::format("{} (at {})", first, where);
}

// Offset of the first byte that is not valid UTF-8 (RFC 3629: no overlong forms, no surrogates, at most
// U+10FFFF), or npos. TOML is UTF-8; toml11 3.7 reads out of bounds reporting invalid UTF-8 inside a
// string (found by fuzz/fuzz_scene), so such text never reaches it.
std::size_t invalid_utf8(const std::string& text)
{
    const auto* b = reinterpret_cast<const unsigned char*>(text.data());
    const std::size_t n = text.size();
    auto cont = [&](std::size_t k, unsigned lo, unsigned hi) { return k < n && b[k] >= lo && b[k] <= hi; };
    for (std::size_t i = 0; i < n;) {
        const unsigned c = b[i];
        std::size_t len = 0;
        if (c <= 0x7F) len = 1;
        else if (c >= 0xC2 && c <= 0xDF) len = cont(i + 1, 0x80, 0xBF) ? 2 : 0;
        else if (c == 0xE0) len = cont(i + 1, 0xA0, 0xBF) && cont(i + 2, 0x80, 0xBF) ? 3 : 0;
        else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) len = cont(i + 1, 0x80, 0xBF) && cont(i + 2, 0x80, 0xBF) ? 3 : 0;
        else if (c == 0xED) len = cont(i + 1, 0x80, 0x9F) && cont(i + 2, 0x80, 0xBF) ? 3 : 0;
        else if (c == 0xF0) len = cont(i + 1, 0x90, 0xBF) && cont(i + 2, 0x80, 0xBF) && cont(i + 3, 0x80, 0xBF) ? 4 : 0;
        else if (c >= 0xF1 && c <= 0xF3) len = cont(i + 1, 0x80, 0xBF) && cont(i + 2, 0x80, 0xBF) && cont(i + 3, 0x80, 0xBF) ? 4 : 0;
        else if (c == 0xF4) len = cont(i + 1, 0x80, 0x8F) && cont(i + 2, 0x80, 0xBF) && cont(i + 3, 0x80, 0xBF) ? 4 : 0;
        if (len == 0) return i;
        i += len;
    }
    return std::string::npos;
}

// toml11 parses arrays and inline tables recursively: 20000 '[' exhaust the stack (SIGSEGV, no message).
// A scene nests a few levels; deeper text is refused before toml11 sees it.
constexpr int kMaxNesting = 32;

// Offset of the bracket or brace that opens level kMaxNesting + 1 (strings and comments skipped), or npos.
std::size_t too_deep(const std::string& text)
{
    const std::size_t n = text.size();
    int depth = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const char c = text[i];
        if (c == '#') {
            while (i < n && text[i] != '\n') ++i;
        } else if (c == '"' || c == '\'') {
            const std::string triple(3, c);
            const bool multi = text.compare(i, 3, triple) == 0, escapes = c == '"';
            for (i += multi ? 3 : 1; i < n; ++i) {
                if (escapes && text[i] == '\\') { ++i; continue; }
                if (multi ? text.compare(i, 3, triple) == 0 : text[i] == c || text[i] == '\n') break;  // toml11 reports an open string
            }
            if (multi) i += 2;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxNesting) return i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return std::string::npos;
}

} // namespace

double rayleigh_time(const Material& m, double radius)
{
    return 3.14159265358979323846 * radius * std::sqrt(m.density / m.shear_modulus()) / (0.1631 * m.poisson + 0.8766);
}

std::vector<Wall> box_walls(const Box& box)
{
    std::vector<Wall> w;
    for (const char* f : {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"}) w.push_back(box_face(box, f));
    return w;
}

Wall box_face(const Box& box, const std::string& face)
{
    static const std::map<std::string, std::pair<int, bool>> faces = {
        {"x_min", {0, false}}, {"x_max", {0, true}}, {"y_min", {1, false}},
        {"y_max", {1, true}},  {"z_min", {2, false}}, {"z_max", {2, true}}};
    auto it = faces.find(face);
    if (it == faces.end()) throw Error(fmt::format("unknown box face '{}' (expected x_min, x_max, y_min, y_max, z_min or z_max)", face));
    const auto [axis, upper] = it->second;
    Wall w;
    w.name = face;
    w.point = upper ? box.max : box.min;
    component(w.normal, axis) = upper ? -1.0 : 1.0;
    return w;
}

ContactParams<double> Scene::contact_params() const
{
    const Material& p = material;
    const Material& w = wall_mat();
    const double e_pp = 1.0 / ((1.0 - p.poisson * p.poisson) / p.young + (1.0 - p.poisson * p.poisson) / p.young);
    // A rigid wall adds nothing to 1/E* (physics.md §9); a wall of a material, its (1 − ν²)/E.
    const double wall_term = w.rigid ? 0.0 : (1.0 - w.poisson * w.poisson) / w.young;
    const double e_pw = 1.0 / ((1.0 - p.poisson * p.poisson) / p.young + wall_term);
    ContactParams<double> c;
    c.hertz_pp = 4.0 / 3.0 * e_pp;
    c.hertz_pw = 4.0 / 3.0 * e_pw;
    c.gamma_n = p.gamma_n;
    c.gamma_t = p.gamma_t;
    c.mu = p.mu;
    return c;
}

std::uint64_t Scene::fingerprint(std::size_t particle_count) const
{
    // FNV-1a over the physics that a saved state depends on, from the state format's offset basis
    // (docs/state-format.md: not the standard one, kept so that saved states stay readable).
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (std::size_t k = 0; k < n; ++k) { h ^= b[k]; h *= 1099511628211ull; }
    };
    auto mixd = [&](double d) { mix(&d, sizeof d); };
    for (const Material* m : {&material, &wall_mat()})
        for (double d : {m->density, m->young, m->poisson, m->gamma_n, m->gamma_t, m->mu}) mixd(d);
    if (wall_mat().rigid) mixd(-1.0);  // only a scene with a rigid wall mixes this in: every other fingerprint stays
    for (double d : contact_model.fingerprint_values()) mixd(d);  // none for the paper's law
    mixd(dt);
    mixd(gravity.x); mixd(gravity.y); mixd(gravity.z);
    const std::uint64_t n = particle_count;
    mix(&n, sizeof n);
    return h;
}

Scene parse_scene(const std::string& text, const std::string& label)
{
    if (const std::size_t bad = invalid_utf8(text); bad != std::string::npos)
        throw Error(fmt::format("{}: not UTF-8 text (byte {} on line {}): a scene is a TOML file", label, bad,
                                1 + std::count(text.begin(), text.begin() + std::ptrdiff_t(bad), '\n')));
    if (const std::size_t deep = too_deep(text); deep != std::string::npos)
        throw Error(fmt::format("{}: arrays or inline tables nested deeper than {} levels (line {}): a scene needs a few", label,
                                kMaxNesting, 1 + std::count(text.begin(), text.begin() + std::ptrdiff_t(deep), '\n')));
    toml::value root;
    try {
        std::istringstream in(text);
        root = toml::parse(in, label);
    } catch (const toml::syntax_error& e) {
        throw Error(fmt::format("{}: TOML syntax error: {}", label, one_line(e.what())));
    } catch (const std::exception& e) {
        throw Error(fmt::format("{}: cannot parse: {}", label, one_line(e.what())));
    }

    Scene s;
    Table top(root, "", label);
    s.name = top.string("name", "unnamed");
    s.material = top.has("material") ? read_material(top.table("material")) : Material{};
    if (top.has("wall_material")) s.wall_material = read_wall_material(top.table("wall_material"));

    std::string dt_text;  // as written, for the check against the scene's precision below
    {
        Table t = top.table("time");
        s.dt = t.number("dt");
        if (!(s.dt > 0.0)) t.fail(fmt::format("'time.dt' must be > 0 (got {})", t.shown("dt", s.dt)));
        dt_text = t.shown("dt", s.dt);
        s.gravity = t.vec("gravity", s.gravity);
    }
    {
        Table t = top.table("domain");
        s.domain.min = t.vec("min");
        s.domain.max = t.vec("max");
        for (int c = 0; c < 3; ++c)
            if (!(component(s.domain.max, c) > component(s.domain.min, c)))
                t.fail("'domain.max' must exceed 'domain.min' along every axis");
    }
    if (top.has("wall")) {
        std::set<std::string> names;
        for (Table& t : top.tables("wall")) {
            Wall w;
            if (t.has("face")) {
                const std::string face = t.string("face", "");
                try {
                    w = box_face(s.domain, face);
                } catch (const Error& e) {
                    t.fail(fmt::format("'{}': {}", t.qualified("face"), e.what()));
                }
            } else {
                w.name = t.string("name", fmt::format("wall{}", s.walls.size()));
                w.point = t.vec("point");
                w.normal = unit(t.vec("normal"), t);
            }
            if (t.has("name")) w.name = t.string("name", w.name);
            w.velocity = t.vec("velocity", Vec3d{});
            if (!names.insert(w.name).second) t.fail(fmt::format("two walls are named '{}'", w.name));
            s.walls.push_back(w);
            t.close();
        }
    }
    if (top.has("search")) {
        Table t = top.table("search");
        const std::string m = t.string("method", "cells");
        if (m == "cells") s.search.method = SearchMethod::cells;
        else if (m == "all_pairs") s.search.method = SearchMethod::all_pairs;
        else t.fail(fmt::format("unknown search method '{}' (expected cells or all_pairs)", m));
        s.search.cell_size = t.number("cell_size", s.search.cell_size);
        if (!(s.search.cell_size >= 2.0))
            t.fail(fmt::format("'search.cell_size' is in units of R_max and must be >= 2 (the largest diameter), got {}", s.search.cell_size));
    }
    if (top.has("capacity")) {
        Table t = top.table("capacity");
        s.capacity.contacts_per_particle = int(t.integer("contacts_per_particle", s.capacity.contacts_per_particle, 1, kIntMax));
        s.capacity.wall_contacts_per_particle =
            int(t.integer("wall_contacts_per_particle", s.capacity.wall_contacts_per_particle, 1, kIntMax));
    }
    if (top.has("checks")) {
        Table t = top.table("checks");
        s.checks.interval = int(t.integer("interval", s.checks.interval, 0, kIntMax));
        s.checks.max_overlap_ratio = t.positive("max_overlap_ratio", s.checks.max_overlap_ratio);
        s.checks.max_speed = t.non_negative("max_speed", s.checks.max_speed);
    }

    if (top.has("integrator")) {
        Table t = top.table("integrator");
        const std::string scheme = t.string("scheme", name(s.integrator.scheme));
        const auto sc = parse_integrator(scheme);
        if (!sc) t.fail(fmt::format("unknown integrator '{}' (expected {})", scheme, integrator_names));
        const std::string precision = t.string("precision", name(s.integrator.precision));
        const auto pr = parse_precision(precision);
        if (!pr) t.fail(fmt::format("unknown precision '{}' (expected {})", precision, precision_names));
        s.integrator = {*sc, *pr};
    }

    if (s.dt < min_time_step(s.integrator.precision))
        top.fail(fmt::format("'time.dt' = {} is below {:g} s, where the Gear values' Δt²/2·a underflows in {} (the run would turn "
                             "to NaN)", dt_text, min_time_step(s.integrator.precision), name(s.integrator.precision)));

    if (top.has("contact")) s.contact_model = parse_contact_model(top.raw("contact"), label);

    Table p = top.table("particles");
    const std::string source = p.string("source", "");
    if (source == "grid") {
        GridGenerator g;
        if (!p.has("count")) p.fail("missing key 'count' in [particles] (source = \"grid\")");
        // The variants index particles with 32-bit integers (linked cells, neighbour lists).
        g.count = p.integer("count", 0, 1, kIntMax);
        const auto r = p.numbers("radius", 2);
        g.radius_min = r[0];
        g.radius_max = r[1];
        if (!(g.radius_min >= std::numeric_limits<double>::min()) || g.radius_max < g.radius_min)
            p.fail(fmt::format("'particles.radius' must be [min, max] with 0 < min <= max (got [{}, {}])", r[0], r[1]));
        const auto v = p.has("speed") ? p.numbers("speed", 2) : std::vector<double>{0.0, 0.0};
        g.speed_min = v[0];
        g.speed_max = v[1];
        if (g.speed_min < 0.0 || g.speed_max < g.speed_min) p.fail("'particles.speed' must be [min, max] with 0 <= min <= max");
        const std::int64_t seed = p.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max());
        g.seed = std::uint64_t(seed);
        if (p.has("cells")) {
            const auto c = p.numbers("cells", 3);
            for (int k = 0; k < 3; ++k) {
                if (!(c[k] >= 1.0 && c[k] <= 2147483647.0) || c[k] != std::floor(c[k]))
                    p.fail("'particles.cells' must be three integers from 1 to 2147483647");
                g.cells[k] = std::int64_t(c[k]);
            }
            const double holds = double(g.cells[0]) * double(g.cells[1]) * double(g.cells[2]);  // no integer overflow
            if (holds < double(g.count))
                p.fail(fmt::format("'particles.cells' holds {} particles, fewer than count = {}", holds, g.count));
        }
        g.spacing = p.non_negative("spacing", 0.0);
        s.grid = g;
    } else if (source == "list") {
        for (Table& t : p.tables("particle")) {
            ParticleInit q;
            q.radius = t.number("radius");
            if (!(q.radius > 0.0)) t.fail(fmt::format("'{}' must be > 0 (got {})", t.qualified("radius"), t.shown("radius", q.radius)));
            if (q.radius < std::numeric_limits<double>::min())
                t.fail(fmt::format("'{}' = {} is below the smallest normal double", t.qualified("radius"), t.shown("radius", q.radius)));
            q.position = t.vec("position");
            q.velocity = t.vec("velocity", Vec3d{});
            q.angular_velocity = t.vec("angular_velocity", Vec3d{});
            s.particles.push_back(q);
            t.close();
        }
        if (s.particles.empty()) p.fail("'particles.particle' is empty");
    } else if (source == "state") {
        s.state_file = p.string("file", "");
        if (s.state_file.empty()) p.fail("'particles.file' must name a state file");
    } else {
        p.fail(fmt::format("'particles.source' must be grid, list or state (got '{}')", source));
    }
    return s;
}

void override_integrator(Scene& s, const std::string& integrator, const std::string& precision)
{
    if (!integrator.empty()) {
        const auto k = parse_integrator(integrator);
        if (!k) throw Error(fmt::format("unknown integrator '{}' (expected {})", integrator, integrator_names));
        s.integrator.scheme = *k;
    }
    if (!precision.empty()) {
        const auto p = parse_precision(precision);
        if (!p) throw Error(fmt::format("unknown precision '{}' (expected {})", precision, precision_names));
        s.integrator.precision = *p;
    }
}

Scene load_scene(const std::filesystem::path& file)
{
    Scene s = parse_scene(read_input_file(file, "scene file", kMaxSceneBytes), file.string());
    s.source = file;
    if (!s.state_file.empty() && s.state_file.is_relative()) s.state_file = file.parent_path() / s.state_file;
    return s;
}

namespace {
std::string num(double d) { return fmt::format("{}", d); }  // shortest round-trip representation
// A TOML basic string: quotes and backslashes escaped (control characters never get this far).
std::string quoted(const std::string& s)
{
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}
std::string vec3(const Vec3d& v) { return fmt::format("[{}, {}, {}]", num(v.x), num(v.y), num(v.z)); }
std::string material_toml(const Material& m)
{
    std::string out = fmt::format("density = {}\nyoung = {}\npoisson = {}\n", num(m.density), num(m.young), num(m.poisson));
    if (m.shear > 0.0) out += fmt::format("shear = {}\n", num(m.shear));
    out += fmt::format("gamma_n = {}\ngamma_t = {}\nmu = {}\n", num(m.gamma_n), num(m.gamma_t), num(m.mu));
    return out;
}
} // namespace

std::string scene_to_toml(const Scene& s)
{
    std::string o;
    o += fmt::format("# DEMMAT scene (format: docs/scene-format.md)\nname = {}\n\n", quoted(s.name));
    o += "[material]\n" + material_toml(s.material) + "\n";
    if (s.wall_material) o += "[wall_material]\n" + (s.wall_material->rigid ? std::string("rigid = true\n") : material_toml(*s.wall_material)) + "\n";
    o += fmt::format("[time]\ndt = {}\ngravity = {}\n\n", num(s.dt), vec3(s.gravity));
    o += fmt::format("[domain]\nmin = {}\nmax = {}\n\n", vec3(s.domain.min), vec3(s.domain.max));
    for (const Wall& w : s.walls) {
        o += "[[wall]]\n";
        bool is_face = false;
        try {
            const Wall f = box_face(s.domain, w.name);
            is_face = f.point == w.point && f.normal == w.normal;
        } catch (const Error&) {
        }
        if (is_face) o += fmt::format("face = \"{}\"\n", w.name);
        else o += fmt::format("name = {}\npoint = {}\nnormal = {}\n", quoted(w.name), vec3(w.point), vec3(w.normal));
        if (w.moving()) o += fmt::format("velocity = {}\n", vec3(w.velocity));
        o += "\n";
    }
    o += fmt::format("[search]\nmethod = \"{}\"\ncell_size = {}   # in units of R_max\n\n",
                     s.search.method == SearchMethod::cells ? "cells" : "all_pairs", num(s.search.cell_size));
    o += fmt::format("[capacity]\ncontacts_per_particle = {}\nwall_contacts_per_particle = {}\n\n",
                     s.capacity.contacts_per_particle, s.capacity.wall_contacts_per_particle);
    o += fmt::format("[checks]\ninterval = {}\nmax_overlap_ratio = {}\n", s.checks.interval, num(s.checks.max_overlap_ratio));
    if (s.checks.max_speed > 0.0) o += fmt::format("max_speed = {}\n", num(s.checks.max_speed));
    if (!s.integrator.is_default())  // written only when chosen, so default scenes read as before
        o += fmt::format("\n[integrator]\nscheme = \"{}\"\nprecision = \"{}\"\n", name(s.integrator.scheme),
                         name(s.integrator.precision));
    if (!s.contact_model.is_paper()) o += "\n" + s.contact_model.toml();
    o += "\n[particles]\n";
    if (s.grid) {
        const GridGenerator& g = *s.grid;
        o += fmt::format("source = \"grid\"\ncount = {}\nradius = [{}, {}]\nspeed = [{}, {}]\nseed = {}\n", g.count,
                         num(g.radius_min), num(g.radius_max), num(g.speed_min), num(g.speed_max), g.seed);
        if (g.cells[0] > 0) o += fmt::format("cells = [{}, {}, {}]\n", g.cells[0], g.cells[1], g.cells[2]);
        if (g.spacing > 0.0) o += fmt::format("spacing = {}\n", num(g.spacing));
    } else if (!s.state_file.empty()) {
        o += fmt::format("source = \"state\"\nfile = {}\n", quoted(s.state_file.generic_string()));
    } else {
        o += "source = \"list\"\n";
        for (const ParticleInit& q : s.particles)
            o += fmt::format("\n[[particles.particle]]\nradius = {}\nposition = {}\nvelocity = {}\nangular_velocity = {}\n",
                             num(q.radius), vec3(q.position), vec3(q.velocity), vec3(q.angular_velocity));
    }
    return o;
}

} // namespace demmat
