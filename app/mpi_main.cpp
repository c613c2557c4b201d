// demmat_mpi: the mpi variant under mpirun (`mpirun -np R demmat_mpi run SCENE ...`). Rank 0 reads the
// scene and its state and writes every output; every rank runs one Driver over its share. The
// subcommands that run a variant are demmat's (run, compare, bench, list), for the mpi variant only;
// those that only write files (scene, export-lammps, import-lammps, dump) stay with demmat.
//
// Errors: bad input is found on rank 0 before any long work and sent to every rank, which all exit with
// status 2 (rank 0 prints the one line). A failure during a run (a blow-up found by a health check, or
// by one rank's phase) is printed by the rank that met it, and MPI_Abort stops every rank.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <mpi.h>
#include <nlohmann/json.hpp>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/io.hpp"
#include "demmat/output.hpp"
#include "demmat/problem.hpp"
#include "demmat/registry.hpp"
#include "demmat/stability.hpp"
#include "cli_ranges.hpp"
#include "leak_check.hpp"
#include "lockstep.hpp"
#include "mpi_report.hpp"
#include "mpi_variant.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace demmat;
using namespace demmat::mpi;

namespace {

struct Args {
    std::string scene, variant = "mpi", variants = "arrays,mpi", json_file, save_file, balance = "count", grid = "auto";
    std::int64_t steps = 1000, repetitions = 5, warmup = 20;
    double time = 0.0;
    bool quiet = false, allow_unstable = false;
};

MpiOptions options_of(const Args& a)
{
    MpiOptions o;
    if (a.balance == "count") o.balance = Balance::count;
    else if (a.balance == "even") o.balance = Balance::even;
    else throw Error(fmt::format("unknown --balance '{}' (expected count or even)", a.balance));
    if (a.grid != "auto") {
        int x = 0, y = 0, z = 0;
        char t1 = 0, t2 = 0, rest = 0;
        if (std::sscanf(a.grid.c_str(), "%d%c%d%c%d%c", &x, &t1, &y, &t2, &z, &rest) != 5 || t1 != 'x' || t2 != 'x' || x < 1 || y < 1 || z < 1)
            throw Error(fmt::format("--grid '{}' is not auto or PxPyPz with positive counts (e.g. 2x2x1)", a.grid));
        o.grid = {x, y, z};
    }
    return o;
}

std::int64_t steps_for(const Scene& scene, std::int64_t steps, double time)
{
    if (!(time >= 0.0) || !(time / scene.dt <= double(kMaxSteps)))
        throw Error(fmt::format("--time {:g} s is more than a run of Δt = {:g} s can reach in {} steps", time, scene.dt, kMaxSteps));
    return time > 0.0 ? std::max<std::int64_t>(1, steps_to_reach(time, scene.dt)) : steps;
}

// Rank 0's loading, with everything checked before any long work: the variant named, the options, the
// outputs (not a folder, not an input, not the same file twice), the scene and its state, Δt.
std::unique_ptr<Problem> load_checked(const Comm& comm, const Args& a, const std::function<void()>& check = {})
{
    return share_problem(comm, [&] {
        if (check) check();
        if (a.variant != "mpi")
            throw Error(fmt::format("demmat_mpi runs the mpi variant only, not '{}' (run the others with demmat)", a.variant));
        options_of(a);
        Scene scene = load_scene(a.scene);
        std::vector<NamedPath> inputs{{scene.source, "scene file"}};
        if (!scene.state_file.empty()) inputs.emplace_back(scene.state_file, "state file");
        if (!a.json_file.empty()) check_output_path(a.json_file, "--json", inputs);
        if (!a.save_file.empty()) check_output_path(a.save_file, "--save", inputs);
        if (!a.json_file.empty() && !a.save_file.empty() && same_file(a.json_file, a.save_file))
            throw Error(fmt::format("--json and --save name the same file {}", a.json_file));
        if (!scene.integrator.is_default())
            throw Error(fmt::format("the mpi variant integrates with gear5 in double only, not {}", scene.integrator.describe()));
        auto p = std::make_unique<Problem>(std::move(scene));
        if (!a.allow_unstable) {
            const std::string warning = check_time_step(p->scene(), p->state());
            if (!warning.empty()) std::cerr << "demmat_mpi: warning: " << warning << "\n";
        }
        steps_for(p->scene(), a.steps, a.time);
        return p;
    });
}

int cmd_run(const Comm& comm, const Args& a)
{
    auto p = load_checked(comm, a);
    const std::int64_t steps = steps_for(p->scene(), a.steps, a.time);
    auto v = make_mpi_variant(comm.handle(), options_of(a));
    Driver driver(*v, p->setup());
    if (comm.root() && !a.quiet)
        std::cerr << fmt::format("demmat_mpi: mpi on '{}' at {} processes: {} particles, {} walls, {} steps of {:g} s from step {}\n",
                                 p->scene().name, comm.size(), p->size(), p->state().walls.size(), steps, p->scene().dt, p->state().step);
    const double start = MPI_Wtime();
    driver.run(steps);
    const double wall = MPI_Wtime() - start;
    const RunReport r = gather_report(*v, driver, steps);
    const ContactCounts c = v->counts();
    Snapshot snap;
    v->snapshot(snap);
    State saved;
    if (!a.save_file.empty()) v->save(saved);
    if (!comm.root()) return 0;
    const double ke = kinetic_energy(snap, p->setup());
    const double n = double(p->size());
    std::cout << fmt::format("variant mpi  scene {}  particles {}  steps {}  t = {:.6g} s  processes {} (bricks {})\n", p->scene().name,
                             p->size(), steps, driver.time(), comm.size(), v->bricks().grid());
    if (!p->scene().contact_model.is_paper())
        std::cout << "contact law " << describe_law(p->scene().contact_model, p->setup().memory) << "\n";
    std::cout << fmt::format("model {}  (the scene needs {})\n", v->model().name(), features_of(p->scene(), p->state()).name());
    print_report(std::cout, r, n);
    std::cout << fmt::format("contacts per particle {:.3f} (particle-particle {}, particle-wall {})  kinetic energy {:.6e} J\n",
                             c.per_particle(p->size()), c.particle_particle, c.particle_wall, ke);
    std::cout << fmt::format("PERFORMANCE variant=mpi processes={} particles={} steps={} us_per_particle_step={:.5f} seconds={:.4f}\n",
                             comm.size(), p->size(), steps, r.total() / n * 1e6, wall);
    if (!a.save_file.empty()) {
        saved.dt = p->scene().dt;
        saved.fingerprint = p->state().fingerprint;
        save_state(saved, a.save_file);
    }
    if (!a.json_file.empty()) {
        json j = {{"provenance", provenance_json()},
                  {"scene", {{"name", p->scene().name}, {"file", p->scene().source.string()}, {"particles", p->size()}, {"dt", p->scene().dt},
                             {"start_step", p->state().step}}},
                  {"variant", "mpi"},
                  {"processes", comm.size()},
                  {"model", {{"picked", v->model().name()}, {"scene_needs", features_of(p->scene(), p->state()).name()}}},
                  {"steps", steps},
                  {"end_time", driver.time()},
                  {"wall_seconds", wall},
                  {"us_per_particle_step", r.total() / n * 1e6},
                  {"decomposition", report_json(r, *v)},
                  {"contacts", {{"particle_particle", c.particle_particle}, {"particle_wall", c.particle_wall},
                                {"per_particle", c.per_particle(p->size())}}},
                  {"kinetic_energy", ke}};
        write_atomically(a.json_file, j.dump(2) + "\n");
    }
    return 0;
}

// The mpi variant against a reference run on rank 0, at every step.
int cmd_compare(const Comm& comm, const Args& a)
{
    const auto names = std::vector<std::string>{a.variants.substr(0, a.variants.find(',')), a.variants.substr(a.variants.find(',') + 1)};
    auto p = load_checked(comm, a, [&] {
        if (a.variants.find(',') == std::string::npos || names[1] != "mpi" || names[0] == "mpi")
            throw Error(fmt::format("demmat_mpi compare takes --variants REFERENCE,mpi (e.g. arrays,mpi), not '{}'", a.variants));
        registry().find(names[0]);
    });
    const std::int64_t steps = steps_for(p->scene(), a.steps, a.time);
    auto v = make_mpi_variant(comm.handle(), options_of(a));
    const LockstepResult r = compare_lockstep(*p, *v, registry().find(names[0]).create, names[0], steps);
    if (!comm.root()) return r.difference ? 1 : 0;
    if (r.difference) {
        std::cout << "differ: " << r.difference->describe() << "\n";
        return 1;
    }
    std::cout << fmt::format("identical: {}, mpi at {} processes over {} steps of '{}' ({} particles)\n", names[0], comm.size(), r.steps,
                             p->scene().name, p->size());
    return 0;
}

// Repetitions of measure_steps (warm-up, then timed steps with the health checks), one report per
// repetition; the medians and every sample in --json.
int cmd_bench(const Comm& comm, const Args& a)
{
    auto p = load_checked(comm, a);
    std::vector<RunReport> reps;
    json samples = json::array();
    ContactCounts c;
    std::unique_ptr<MpiVariant> last;
    for (std::int64_t k = 0; k < a.repetitions; ++k) {
        auto v = make_mpi_variant(comm.handle(), options_of(a));
        Driver driver(*v, p->setup());
        for (std::int64_t w = 0; w < a.warmup; ++w) driver.step();
        const auto before = snapshot_counters(*v, driver);
        driver.run(a.steps);
        reps.push_back(gather_report(*v, driver, a.steps, &before));
        c = v->counts();
        if (comm.root()) samples.push_back(report_json(reps.back(), *v));
        last = std::move(v);
    }
    const std::int64_t bytes = comm.sum(std::int64_t(last->memory_bytes()));  // every rank's, as Variant::memory_bytes
    if (!comm.root()) return 0;
    const RunReport med = median_report(reps);
    const double n = double(p->size());
    std::cout << fmt::format("variant mpi  scene {}  particles {}  processes {} (bricks {})  ({} repetitions of {} steps after {} warm-up steps)\n",
                             p->scene().name, p->size(), comm.size(), last->bricks().grid(), a.repetitions, a.steps, a.warmup);
    print_report(std::cout, med, n);
    if (!a.json_file.empty()) {
        json j = {{"provenance", provenance_json()},
                  {"scene", {{"name", p->scene().name}, {"file", p->scene().source.string()}, {"particles", p->size()}, {"dt", p->scene().dt}}},
                  {"variant", "mpi"},
                  {"processes", comm.size()},
                  {"model", last->model().name()},
                  {"steps", a.steps},
                  {"warmup_steps", a.warmup},
                  {"repetitions", a.repetitions},
                  {"us_per_particle_step", med.total() / n * 1e6},
                  {"contacts_per_particle", c.per_particle(p->size())},
                  {"memory_bytes", bytes},
                  {"median", report_json(med, *last)},
                  {"samples", samples}};
        write_atomically(a.json_file, j.dump(2) + "\n");
    }
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    MPI_Init(&argc, &argv);
    const Comm comm(MPI_COMM_WORLD);
    auto finish = [](int rc) {
        check_leaks_before_finalize();
        MPI_Finalize();
        return rc;
    };
    CLI::App app{"demmat_mpi: the mpi variant of the DEMMAT suite, run under mpirun -np R (rank 0 reads and writes every file)"};
    app.require_subcommand(1);
    Args a;
    auto* list = app.add_subcommand("list", "List the variant this program runs");
    auto add_common = [&](CLI::App* c) {
        c->add_option("scene", a.scene, "Scene file (TOML)")->required();
        auto* s = c->add_option("--steps,-n", a.steps, "Number of steps")->check(integer_in(1, kMaxSteps));
        c->add_option("--time,-t", a.time, "Simulated time (s), instead of --steps")->excludes(s)->check(number_from(0.0, true));
        c->add_option("--balance", a.balance, "Where the bricks are cut along each axis: count (at the quantiles of the particles, the default) or even (equal widths)");
        c->add_option("--grid", a.grid, "Bricks along x, y and z, as PxPyPz (their product the process count), or auto (the default: the grid whose cuts have the least area)");
        c->add_flag("--allow-unstable", a.allow_unstable, "Run even with a time step above the Rayleigh time, without warning");
    };
    auto* run = app.add_subcommand("run", "Run a scene with the mpi variant and report per-phase times and the decomposition");
    add_common(run);
    run->add_option("--variant,-v", a.variant, "Variant name (mpi only)");
    run->add_option("--json", a.json_file, "Write the summary as JSON with provenance")->check(path_given());
    run->add_option("--save", a.save_file, "Save the final state, gathered on rank 0 (it continues at any process count)")->check(path_given());
    run->add_flag("--quiet,-q", a.quiet, "No progress on stderr");
    auto* compare = app.add_subcommand("compare", "Run the mpi variant beside a reference variant on rank 0 and check every step bit for bit");
    add_common(compare);
    compare->add_option("--variants", a.variants, "REFERENCE,mpi (default arrays,mpi)");
    auto* bench = app.add_subcommand("bench", "Time the mpi variant per phase (communicate included): repetitions, medians");
    add_common(bench);
    bench->add_option("--variants,--variant", a.variant, "Variant name (mpi only)");
    bench->add_option("--repetitions,-r", a.repetitions, "Repetitions")->check(integer_in(1, 1000000));
    bench->add_option("--warmup", a.warmup, "Untimed steps before each repetition")->check(integer_in(0, kMaxSteps));
    bench->add_option("--json", a.json_file, "Write the samples and medians as JSON with provenance")->check(path_given());
    bench->get_option("--steps")->default_val(200);
    for (const char* name : {"scene", "export-lammps", "import-lammps", "dump"})
        app.add_subcommand(name, "(runs on one process: use demmat)")->allow_extras();
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return finish(comm.root() ? app.exit(e) : 0);
    } catch (const CLI::ParseError& e) {
        if (comm.root()) std::cerr << "demmat_mpi: error: " << e.what() << " (see demmat_mpi --help)\n";
        return finish(2);
    }
    try {
        try {
            if (*list) {
                if (comm.root()) std::cout << "mpi  spatial domain decomposition over MPI ranks, bit-identical to arrays at any process count\n";
                return finish(0);
            }
            for (CLI::App* sub : app.get_subcommands())
                if (sub != run && sub != compare && sub != bench)
                    throw AllRanksError(fmt::format("'{}' writes files on one process: run it with demmat", sub->get_name()));
            if (*run) return finish(cmd_run(comm, a));
            if (*compare) return finish(cmd_compare(comm, a));
            if (*bench) return finish(cmd_bench(comm, a));
        } catch (const AllRanksError& e) {
            // Bad input: every rank threw it together (share_problem, the plan); rank 0 says it once.
            if (comm.root()) std::cerr << "demmat_mpi: error: " << e.what() << "\n";
            return finish(2);
        }
    } catch (const InstabilityError& e) {
        std::cerr << fmt::format("demmat_mpi: run stopped (rank {}): {}\n", comm.rank(), e.what());
        MPI_Abort(MPI_COMM_WORLD, 3);
    } catch (const std::exception& e) {
        std::cerr << fmt::format("demmat_mpi: error (rank {}): {}\n", comm.rank(), e.what());
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    return finish(0);
}
