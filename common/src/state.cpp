#include "demmat/state.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/io.hpp"
#include "demmat/reference.hpp"

namespace demmat {

namespace {

constexpr char kMagic[8] = {'D', 'E', 'M', 'M', 'A', 'T', 'S', 'T'};
// Version 2 adds the contacts' stretches (physics.md §9) after the Gear values; a state without any is
// written as version 1, byte for byte as before they existed, and both versions read.
constexpr std::uint32_t kVersion = 2;
constexpr std::uint32_t kVersionWithoutStretches = 1;

// splitmix64: a small, portable generator; the same seed gives the same scene on every machine
// (std:: distributions are implementation-defined, so none is used).
class Random {
public:
    explicit Random(std::uint64_t seed) : s_(seed) {}
    std::uint64_t next()
    {
        std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)

private:
    std::uint64_t s_;
};

// FNV-1a from the offset basis 1469598103934665603, not the standard 14695981039346656037 (a digit short):
// every saved state carries it, so it stays (docs/state-format.md).
std::uint64_t fnv1a(const std::string& bytes)
{
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : bytes) { h ^= c; h *= 1099511628211ull; }
    return h;
}

class Writer {
public:
    template <class T> void put(const T& v) { buf_.append(reinterpret_cast<const char*>(&v), sizeof v); }
    void put(const Vec3d& v) { put(v.x); put(v.y); put(v.z); }
    void put(const std::string& s) { put(std::uint32_t(s.size())); buf_ += s; }
    void put(const std::vector<Vec3d>& a) { for (const auto& v : a) put(v); }
    std::string& bytes() { return buf_; }

private:
    std::string buf_;
};

class Reader {
public:
    Reader(const std::string& bytes, std::string label) : b_(bytes), label_(std::move(label)) {}
    template <class T> T get()
    {
        need(sizeof(T));
        T v;
        std::memcpy(&v, b_.data() + pos_, sizeof v);
        pos_ += sizeof v;
        return v;
    }
    Vec3d vec() { const double x = get<double>(), y = get<double>(), z = get<double>(); return {x, y, z}; }
    std::string str()
    {
        const auto n = get<std::uint32_t>();
        if (n > 4096) fail("corrupt (wall name too long)");
        need(n);
        std::string s = b_.substr(pos_, n);
        pos_ += n;
        return s;
    }
    void vecs(std::vector<Vec3d>& a) { for (auto& v : a) v = vec(); }
    std::size_t pos() const { return pos_; }
    std::size_t left() const { return b_.size() - pos_; }
    [[noreturn]] void fail(const std::string& msg) const { throw Error(fmt::format("{}: {}", label_, msg)); }

private:
    void need(std::size_t n) const
    {
        if (n > left()) fail(fmt::format("state file is truncated (needs more than its {} bytes)", b_.size()));
    }
    const std::string& b_;
    std::size_t pos_ = 0;
    std::string label_;
};

void check_finite(const State& s, const std::string& label)
{
    auto bad = [&](const std::vector<Vec3d>& a, const char* what) {
        for (std::size_t i = 0; i < a.size(); ++i)
            if (!std::isfinite(a[i].x) || !std::isfinite(a[i].y) || !std::isfinite(a[i].z))
                throw Error(fmt::format("{}: particle {} has a non-finite {}", label, i, what));
    };
    for (std::size_t i = 0; i < s.size(); ++i)
        if (!(s.radius[i] > 0.0) || !std::isfinite(s.radius[i]))
            throw Error(fmt::format("{}: particle {} has radius {} (must be > 0)", label, i, s.radius[i]));
    bad(s.trans.x, "position"); bad(s.trans.v, "velocity"); bad(s.trans.a, "acceleration");
    bad(s.trans.b3, "b3"); bad(s.trans.b4, "b4"); bad(s.trans.b5, "b5");
    bad(s.rot.x, "orientation"); bad(s.rot.v, "angular velocity"); bad(s.rot.a, "angular acceleration");
    bad(s.rot.b3, "rotational b3"); bad(s.rot.b4, "rotational b4"); bad(s.rot.b5, "rotational b5");
}

// The stretches of a version-2 file: keys in range and in the canonical order, values finite.
void read_stretches(Reader& r, State& s)
{
    const auto count = r.get<std::uint64_t>();
    // 9 eight-byte fields per contact; a count the file cannot hold is damage, not an allocation.
    if (count == 0 || count > r.left() / (9 * 8)) r.fail(fmt::format("state file is truncated or corrupt ({} contacts announced)", count));
    const auto n = std::int64_t(s.size()), nw = std::int64_t(s.walls.size());
    s.stretches.resize(std::size_t(count));
    for (std::size_t k = 0; k < count; ++k) {
        ContactStretch& c = s.stretches[k];
        c.i = r.get<std::int64_t>();
        c.partner = r.get<std::int64_t>();
        const auto wall = r.get<std::uint64_t>();
        c.wall = wall == 1;
        c.tangential = r.vec();
        c.rolling = r.vec();
        const bool key_ok = wall <= 1 && c.i >= 0 && c.i < n && (c.wall ? c.partner >= 0 && c.partner < nw : c.partner > c.i && c.partner < n);
        if (!key_ok) r.fail(fmt::format("corrupt (contact {} names particle {} and {} {})", k, c.i, c.wall ? "wall" : "particle", c.partner));
        if (k > 0 && !(s.stretches[k - 1] < c)) r.fail(fmt::format("corrupt (contact {} is out of order or repeated)", k));
        for (const Vec3d& v : {c.tangential, c.rolling})
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                r.fail(fmt::format("corrupt (contact {} has a non-finite stretch)", k));
    }
}

void generate_grid(const Scene& scene, State& s)
{
    const GridGenerator& g = *scene.grid;
    std::int64_t n[3];
    const auto side = std::int64_t(std::ceil(std::cbrt(double(g.count)) - 1e-9));
    for (int c = 0; c < 3; ++c) n[c] = g.cells[c] > 0 ? g.cells[c] : side;
    double sp[3];
    for (int c = 0; c < 3; ++c)
        sp[c] = g.spacing > 0.0 ? g.spacing : (component(scene.domain.max, c) - component(scene.domain.min, c)) / double(n[c]);
    const double gap = std::min({sp[0], sp[1], sp[2]});
    if (!(gap > 2.0 * g.radius_max))
        throw Error(fmt::format("{}: grid spacing {} m does not exceed the largest diameter {} m: particles would touch",
                                scene.name, gap, 2.0 * g.radius_max));
    Random rng(g.seed);
    s.resize(std::size_t(g.count));
    for (std::int64_t i = 0; i < g.count; ++i) {
        const std::int64_t ix = i % n[0], iy = (i / n[0]) % n[1], iz = i / (n[0] * n[1]);
        Vec3d x{scene.domain.min.x + (double(ix) + 0.5) * sp[0], scene.domain.min.y + (double(iy) + 0.5) * sp[1],
                scene.domain.min.z + (double(iz) + 0.5) * sp[2]};
        s.radius[i] = g.radius_min + (g.radius_max - g.radius_min) * rng.uniform();
        const double speed = g.speed_min + (g.speed_max - g.speed_min) * rng.uniform();
        const double cz = 2.0 * rng.uniform() - 1.0;
        const double phi = 2.0 * 3.14159265358979323846 * rng.uniform();
        const double sxy = std::sqrt(std::max(0.0, 1.0 - cz * cz));
        s.trans.x[i] = x;
        s.trans.v[i] = {speed * sxy * std::cos(phi), speed * sxy * std::sin(phi), speed * cz};
    }
}

// Particles made by a scene must start apart, inside the domain and clear of the walls.
void validate_new_particles(const Scene& scene, const State& s)
{
    const std::string& label = scene.name;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const Vec3d& x = s.trans.x[i];
        for (int c = 0; c < 3; ++c)
            if (component(x, c) < component(scene.domain.min, c) || component(x, c) > component(scene.domain.max, c))
                throw Error(fmt::format("{}: particle {} at ({}, {}, {}) lies outside the domain", label, i, x.x, x.y, x.z));
        for (const Wall& w : s.walls) {
            const double sd = dot(x - w.point_at(s.step, scene.dt), w.normal);
            if (sd < 0.0)
                throw Error(fmt::format("{}: particle {} lies behind wall '{}'", label, i, w.name));
            if (s.radius[i] - sd > 0.0)
                throw Error(fmt::format("{}: particle {} overlaps wall '{}' by {} m at the start", label, i, w.name, s.radius[i] - sd));
        }
    }
    const auto pairs = contact_pairs(s.trans.x, s.radius, false);
    if (!pairs.empty()) {
        const auto [i, j] = pairs.front();
        const Vec3d d = s.trans.x[j] - s.trans.x[i];
        throw Error(fmt::format("{}: particles {} and {} overlap by {} m at the start", label, i, j,
                                s.radius[i] + s.radius[j] - std::sqrt(dot(d, d))));
    }
}

} // namespace

