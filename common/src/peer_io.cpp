#include "demmat/peer_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "demmat/contact_memory.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/reference.hpp"

namespace demmat {

namespace {

// Every double is written with 17 significant digits, so that reading it back gives the same bits.
std::string d17(double v) { return fmt::format("{:.17g}", v); }

const char* kAxis[3] = {"x", "y", "z"};

// The most particles a state holds: the variants index them with 32-bit integers (as the scene reader bounds a grid).
constexpr std::int64_t kMaxParticles = 2147483647;

// The axis a unit normal lies along, or -1.
int axis_of(const Vec3d& n)
{
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        if (component(n, b) == 0.0 && component(n, c) == 0.0 && std::abs(component(n, a)) == 1.0) return a;
    }
    return -1;
}

double radius_max(const State& s) { return *std::max_element(s.radius.begin(), s.radius.end()); }
double radius_min(const State& s) { return *std::min_element(s.radius.begin(), s.radius.end()); }

// The simulation box of the peers: the scene's domain padded by two largest diameters, so that no grain
// and no wall mesh lies on its boundary (the boundaries are non-periodic and would lose atoms).
Box peer_box(const Scene& scene, const State& s)
{
    const double pad = 4.0 * radius_max(s);
    Box b = scene.domain;
    b.min = b.min - Vec3d{pad, pad, pad};
    b.max = b.max + Vec3d{pad, pad, pad};
    return b;
}

class SplitMix {
public:
    explicit SplitMix(std::uint64_t seed) : s_(seed) {}
    double uniform()  // [0, 1)
    {
        std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    }

private:
    std::uint64_t s_;
};

std::string data_file(const Scene& scene, const State& s)
{
    const Box b = peer_box(scene, s);
    std::string out = fmt::format("LAMMPS data file from demmat export-lammps: scene '{}' at step {}, {} particles, atom_style sphere "
                                  "(LIGGGHTS: granular); type 2 is the walls' material\n\n",
                                  scene.name, s.step, s.size());
    out += fmt::format("{} atoms\n2 atom types\n\n", s.size());
    for (int a = 0; a < 3; ++a)
        out += fmt::format("{} {} {}lo {}hi\n", d17(component(b.min, a)), d17(component(b.max, a)), kAxis[a], kAxis[a]);
    out += "\nAtoms\n\n";  // no style hint: LIGGGHTS 3.8 reads only the bare keyword
    const double rho = scene.material.density;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const Vec3d& x = s.trans.x[i];
        // diameter = 2R is exact in binary, and LAMMPS takes radius = diameter/2 back exactly.
        out += fmt::format("{} 1 {} {} {} {} {}\n", i + 1, d17(2.0 * s.radius[i]), d17(rho), d17(x.x), d17(x.y), d17(x.z));
    }
    out += "\nVelocities\n\n";
    for (std::size_t i = 0; i < s.size(); ++i) {
        const Vec3d& v = s.trans.v[i];
        const Vec3d& w = s.rot.v[i];
        out += fmt::format("{} {} {} {} {} {} {}\n", i + 1, d17(v.x), d17(v.y), d17(v.z), d17(w.x), d17(w.y), d17(w.z));
    }
    return out;
}

double e_star_pw(const Scene& scene) { return scene.contact_params().estar_pw(); }

