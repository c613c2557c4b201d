// state_damage: makes a damaged copy of a good state file for the bad-input corpus, so that the corpus
// holds no binaries and every damaged file follows the current format (docs/state-format.md).
//
//   state_damage GOOD OUT empty                 a file of zero bytes
//   state_damage GOOD OUT truncate K            the first K bytes (K < 0: all but the last -K)
//   state_damage GOOD OUT append K              K extra zero bytes after the checksum
//   state_damage GOOD OUT flip-byte K           byte K inverted (K < 0: from the end); checksum left stale
//   state_damage GOOD OUT set FIELD VALUE       one field changed and the checksum recomputed, so that the
//                                               reader's checks behind the checksum are reached
// FIELD: version, fingerprint, step, dt, count, walls (header integers/doubles); radius:I, position:I,
// velocity:I (all three components of particle I); wall_point:K, wall_normal:K, wall_velocity:K;
// wall_name:K (VALUE: the byte code that replaces the last character of wall K's name).
// VALUE: a number, or nan / inf / -inf.
//
// Written independently of harness/src/state_file.cpp on purpose: a test tool that reused the reader's code
// would share its mistakes.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>

namespace {

[[noreturn]] void die(const std::string& m)
{
    std::cerr << "state_damage: " << m << "\n";
    std::exit(2);
}

std::uint64_t fnv1a(const std::string& b, std::size_t n)
{
    std::uint64_t h = 1469598103934665603ull;
    for (std::size_t k = 0; k < n; ++k) {
        h ^= static_cast<unsigned char>(b[k]);
        h *= 1099511628211ull;
    }
    return h;
}

template <class T> T peek(const std::string& b, std::size_t at)
{
    if (at + sizeof(T) > b.size()) die("the good state is shorter than its header says");
    T v;
    std::memcpy(&v, b.data() + at, sizeof v);
    return v;
}
template <class T> void poke(std::string& b, std::size_t at, T v)
{
    if (at + sizeof(T) > b.size()) die("field lies beyond the end of the file");
    std::memcpy(b.data() + at, &v, sizeof v);
}

double number(const std::string& s)
{
    if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
    return std::stod(s);
}

// Header: magic[8] version u32 reserved u32 fingerprint u64 step i64 dt f64 count u64 walls u64 (56 bytes);
// walls: name (u32 length + bytes), point, normal, velocity (3 f64 each), ref_step i64; then radius[n] and
// twelve (n, 3) arrays of f64 in particle order (position first, velocity second); then the checksum.
struct Layout {
    std::uint64_t n = 0, nw = 0;
    std::size_t walls_at = 56, radius_at = 0;
    std::size_t wall(const std::string& b, std::uint64_t k) const
    {
        std::size_t at = walls_at;
        for (std::uint64_t w = 0; w < k; ++w) at += 4 + peek<std::uint32_t>(b, at) + 80;
        return at + 4 + peek<std::uint32_t>(b, at);  // the wall's point
    }
};

Layout layout(const std::string& b)
{
    Layout l;
    l.n = peek<std::uint64_t>(b, 40);
    l.nw = peek<std::uint64_t>(b, 48);
    std::size_t at = l.walls_at;
    for (std::uint64_t w = 0; w < l.nw; ++w) at += 4 + peek<std::uint32_t>(b, at) + 80;
    l.radius_at = at;
    return l;
}

void set(std::string& b, const std::string& field, const std::string& value)
{
    const Layout l = layout(b);
    const auto colon = field.find(':');
    const std::string name = field.substr(0, colon);
    const std::uint64_t idx = colon == std::string::npos ? 0 : std::stoull(field.substr(colon + 1));
    auto vec3 = [&](std::size_t at) {
        const double v = number(value);
        for (int c = 0; c < 3; ++c) poke(b, at + 8 * std::size_t(c), v);
    };
    if (name == "version") poke(b, 8, std::uint32_t(std::stoul(value)));
    else if (name == "fingerprint") poke(b, 16, std::uint64_t(std::stoull(value)));
    else if (name == "step") poke(b, 24, std::int64_t(std::stoll(value)));
    else if (name == "dt") poke(b, 32, number(value));
    else if (name == "count") poke(b, 40, std::uint64_t(std::stoull(value)));
    else if (name == "walls") poke(b, 48, std::uint64_t(std::stoull(value)));
    else if (name == "radius") poke(b, l.radius_at + 8 * idx, number(value));
    else if (name == "position") vec3(l.radius_at + 8 * l.n + 24 * idx);
    else if (name == "velocity") vec3(l.radius_at + 8 * l.n + 24 * l.n + 24 * idx);
    else if (name == "wall_name") b[l.wall(b, idx) - 1] = char(std::stoi(value));
    else if (name == "wall_point") vec3(l.wall(b, idx));
    else if (name == "wall_normal") vec3(l.wall(b, idx) + 24);
    else if (name == "wall_velocity") vec3(l.wall(b, idx) + 48);
    else die("unknown field '" + field + "'");
    if (b.size() < 8) die("file too short for a checksum");
    poke(b, b.size() - 8, fnv1a(b, b.size() - 8));
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 4) die("usage: state_damage GOOD OUT OPERATION [ARGS...]");
    std::ifstream in(argv[1], std::ios::binary);
    if (!in) die(std::string("cannot open ") + argv[1]);
    std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string op = argv[3];
    try {
        auto offset = [&](const char* s) {
            const long long k = std::stoll(s);
            const long long at = k < 0 ? static_cast<long long>(b.size()) + k : k;
            if (at < 0 || at >= static_cast<long long>(b.size())) die("offset outside the file");
            return static_cast<std::size_t>(at);
        };
        if (op == "empty") b.clear();
        else if (op == "truncate" && argc == 5) b.resize(offset(argv[4]));
        else if (op == "append" && argc == 5) b.append(std::stoull(argv[4]), '\0');
        else if (op == "flip-byte" && argc == 5) b[offset(argv[4])] = static_cast<char>(~b[offset(argv[4])]);
        else if (op == "set" && argc == 6) set(b, argv[4], argv[5]);
        else die("unknown operation or wrong arguments: " + op);
    } catch (const std::logic_error& e) {
        die(std::string("bad number: ") + e.what());
    }
    std::ofstream out(argv[2], std::ios::binary | std::ios::trunc);
    out << b;
    if (!out.flush()) die(std::string("cannot write ") + argv[2]);
    return 0;
}
