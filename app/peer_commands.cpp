#include "peer_commands.hpp"

#include <algorithm>

#include <iostream>
#include <limits>

#include <fmt/format.h>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/peer_io.hpp"
#include "demmat/registry.hpp"
#include "demmat/stability.hpp"
#include "cli_ranges.hpp"

namespace fs = std::filesystem;

namespace demmat {

struct PeerCommands::Args {
    CLI::App* exp = nullptr;
    CLI::App* imp = nullptr;
    CLI::App* dump = nullptr;
    std::string scene, state, out, variant = "arrays", integrator;
    double perturb = 0.0, skin = 0.0;
    std::uint64_t seed = 1;
    std::int64_t steps = 1000, every = 100;
    bool allow_unstable = false;
};

PeerCommands::PeerCommands(CLI::App& app) : a_(std::make_unique<Args>())
{
    Args& a = *a_;
    a.exp = app.add_subcommand("export-lammps",
                               "Write a scene's particles as a LAMMPS data file, with LAMMPS and LIGGGHTS input fragments (docs/peers.md)");
    a.exp->add_option("scene", a.scene, "Scene file (TOML)")->required();
    a.exp->add_option("--state", a.state, "Take the particles from this state file instead of the scene's own source")->check(path_given());
    a.exp->add_option("--out,-o", a.out, "Data file to write (NAME.data); beside it NAME.lammps, NAME.liggghts, NAME_<wall>.stl")->required()->check(path_given());
    a.exp->add_option("--perturb", a.perturb, "Add random velocities with components uniform in [-A, A] m/s (an ensemble member)")
        ->check(number_from(0.0, false));
    a.exp->add_option("--seed", a.seed, "Seed of the perturbation")->check(integer_in(0, std::numeric_limits<std::int64_t>::max()));
    a.exp->add_option("--skin", a.skin, "Neighbour skin of the peers (m); default half the smallest radius")->check(number_from(0.0, false));

    a.imp = app.add_subcommand("import-lammps", "Read a LAMMPS data file or dump (last frame) into a state file for a scene");
    a.imp->add_option("file", a.state, "LAMMPS data file or text dump")->required();
    a.imp->add_option("--scene", a.scene, "The scene the particles belong to (materials, walls, time step)")->required();
    a.imp->add_option("--out,-o", a.out, "State file to write")->required()->check(path_given());

    a.dump = app.add_subcommand("dump", "Run a scene with one variant and write LAMMPS-style dump frames (id radius x v omega)");
    a.dump->add_option("scene", a.scene, "Scene file (TOML)")->required();
    a.dump->add_option("--state", a.state, "Start from this state file instead of the scene's own source")->check(path_given());
    a.dump->add_option("--variant,-v", a.variant, "Variant name (see demmat list)");
    a.dump->add_option("--steps,-n", a.steps, "Number of steps")->check(integer_in(1, kMaxSteps));
    a.dump->add_option("--every", a.every, "Steps between frames (the first frame is the initial state; frames carry the "
                                           "scene's step, continued from a state file's)")->check(integer_in(1, kMaxSteps));
    a.dump->add_option("--integrator", a.integrator, "gear5 | gear3 | verlet | symplectic_euler (overrides the scene's [integrator])");
    a.dump->add_option("--out,-o", a.out, "Dump file to write")->required()->check(path_given());
    a.dump->add_flag("--allow-unstable", a.allow_unstable, "Run even with a time step above the integrator's stability limit, without warning");
}

PeerCommands::~PeerCommands() = default;

namespace {

// The scene continued from another state file, when one is given (its walls as a run from that state
// would have them).
void use_state_file(Scene& scene, const std::string& state_file)
{
    if (state_file.empty()) return;
    scene.grid.reset();
    scene.particles.clear();
    scene.state_file = state_file;
}

// The files a command reads, which its outputs must not overwrite.
std::vector<NamedPath> inputs_of(const Scene& scene, const std::string& other = {}, const std::string& other_kind = {})
{
    std::vector<NamedPath> in{{scene.source, "scene file"}};
    if (!scene.state_file.empty()) in.emplace_back(scene.state_file, "state file");
    if (!other.empty()) in.emplace_back(other, other_kind);
    return in;
}

int cmd_export(const std::string& scene_file, const std::string& state_file, const std::string& out,
               double perturb, std::uint64_t seed, double skin)
{
    Scene scene = load_scene(scene_file);
    use_state_file(scene, state_file);
    const fs::path data = out;
    if (data.filename().empty()) throw Error(fmt::format("export: '{}' is not a file name", out));
    const auto inputs = inputs_of(scene);
    for (const char* ext : {".data", ".lammps", ".liggghts"})
        check_output_path(data.parent_path() / (data.stem().string() + ext), "--out", inputs);
    check_output_path(data, "--out", inputs);
    State state = initial_state(scene);
    const Vec3d side = scene.domain.max - scene.domain.min;
    if (skin > std::max({side.x, side.y, side.z}))
        throw Error(fmt::format("--skin {:g} m is larger than the domain itself (its largest side is {:g} m)", skin, std::max({side.x, side.y, side.z})));
    if (perturb > 0.0) {
        perturb_velocities(state, perturb, seed);
        try {  // the perturbed grains must still make a run the time-step check accepts
            check_time_step(scene, state);
        } catch (const Error& e) {
            throw Error(fmt::format("--perturb {:g} m/s: the perturbed velocities fail the time-step check: {}", perturb, e.what()));
        }
    }
    PeerOptions o;
    o.data_name = data.filename().string();
    o.mesh_prefix = data.stem().string();
    o.skin = skin;
    const PeerExport e = export_peers(scene, state, o);
    const fs::path dir = data.parent_path();
    // Meshes and fragments first, the data file last: a data file present means the set is complete.
    for (const auto& [name, text] : e.meshes) write_atomically(dir / name, text);
    write_atomically(dir / (data.stem().string() + ".lammps"), e.lammps);
    if (!e.liggghts.empty()) write_atomically(dir / (data.stem().string() + ".liggghts"), e.liggghts);
    else std::cerr << "demmat: warning: no LIGGGHTS fragment: " << e.note << "\n";
    if (!e.warning.empty()) std::cerr << "demmat: warning: " << e.warning << "\n";
    write_atomically(data, e.data);
    return 0;
}

int cmd_import(const std::string& file, const std::string& scene_file, const std::string& out)
{
    const Scene scene = load_scene(scene_file);
    check_output_path(out, "--out", inputs_of(scene, file, "LAMMPS file"));
    const State s = import_peer_state(file, scene);
    save_state(s, out);
    return 0;
}

int cmd_dump(const std::string& scene_file, const std::string& state_file, const std::string& variant_name, const std::string& integrator,
             std::int64_t steps, std::int64_t every, const std::string& out, bool allow_unstable)
{
    Scene scene = load_scene(scene_file);
    override_integrator(scene, integrator, {});
    use_state_file(scene, state_file);
    check_output_path(out, "--out", inputs_of(scene));
    const State state = initial_state(scene);
    if (!allow_unstable) {  // the time step against the chosen integrator's limit, as run checks it
        const std::string warning = check_time_step(scene, state);
        if (!warning.empty()) std::cerr << "demmat: warning: " << warning << "\n";
    } else {
        check_magnitudes(scene, state);
    }
    const Setup setup = Setup::make(scene, state);
    auto variant = registry().find(variant_name).create();
    Driver driver(*variant, setup);
    // The run happens inside the one atomic writer of every output (a fresh temporary file, removed on an
    // error or a signal, renamed into place at the end): the dump is complete or absent.
    write_atomically(out, [&](std::ostream& f) {
        Snapshot snap;
        auto frame = [&](std::int64_t k) {
            variant->snapshot(snap);
            f << lammps_dump_frame(k, scene, state.radius, snap.position, snap.velocity, snap.angular_velocity);
            if (!f) throw Error(fmt::format("{}: write failed (disk full?)", out));
        };
        // Frames carry the scene's step: a run from a state file at step S writes S, S + every, ...
        frame(state.step);
        driver.run(steps, [&](std::int64_t k) { if (k % every == 0) frame(driver.current_step()); });
    });
    return 0;
}

} // namespace

int PeerCommands::dispatch()
{
    const Args& a = *a_;
    if (*a.exp) return cmd_export(a.scene, a.state, a.out, a.perturb, a.seed, a.skin);
    if (*a.imp) return cmd_import(a.state, a.scene, a.out);
    if (*a.dump) return cmd_dump(a.scene, a.state, a.variant, a.integrator, a.steps, a.every, a.out, a.allow_unstable);
    return -1;
}

} // namespace demmat