// Walls of a run that starts from a saved state: a wall the state knows keeps its position; if the
// scene gives it another velocity, its motion is re-anchored at the state's step (a new stage, e.g.
// compression after settling). A wall the state does not know starts where the scene puts it.
std::vector<Wall> continue_walls(const Scene& scene, const State& saved)
{
    std::vector<Wall> out;
    for (const Wall& w : scene.walls) {
        Wall m = w;
        m.ref_step = saved.step;
        for (const Wall& old : saved.walls) {
            if (old.name != w.name) continue;
            if (old.velocity == w.velocity) {
                m = old;
            } else {
                m.point = old.point_at(saved.step, scene.dt);
                m.normal = old.normal;
            }
        }
        out.push_back(m);
    }
    return out;
}

void save_state(const State& s, const std::filesystem::path& file)
{
    Writer w;
    w.bytes().append(kMagic, 8);
    w.put(s.stretches.empty() ? kVersionWithoutStretches : kVersion);
    w.put(std::uint32_t(0));
    w.put(s.fingerprint);
    w.put(s.step);
    w.put(s.dt);
    w.put(std::uint64_t(s.size()));
    w.put(std::uint64_t(s.walls.size()));
    for (const Wall& x : s.walls) {
        w.put(x.name);
        w.put(x.point);
        w.put(x.normal);
        w.put(x.velocity);
        w.put(x.ref_step);
    }
    for (double r : s.radius) w.put(r);
    for (const GearState* g : {&s.trans, &s.rot})
        for (const auto* a : {&g->x, &g->v, &g->a, &g->b3, &g->b4, &g->b5}) w.put(*a);
    if (!s.stretches.empty()) {
        w.put(std::uint64_t(s.stretches.size()));
        for (const ContactStretch& c : s.stretches) {
            w.put(c.i);
            w.put(c.partner);
            w.put(std::uint64_t(c.wall ? 1 : 0));
            w.put(c.tangential);
            w.put(c.rolling);
        }
    }
    const std::uint64_t sum = fnv1a(w.bytes());
    w.put(sum);
    write_atomically(file, w.bytes());
}

