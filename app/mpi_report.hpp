#pragma once
// What demmat_mpi reports of a run: the per-step phase times of every rank with `communicate` (the
// exchanges with the neighbours, timed inside the search phase and taken out of it), the particles and
// ghosts per rank, and the halo traffic per step per rank (messages and bytes sent, migrants and ghosts).
#include <cstdint>
#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "mpi_variant.hpp"
#include "demmat/driver.hpp"

namespace demmat::mpi {

// This rank's cumulative counters, to subtract a warm-up from a measurement.
struct Counters {
    PhaseTimes times;
    RankReport report;
};
Counters snapshot_counters(const MpiVariant& v, const Driver& d);

struct RankShare {
    RankReport report;       // at the end (owned, ghosts), and over the measured steps (traffic, migrants)
    PhaseTimes per_step;     // search without communicate
    double communicate = 0.0;  // seconds per step
    double total() const { return per_step.total() + communicate; }
};

struct RunReport {
    std::int64_t steps = 0;
    std::vector<RankShare> ranks;  // rank 0 only
    // The slowest rank's seconds per step (the ranks wait for each other at every exchange).
    double total() const;
};

// Collective: every rank's share of the last `steps` steps (since `before`, if given); rank 0 gets them.
RunReport gather_report(const MpiVariant& v, const Driver& d, std::int64_t steps, const Counters* before = nullptr);
// The repetition whose total is the median.
RunReport median_report(std::vector<RunReport> reps);
void print_report(std::ostream& out, const RunReport& r, double particles);
nlohmann::json report_json(const RunReport& r, const MpiVariant& v);

} // namespace demmat::mpi