// The e that LAMMPS's `damping tsuji` must be given for the damping constant α: Tsuji's fit α(e) falls
// monotonically from α(0) = 1.2728 to α(1) ≈ 0, so a `restitution` run's solved α is exported as the e whose
// fit gives it (bisection to the last bit), and LAMMPS computes the same η_n = α·sqrt(m*·k_n).
double tsuji_e_for_alpha(double alpha)
{
    if (!(alpha <= tsuji_alpha(0.0)))
        throw Error(fmt::format("export: the restitution damping's alpha = {} exceeds what LAMMPS's damping tsuji can express ({} at e = 0)",
                                alpha, tsuji_alpha(0.0)));
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < 200 && lo < hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (mid == lo || mid == hi) break;
        (tsuji_alpha(mid) > alpha ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// The contact law in pair_style granular's words (physics.md §9): the damping coefficient that follows
// hertz/material's modulus, then the damping, tangential and rolling keywords, always with limit_damping
// (the cap uses the clipped F_n, as here). `mindlin_kt` is the tangential keyword's stiffness for mindlin:
// NULL for pairs (LAMMPS derives 8·G* from E and ν as physics.md does), the number 8·G* for walls (this
// LAMMPS version's fix wall/gran derives it wrongly).
struct LammpsLaw {
    std::string damping_coefficient, keywords;
};
LammpsLaw lammps_law(const Scene& scene, const std::string& mindlin_kt)
{
    const Material& m = scene.material;
    const ContactModel& law = scene.contact_model;
    LammpsLaw out;
    if (law.damping == NormalDamping::viscous) {
        out.damping_coefficient = d17(m.gamma_n);
        out.keywords = "damping mass_velocity";
    } else {
        const double e = law.damping == NormalDamping::tsuji ? law.restitution : tsuji_e_for_alpha(restitution_alpha(law.restitution));
        out.damping_coefficient = d17(e);
        out.keywords = "damping tsuji";
    }
    switch (law.tangential) {
    case TangentialModel::viscous:
        // linear_nohistory's damping is x·η_n: the paper's γ_t·m* only when η_n is the paper's γ_n·m*.
        if (law.damping != NormalDamping::viscous)
            throw Error(fmt::format("export: the paper's viscous friction (gamma_t*m*) beside damping {} cannot be written for LAMMPS, "
                                    "whose tangential linear_nohistory damping scales with the normal damping", name(law.damping)));
        if (m.gamma_n == 0.0 && m.gamma_t != 0.0)
            throw Error("export: LAMMPS's tangential linear_nohistory damping is x·γn·m*, so γt != 0 with γn = 0 cannot be expressed");
        out.keywords += fmt::format(" tangential linear_nohistory {} {}", d17(m.gamma_n == 0.0 ? 0.0 : m.gamma_t / m.gamma_n), d17(m.mu));
        break;
    case TangentialModel::linear_history:
        out.keywords += fmt::format(" tangential linear_history {} {} {}", d17(law.kt), d17(law.tangential_damping_ratio), d17(m.mu));
        break;
    case TangentialModel::mindlin:
        out.keywords += fmt::format(" tangential mindlin {} {} {}", mindlin_kt, d17(law.tangential_damping_ratio), d17(m.mu));
        break;
    }
    if (law.rolling == RollingModel::sds)
        out.keywords += fmt::format(" rolling sds {} {} {}", d17(law.kr), d17(law.rolling_damping), d17(law.rolling_friction));
    out.keywords += " limit_damping";
    return out;
}

std::string lammps_fragment(const Scene& scene, const State& s, const PeerOptions& o, double skin)
{
    const Material& m = scene.material;
    const LammpsLaw pair_law = lammps_law(scene, "NULL");
    const LammpsLaw wall_law_words = lammps_law(scene, d17(memory_params(scene).shear8_pw));
    std::string out = fmt::format("# LAMMPS input fragment from demmat export-lammps: scene '{}' at step {} (docs/peers.md).\n", scene.name, s.step);
    if (scene.contact_model.is_paper())
        out += "# The paper's contact law: Hertz (4/3)E*sqrt(R*)h^1.5 + gamma_n*m*u_n clipped at 0 (limit_damping),\n"
               "# tangential -min(mu*Fn, gamma_t*m*|u_t|) without history; velocity Verlet (nve/sphere).\n";
    else
        out += fmt::format("# The contact law of physics.md section 9: {}.\n# Velocity Verlet (nve/sphere); every contact starts with "
                           "zero stretch (a data file holds none).\n", scene.contact_model.describe());
    out += "units si\natom_style sphere\natom_modify map array\nboundary f f f\nnewton off\ncomm_modify vel yes\n";
    out += fmt::format("read_data {}\nreset_timestep 0\n", o.data_name);
    out += fmt::format("neighbor {} bin\nneigh_modify delay 0 every 1 check yes\n", d17(skin));
    out += "pair_style granular\n";
    out += fmt::format("pair_coeff * * hertz/material {} {} {} {}\n", d17(m.young), pair_law.damping_coefficient, d17(m.poisson), pair_law.keywords);
    out += fmt::format("timestep {}\n", d17(scene.dt));
    const Vec3d& g = scene.gravity;
    const double gabs = std::sqrt(dot(g, g));
    if (gabs > 0.0) out += fmt::format("fix demmat_gravity all gravity {} vector {} {} {}\n", d17(gabs), d17(g.x / gabs), d17(g.y / gabs), d17(g.z / gabs));
    // Walls: the modulus argument that gives the suite's E* in this version's fix wall/gran (see header).
    const double nu = m.poisson;
    const std::string wall_law = fmt::format("granular hertz/material {} {} {} {}", d17(lammps_wall_modulus_argument(e_star_pw(scene), nu)),
                                             wall_law_words.damping_coefficient, d17(nu), wall_law_words.keywords);
    for (const Wall& w : s.walls) {
        const Vec3d p = w.point_at(s.step, scene.dt);
        const int a = axis_of(w.normal);
        if (!w.moving() && a >= 0) {
            const std::string pos = d17(component(p, a));
            out += fmt::format("fix wall_{} all wall/gran {} {}plane {} {}\n", w.name, wall_law, kAxis[a],
                               component(w.normal, a) > 0 ? pos : "NULL", component(w.normal, a) > 0 ? "NULL" : pos);
            continue;
        }
        // A moving (or oblique) wall: a plane region, displaced by v·(step·dt) from where it stands now;
        // fix wall/gran/region takes the region's velocity into the contact's relative velocity.
        std::string move;
        if (w.moving()) {
            std::string args[3];
            for (int c = 0; c < 3; ++c) {
                if (component(w.velocity, c) == 0.0) { args[c] = "NULL"; continue; }
                out += fmt::format("variable demmat_d{}_{} equal {}*step*dt\n", kAxis[c], w.name, d17(component(w.velocity, c)));
                args[c] = fmt::format("v_demmat_d{}_{}", kAxis[c], w.name);
            }
            move = fmt::format(" move {} {} {}", args[0], args[1], args[2]);
        }
        out += fmt::format("region demmat_{} plane {} {} {} {} {} {} side in{} units box\n", w.name, d17(p.x), d17(p.y), d17(p.z),
                           d17(w.normal.x), d17(w.normal.y), d17(w.normal.z), move);
        out += fmt::format("fix wall_{} all wall/gran/region {} region demmat_{}\n", w.name, wall_law, w.name);
    }
    out += "fix demmat_integrate all nve/sphere\n";
    return out;
}

// An axis-aligned wall as a rectangle of two triangles (ASCII STL) covering the domain's face and one
// largest radius more on each side, inside the padded box.
std::string wall_stl(const Scene& scene, const State& s, const Wall& w, int a)
{
    const Vec3d p = w.point_at(s.step, scene.dt);
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const double r = radius_max(s);
    const double b0 = component(scene.domain.min, b) - r, b1 = component(scene.domain.max, b) + r;
    const double c0 = component(scene.domain.min, c) - r, c1 = component(scene.domain.max, c) + r;
    auto vertex = [&](double vb, double vc) {
        Vec3d v;
        component(v, a) = component(p, a);
        component(v, b) = vb;
        component(v, c) = vc;
        return fmt::format("      vertex {} {} {}\n", d17(v.x), d17(v.y), d17(v.z));
    };
    const Vec3d& n = w.normal;
    auto facet = [&](const std::string& v1, const std::string& v2, const std::string& v3) {
        return fmt::format("  facet normal {} {} {}\n    outer loop\n{}{}{}    endloop\n  endfacet\n", d17(n.x), d17(n.y), d17(n.z), v1, v2, v3);
    };
    std::string out = fmt::format("solid {}\n", w.name);
    out += facet(vertex(b0, c0), vertex(b1, c0), vertex(b1, c1));
    out += facet(vertex(b0, c0), vertex(b1, c1), vertex(b0, c1));
    out += fmt::format("endsolid {}\n", w.name);
    return out;
}

std::string liggghts_fragment(const Scene& scene, const State& s, const PeerOptions& o, double skin,
                              std::vector<std::pair<std::string, std::string>>& meshes)
{
    if (!scene.contact_model.is_paper())
        throw Error(fmt::format("the LIGGGHTS fragment writes the paper's law only, not {}", scene.contact_model.describe()));
    const Material& m = scene.material;
    const ContactParams<double> cp = scene.contact_params();
    // hertz/stiffness: F = k_n·sqrt(R*δ)·δ − γ·m*·sqrt(R*δ)·u_n: k_n = (4/3)E* exactly; γ matches the
    // suite's γ_n at the reference overlap only (docs/peers.md, LIGGGHTS's damping).
    const double sq = liggghts_reference_sqrt_rdelta(scene, s);
    const double gn = m.gamma_n / sq, gt = m.gamma_t / sq;
    auto pairs = [](double pp, double pw) { return fmt::format("2 {} {} {} {}", d17(pp), d17(pw), d17(pw), d17(pw)); };
    std::string out = fmt::format(
        "# LIGGGHTS 3.8 input fragment from demmat export-lammps: scene '{}' at step {} (docs/peers.md).\n"
        "# Nearest model to the paper's law: hertz/stiffness (elastic part exact), damping gamma*m*sqrt(R*delta)*u_n\n"
        "# with gamma = gamma_n/sqrt(R*delta_ref), sqrt(R*delta_ref) = {} m; tangential no_history; limitForce on.\n",
        scene.name, s.step, d17(sq));
    out += "units si\natom_style granular\natom_modify map array\nboundary f f f\nnewton off\ncommunicate single vel yes\n";
    out += fmt::format("read_data {}\nreset_timestep 0\n", o.data_name);
    out += fmt::format("neighbor {} bin\nneigh_modify delay 0\n", d17(skin));
    out += fmt::format("fix demmat_kn all property/global kn peratomtypepair {}\n", pairs(cp.hertz_pp, cp.hertz_pw));
    out += fmt::format("fix demmat_kt all property/global kt peratomtypepair {}\n", pairs(0.0, 0.0));
    out += fmt::format("fix demmat_gn all property/global gamman peratomtypepair {}\n", pairs(gn, gn));
    out += fmt::format("fix demmat_gt all property/global gammat peratomtypepair {}\n", pairs(gt, gt));
    out += fmt::format("fix demmat_mu all property/global coefficientFriction peratomtypepair {}\n", pairs(m.mu, m.mu));
    // Model keywords follow the model names in pair_style, but the wall style in fix wall/gran.
    const std::string model = "model hertz/stiffness tangential no_history", keywords = "limitForce on";
    out += fmt::format("pair_style gran {} {}\npair_coeff * *\n", model, keywords);
    out += fmt::format("timestep {}\n", d17(scene.dt));
    const Vec3d& g = scene.gravity;
    const double gabs = std::sqrt(dot(g, g));
    if (gabs > 0.0) out += fmt::format("fix demmat_gravity all gravity {} vector {} {} {}\n", d17(gabs), d17(g.x / gabs), d17(g.y / gabs), d17(g.z / gabs));
    for (const Wall& w : s.walls) {
        const int a = axis_of(w.normal);
        if (a < 0) throw Error(fmt::format("export: wall '{}' is not axis-aligned; the LIGGGHTS export supports axis-aligned walls only", w.name));
        if (!w.moving()) {
            out += fmt::format("fix wall_{} all wall/gran {} primitive type 2 {}plane {} {}\n", w.name, model, kAxis[a],
                               d17(component(w.point_at(s.step, scene.dt), a)), keywords);
            continue;
        }
        const std::string stl = fmt::format("{}_{}.stl", o.mesh_prefix, safe_file_stem(w.name));  // a name from the scene stays a file name
        meshes.emplace_back(stl, wall_stl(scene, s, w, a));
        out += fmt::format("fix demmat_mesh_{} all mesh/surface file {} type 2\n", w.name, stl);
        out += fmt::format("fix wall_{} all wall/gran {} mesh n_meshes 1 meshes demmat_mesh_{} {}\n", w.name, model, w.name, keywords);
        out += fmt::format("fix demmat_move_{} all move/mesh mesh demmat_mesh_{} linear {} {} {}\n", w.name, w.name,
                           d17(w.velocity.x), d17(w.velocity.y), d17(w.velocity.z));
    }
    out += "fix demmat_integrate all nve/sphere\n";
    return out;
}

[[noreturn]] void bad(const std::string& file, std::size_t line, const std::string& what)
{
    throw Error(fmt::format("{}:{}: {}", file, line, what));
}

} // namespace

double lammps_wall_modulus_argument(double e_star_wall, double poisson) { return 2.0 * (1.0 - poisson) * e_star_wall; }

double liggghts_reference_sqrt_rdelta(const Scene& scene, const State& state)
{
    double mean = 0.0;
    for (double r : state.radius) mean += r;
    mean /= double(state.size());
    const double g = std::sqrt(dot(scene.gravity, scene.gravity));
    const double estar = e_star_pw(scene);
    // Rest overlap on a wall (physics.md §8); without gravity, a thousandth of the radius.
    const double h = g > 0.0 ? std::cbrt(std::pow(3.0 * sphere_mass(mean, scene.material.density) * g / (4.0 * estar * std::sqrt(mean)), 2.0))
                             : 1e-3 * mean;
    return std::sqrt(mean * h);
}

PeerExport export_peers(const Scene& scene, const State& state, const PeerOptions& options)
{
    if (state.size() == 0) throw Error("export: the state has no particles");
    PeerExport e;
    // A data file holds particles, not contacts: a state's stretches are not carried (LAMMPS starts every
    // contact at zero stretch), which export-lammps says; a start without live contacts loses nothing.
    if (!state.stretches.empty())
        e.warning = fmt::format("the state's {} contact stretches are not carried: LAMMPS starts every contact with zero stretch",
                                state.stretches.size());
    const double skin = options.skin > 0.0 ? options.skin : 0.5 * radius_min(state);
    e.data = data_file(scene, state);
    e.lammps = lammps_fragment(scene, state, options, skin);
    try {
        e.liggghts = liggghts_fragment(scene, state, options, skin, e.meshes);
    } catch (const Error& err) {
        e.liggghts.clear();
        e.meshes.clear();
        e.note = err.what();
    }
    return e;
}

void perturb_velocities(State& state, double amplitude, std::uint64_t seed)
{
    SplitMix r(seed);
    for (Vec3d& v : state.trans.v)
        for (int c = 0; c < 3; ++c) component(v, c) += amplitude * (2.0 * r.uniform() - 1.0);
}

State import_peer_state(const std::filesystem::path& file, const Scene& scene)
{
    const std::string label = file.string();
    std::vector<std::string> lines;
    {
        // A regular file of at most 64 GiB (a text dump of 10^8 atoms with 11 columns of 17 digits is ~20 GB).
        std::istringstream in(read_input_file(file, "LAMMPS file", std::uintmax_t(64) << 30));
        for (std::string l; std::getline(in, l);) lines.push_back(l);
    }
    auto trim = [](std::string s) {
        const auto c = s.find('#');
        if (c != std::string::npos) s.erase(c);
        s.erase(0, s.find_first_not_of(" \t\r"));
        s.erase(s.find_last_not_of(" \t\r") + 1);
        return s;
    };
    auto numbers = [&](std::size_t k, std::size_t want) {
        std::istringstream ss(lines[k]);
        std::vector<double> v;
        for (std::string t; ss >> t;) {
            try {
                std::size_t used = 0;
                v.push_back(std::stod(t, &used));
                if (used != t.size()) throw std::invalid_argument(t);
            } catch (const std::exception&) {
                bad(label, k + 1, fmt::format("'{}' is not a number", t));
            }
        }
        if (v.size() < want) bad(label, k + 1, fmt::format("expected {} columns, found {}", want, v.size()));
        return v;
    };

    // An atom count as written (an integer, no exponent), believed only as far as the file can hold it:
    // each atom needs a line of its own after line k, so a header cannot make the reader allocate more.
    auto atom_count = [&](const std::string& text, std::size_t k) {
        std::int64_t c = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), c);
        if (ec == std::errc::result_out_of_range || (ec == std::errc() && end == text.data() + text.size() && c > kMaxParticles))
            bad(label, k + 1, fmt::format("{} atoms is more than the {} particles a state can hold", text, kMaxParticles));
        if (ec != std::errc() || end != text.data() + text.size() || c < 1) bad(label, k + 1, fmt::format("bad number of atoms '{}'", text));
        if (std::uint64_t(c) > lines.size() - k - 1)
            bad(label, k + 1, fmt::format("the header announces {} atoms, but only {} lines follow it", c, lines.size() - k - 1));
        return std::size_t(c);
    };
    auto is_section = [&](const std::string& t) { return t == "Atoms" || t == "Velocities"; };

    std::size_t n = 0;
    std::vector<double> radius, density;
    std::vector<Vec3d> x, v, w;
    std::vector<char> seen;
    auto slot = [&](double id, std::size_t k) {
        if (id != std::floor(id) || id < 1 || id > double(n)) bad(label, k + 1, fmt::format("atom id {} is not in 1..{}", id, n));
        return std::size_t(id) - 1;
    };
    auto allocate = [&] {
        radius.assign(n, 0.0); density.assign(n, scene.material.density);
        x.assign(n, {}); v.assign(n, {}); w.assign(n, {}); seen.assign(n, 0);
    };

    // The step the particles belong to: a dump frame's TIMESTEP, or the step export-lammps names in a data
    // file's title ("... at step S, ..."); 0 for another code's data file.
    std::int64_t step = 0;
    auto step_of = [&](const std::string& text, std::size_t k) {
        std::int64_t v = -1;
        const std::string t = trim(text);
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc() || end != t.data() + t.size() || v < 0) bad(label, k + 1, fmt::format("'{}' is not a step number", t));
        return v;
    };
    const bool dump = !lines.empty() && trim(lines[0]) == "ITEM: TIMESTEP";
    if (dump) {
        // Frames: the last complete one wins.
        std::size_t k = 0;
        bool any = false;
        while (k < lines.size()) {
            if (trim(lines[k]).empty()) { ++k; continue; }
            if (trim(lines[k]) != "ITEM: TIMESTEP") bad(label, k + 1, "expected ITEM: TIMESTEP");
            if (k + 1 >= lines.size()) bad(label, k + 1, "the dump frame is truncated");
            step = step_of(lines[k + 1], k + 1);
            k += 2;
            if (k >= lines.size() || trim(lines[k]) != "ITEM: NUMBER OF ATOMS") bad(label, k + 1, "expected ITEM: NUMBER OF ATOMS");
            if (k + 1 >= lines.size()) bad(label, k + 1, "the dump frame is truncated");
            n = atom_count(trim(lines[k + 1]), k + 1);
            k += 2;
            if (k >= lines.size() || lines[k].rfind("ITEM: BOX BOUNDS", 0) != 0) bad(label, k + 1, "expected ITEM: BOX BOUNDS");
            k += 4;
            if (k >= lines.size() || lines[k].rfind("ITEM: ATOMS", 0) != 0) bad(label, k + 1, "expected ITEM: ATOMS");
            std::map<std::string, std::size_t> col;
            {
                std::istringstream ss(lines[k].substr(11));
                std::size_t c = 0;
                for (std::string t; ss >> t;) col[t] = c++;
            }
            for (const char* need : {"id", "x", "y", "z"})
                if (!col.count(need)) bad(label, k + 1, fmt::format("the dump has no '{}' column", need));
            if (!col.count("radius") && !col.count("diameter")) bad(label, k + 1, "the dump has neither a 'radius' nor a 'diameter' column");
            allocate();
            auto get = [&](const std::vector<double>& row, const char* name) { return col.count(name) ? row[col[name]] : 0.0; };
            for (std::size_t a = 0; a < n; ++a) {
                const std::size_t line = k + 1 + a;
                if (line >= lines.size()) bad(label, line, "the dump frame is truncated");
                const std::vector<double> row = numbers(line, col.size());
                if (row.size() != col.size())
                    bad(label, line + 1, fmt::format("{} values, but ITEM: ATOMS names {} columns", row.size(), col.size()));
                const std::size_t i = slot(row[col["id"]], line);
                if (seen[i]) bad(label, line + 1, fmt::format("atom id {} appears twice", i + 1));
                seen[i] = 1;
                radius[i] = col.count("radius") ? row[col["radius"]] : 0.5 * row[col["diameter"]];
                x[i] = {row[col["x"]], row[col["y"]], row[col["z"]]};
                v[i] = {get(row, "vx"), get(row, "vy"), get(row, "vz")};
                w[i] = {get(row, "omegax"), get(row, "omegay"), get(row, "omegaz")};
            }
            k += 1 + n;
            any = true;
        }
        if (!any) bad(label, 1, "the dump has no frame");
    } else {
        // export-lammps's title: "LAMMPS data file from demmat export-lammps: scene '…' at step S, N particles, …".
        const std::string head = "LAMMPS data file from demmat export-lammps: ";
        if (!lines.empty() && lines[0].rfind(head, 0) == 0) {
            const std::string& t = lines[0];
            const auto at = t.rfind(" at step ", t.find(" particles,"));
            const auto comma = at == std::string::npos ? std::string::npos : t.find(", ", at);
            if (comma != std::string::npos) step = step_of(t.substr(at + 9, comma - at - 9), 0);
        }
        std::size_t k = 1;  // line 1 is the title
        for (; k < lines.size(); ++k) {
            const std::string t = trim(lines[k]);
            if (t.empty()) continue;
            if (t == "Atoms" || t == "Velocities") break;
            std::istringstream ss(t);
            std::string value, word;
            if (ss >> value >> word && word == "atoms" && !(ss >> word)) n = atom_count(value, k);
        }
        if (n == 0) bad(label, k, "no 'N atoms' line in the header of this LAMMPS data file");
        allocate();
        bool atoms = false;
        while (k < lines.size()) {
            const std::string section = trim(lines[k]);
            if (section.empty()) { ++k; continue; }
            if (!is_section(section)) {
                if (std::isdigit(static_cast<unsigned char>(section[0])))
                    bad(label, k + 1, fmt::format("more atom lines than the {} atoms the header announces", n));
                bad(label, k + 1, fmt::format("unknown section '{}' (expected Atoms or Velocities)", section));
            }
            ++k;
            std::size_t got = 0;
            while (k < lines.size() && got < n) {
                if (trim(lines[k]).empty()) { ++k; continue; }
                if (is_section(trim(lines[k]))) break;  // the next section: this one is short (reported below)
                const std::vector<double> row = numbers(k, 7);
                const std::size_t i = slot(row[0], k);
                if (section == "Atoms") {
                    if (seen[i]) bad(label, k + 1, fmt::format("atom id {} appears twice", i + 1));
                    seen[i] = 1;
                    radius[i] = 0.5 * row[2];
                    density[i] = row[3];
                    x[i] = {row[4], row[5], row[6]};
                } else {
                    v[i] = {row[1], row[2], row[3]};
                    w[i] = {row[4], row[5], row[6]};
                }
                ++got;
                ++k;
            }
            if (got < n) bad(label, k, fmt::format("section {} has {} of {} atoms", section, got, n));
            atoms = atoms || section == "Atoms";
        }
        if (!atoms) bad(label, lines.size(), "no Atoms section");
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!seen[i]) throw Error(fmt::format("{}: atom id {} is missing", label, i + 1));
        // The particles must fit the scene: inside its domain, not behind one of its walls.
        for (int c = 0; c < 3; ++c)
            if (!(component(x[i], c) >= component(scene.domain.min, c) && component(x[i], c) <= component(scene.domain.max, c)))
                throw Error(fmt::format("{}: atom id {} at ({}, {}, {}) lies outside the domain of scene '{}' ({}, {}, {}) to ({}, {}, {})",
                                        label, i + 1, x[i].x, x[i].y, x[i].z, scene.name, scene.domain.min.x, scene.domain.min.y,
                                        scene.domain.min.z, scene.domain.max.x, scene.domain.max.y, scene.domain.max.z));
        if (!(radius[i] > 0.0) || !std::isfinite(radius[i])) throw Error(fmt::format("{}: atom id {} has radius {}", label, i + 1, radius[i]));
        const Vec3d side = scene.domain.max - scene.domain.min;
        if (2.0 * radius[i] > std::min({side.x, side.y, side.z}))
            throw Error(fmt::format("{}: atom id {} has diameter {} m, larger than the smallest side {} m of the domain of scene '{}'",
                                    label, i + 1, 2.0 * radius[i], std::min({side.x, side.y, side.z}), scene.name));
        if (std::abs(density[i] - scene.material.density) > 1e-12 * scene.material.density)
            throw Error(fmt::format("{}: atom id {} has density {}, the scene's material has {}", label, i + 1, density[i], scene.material.density));
        for (const Vec3d* q : {&x[i], &v[i], &w[i]})
            if (!std::isfinite(q->x) || !std::isfinite(q->y) || !std::isfinite(q->z))
                throw Error(fmt::format("{}: atom id {} has a non-finite value", label, i + 1));
    }

    State s;
    s.resize(n);
    s.dt = scene.dt;
    s.step = step;
    // The scene's walls where the scene puts them, moving from this step on (as continue_walls places a
    // wall a saved state does not know; a data file carries no walls).
    s.walls = continue_walls(scene, s);
    for (std::size_t i = 0; i < n; ++i)
        for (const Wall& wall : s.walls)
            if (dot(x[i] - wall.point_at(step, scene.dt), wall.normal) < 0.0)
                throw Error(fmt::format("{}: atom id {} at ({}, {}, {}) lies behind wall '{}' of scene '{}'", label, i + 1, x[i].x, x[i].y,
                                        x[i].z, wall.name, scene.name));
    s.fingerprint = scene.fingerprint(n);
    s.radius = radius;
    s.trans.x = x;
    s.trans.v = v;
    s.rot.v = w;
    initial_accelerations(scene, s);  // t = 0, as for any new scene
    return s;
}

std::string lammps_dump_frame(std::int64_t step, const Scene& scene, const std::vector<double>& radius,
                              const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w)
{
    std::string out = fmt::format("ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS ff ff ff\n", step, radius.size());
    for (int a = 0; a < 3; ++a) out += fmt::format("{} {}\n", d17(component(scene.domain.min, a)), d17(component(scene.domain.max, a)));
    out += "ITEM: ATOMS id radius x y z vx vy vz omegax omegay omegaz\n";
    for (std::size_t i = 0; i < radius.size(); ++i)
        out += fmt::format("{} {} {} {} {} {} {} {} {} {} {}\n", i + 1, d17(radius[i]), d17(x[i].x), d17(x[i].y), d17(x[i].z), d17(v[i].x),
                           d17(v[i].y), d17(v[i].z), d17(w[i].x), d17(w[i].y), d17(w[i].z));
    return out;
}

} // namespace demmat
