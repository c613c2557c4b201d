#pragma once
// The run log (`demmat run --log FILE`): a CSV time series of the energies, the contacts, the largest
// overlap and the force on every wall, what LAMMPS's `thermo` prints. Every value is computed from a
// variant's Snapshot and the Setup between steps, outside the timed phases, through the shared law
// (contact_law.hpp), contact set (reference.hpp) and energies (driver.hpp, stability.hpp). The elastic
// energy and the wall forces are evaluated on the logged state, the corrected positions and velocities
// of the step (a variant's own forces come from the predicted state, so they differ by the corrector).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "demmat/variant.hpp"

namespace demmat {

// Steps between rows when --log is given without --log-every: a row costs a contact search (O(N)), so
// this keeps the log's cost to about one percent of the run.
inline constexpr std::int64_t kDefaultLogEvery = 100;

// `--log -`: the rows go to standard output. The log is a stream written in place (not renamed into
// place like the other outputs), so a pipe or a terminal is a fine log too.
inline const std::filesystem::path kStandardOutput = "-";

// One row of the log (columns in docs: see log_header).
struct LogRow {
    std::int64_t step = 0;
    double time = 0.0;                    // step·Δt, s
    double kinetic_translational = 0.0;   // Σ ½·m·v², J
    double kinetic_rotational = 0.0;      // Σ ½·I·ω², J
    double gravitational = 0.0;           // −Σ m·g·x, J (relative to the origin)
    double elastic = 0.0;                 // Σ (8/15)·E*·sqrt(R*)·h^(5/2) over pair and wall contacts, J
    std::int64_t contacts_particle = 0;   // particle pairs with h > 0
    std::int64_t contacts_wall = 0;       // particle–wall contacts with h > 0
    double largest_overlap_ratio = 0.0;   // max h / smaller radius (pairs) or h / radius (walls); 0 without contacts
    std::vector<Vec3d> wall_force;        // per wall, the scene's order: force of the particles on the wall, N

    double total() const { return kinetic_translational + kinetic_rotational + gravitational + elastic; }
};

// The row of a snapshot. A position that is not finite (or absurdly far) leaves the contacts uncounted
// and makes elastic, the overlap ratio and the wall forces NaN.
LogRow measure_log_row(const Snapshot& s, const Setup& setup);

// "step,time,…,wall0_fx,wall0_fy,wall0_fz,…" for `walls` walls, and one row in the same order (%.17g:
// every double reads back exactly). Neither ends in a newline.
std::string log_header(std::size_t walls);
std::string log_line(const LogRow& row);

// Refuses (Error, one line) a log path that cannot be written or would overwrite an input: an empty name, a folder,
// a file in a folder that does not exist or cannot be written, an unwritable file, or one of `inputs`
// (the scene file, the state file it reads). Called before the run starts.
void check_log_path(const std::filesystem::path& log, const std::vector<std::filesystem::path>& inputs);
// Refuses (Error, one line) --log-every below 1.
void check_log_every(std::int64_t every);

// The open log: the header at construction, then one row per write(), each handed to the system at
// once (one write call per row, so a reader watching the file sees whole rows, and a run that stops
// leaves every row it logged).
class RunLog {
public:
    RunLog(const std::filesystem::path& file, const Setup& setup, std::int64_t every);
    ~RunLog();
    RunLog(const RunLog&) = delete;
    RunLog& operator=(const RunLog&) = delete;

    // Whether step k of a run of `steps` is logged: every `every` steps and the last (step 0 is logged
    // by the caller before the run).
    bool due(std::int64_t k, std::int64_t steps) const { return k % every_ == 0 || k == steps; }
    void write(const Snapshot& s);

private:
    void append(const std::string& line);

    std::filesystem::path file_;
    const Setup& setup_;
    std::int64_t every_;
    int fd_ = -1;
    bool owned_ = true;  // false for standard output, which is not closed
};

} // namespace demmat