State load_state(const std::filesystem::path& file)
{
    // A bound that stops a device or a runaway file, not the format's exact maximum: the header, 1024
    // walls with names of 4096 bytes, 2^31 - 1 particles of 37 doubles, the checksum. A version-2 file's
    // stretch block (80 bytes a contact) fits within it for any bed small enough to hold in memory.
    // (A regular file only: read_input_file refuses devices.)
    constexpr std::uintmax_t kMaxStateBytes = 56 + 1024 * (4 + 4096 + 9 * 8 + 8) + std::uintmax_t(2147483647) * 37 * 8 + 8;
    return parse_state(read_input_file(file, "state file", kMaxStateBytes), file.string());
}

State parse_state(const std::string& bytes, const std::string& label)
{
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
        throw Error(fmt::format("{}: not a DEMMAT state file (bad magic)", label));
    Reader r(bytes, label);
    r.get<std::uint64_t>();  // magic
    const auto version = r.get<std::uint32_t>();
    if (version != kVersion && version != kVersionWithoutStretches)
        r.fail(fmt::format("state file version {} is not supported (expected {} or {})", version, kVersionWithoutStretches, kVersion));
    if (r.get<std::uint32_t>() != 0) r.fail("corrupt (the reserved header field is not zero)");
    State s;
    s.fingerprint = r.get<std::uint64_t>();
    s.step = r.get<std::int64_t>();
    s.dt = r.get<double>();
    const auto n = r.get<std::uint64_t>();
    const auto nw = r.get<std::uint64_t>();
    if (s.step < 0) r.fail("corrupt (negative step)");
    if (!(s.dt > 0.0) || !std::isfinite(s.dt)) r.fail(fmt::format("corrupt (time step {})", s.dt));
    if (nw > 1024) r.fail("corrupt (too many walls)");
    // 37 doubles per particle: radius and twelve vectors.
    if (n == 0 || n > r.left() / (37 * sizeof(double))) r.fail(fmt::format("state file is truncated or corrupt ({} particles announced)", n));
    for (std::uint64_t k = 0; k < nw; ++k) {
        Wall w;
        w.name = r.str();
        for (unsigned char c : w.name)  // names appear in one-line messages and in scene files
            if (c < 0x20 || c == 0x7F) r.fail("corrupt (a wall name holds control characters)");
        w.point = r.vec();
        w.normal = r.vec();
        w.velocity = r.vec();
        w.ref_step = r.get<std::int64_t>();
        for (const Vec3d& v : {w.point, w.normal, w.velocity})
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                r.fail(fmt::format("corrupt (wall '{}' has a non-finite point, normal or velocity)", w.name));
        if (!(std::abs(dot(w.normal, w.normal) - 1.0) < 1e-9))
            r.fail(fmt::format("corrupt (wall '{}' has a normal that is not a unit vector)", w.name));
        s.walls.push_back(w);
    }
    s.resize(std::size_t(n));
    for (auto& x : s.radius) x = r.get<double>();
    for (GearState* g : {&s.trans, &s.rot})
        for (auto* a : {&g->x, &g->v, &g->a, &g->b3, &g->b4, &g->b5}) r.vecs(*a);
    if (version == kVersion) read_stretches(r, s);
    const std::uint64_t expect = fnv1a(bytes.substr(0, r.pos()));
    const auto sum = r.get<std::uint64_t>();
    if (sum != expect) r.fail("state file is corrupt (checksum mismatch)");
    if (r.left() != 0) r.fail("state file has trailing bytes (corrupt)");
    check_finite(s, label);
    return s;
}

void initial_accelerations(const Scene& scene, State& s)
{
    std::vector<double> mass(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) mass[i] = sphere_mass(s.radius[i], scene.material.density);
    std::vector<Vec3d> f, t;
    if (scene.contact_model.is_paper())
        reference_forces(s.trans.x, s.trans.v, s.rot.v, s.radius, mass, s.walls, s.step, scene.dt, scene.contact_params(), f, t);
    else  // a §9 law: zero stretches, not advanced (physics.md §9)
        reference_forces_law(s.trans.x, s.trans.v, s.rot.v, s.radius, mass, s.walls, s.step, scene.dt, scene.contact_params(),
                             memory_params(scene), law_features(scene.contact_model), f, t);
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double inertia = sphere_inertia(s.radius[i], mass[i]);
        s.trans.a[i] = {acceleration(f[i].x, mass[i], scene.gravity.x), acceleration(f[i].y, mass[i], scene.gravity.y),
                        acceleration(f[i].z, mass[i], scene.gravity.z)};
        s.rot.a[i] = {t[i].x / inertia, t[i].y / inertia, t[i].z / inertia};
    }
}

State initial_state(const Scene& scene)
{
    State s;
    s.dt = scene.dt;
    if (!scene.state_file.empty()) {
        const State saved = load_state(scene.state_file);
        const std::uint64_t fp = scene.fingerprint(saved.size());
        if (saved.fingerprint != fp)
            throw Error(fmt::format("{}: state file {} was written for another scene (materials, time step, gravity or "
                                    "particle count differ)", scene.name, scene.state_file.string()));
        s = saved;
        s.walls = continue_walls(scene, saved);
        // A wall contact's stretch is keyed by the wall's index: re-key it to the scene's walls by name, and
        // forget it where the scene has no such wall.
        std::vector<ContactStretch> kept;
        for (ContactStretch c : s.stretches) {
            if (c.wall) {
                const std::string& wname = saved.walls[std::size_t(c.partner)].name;
                auto it = std::find_if(s.walls.begin(), s.walls.end(), [&](const Wall& w) { return w.name == wname; });
                if (it == s.walls.end()) continue;
                c.partner = it - s.walls.begin();
            }
            kept.push_back(c);
        }
        std::sort(kept.begin(), kept.end());
        s.stretches = kept;
        return s;
    }
    s.walls = scene.walls;
    if (scene.grid) {
        generate_grid(scene, s);
    } else {
        s.resize(scene.particles.size());
        for (std::size_t i = 0; i < scene.particles.size(); ++i) {
            s.radius[i] = scene.particles[i].radius;
            s.trans.x[i] = scene.particles[i].position;
            s.trans.v[i] = scene.particles[i].velocity;
            s.rot.v[i] = scene.particles[i].angular_velocity;
        }
    }
    s.fingerprint = scene.fingerprint(s.size());
    validate_new_particles(scene, s);

    initial_accelerations(scene, s);  // t = 0; b3 = b4 = b5 = 0 as resized
    return s;
}

} // namespace demmat
