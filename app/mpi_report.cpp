#include "mpi_report.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace demmat::mpi {

Counters snapshot_counters(const MpiVariant& v, const Driver& d) { return {d.times(), v.local_report()}; }

double RunReport::total() const
{
    double t = 0.0;
    for (const RankShare& s : ranks) t = std::max(t, s.total());
    return t;
}

RunReport gather_report(const MpiVariant& v, const Driver& d, std::int64_t steps, const Counters* before)
{
    const Counters now = snapshot_counters(v, d);
    const Counters zero{};
    const Counters& b = before ? *before : zero;
    const PhaseTimes t = (now.times - b.times).per_step(steps);
    const double k = steps > 0 ? 1.0 / double(steps) : 0.0;
    const double comm = (now.report.traffic.seconds - b.report.traffic.seconds) * k;
    const RankReport& r = now.report;
    const std::vector<double> mine = {double(r.rank), double(r.owned), double(r.ghosts), double(r.owned_max), double(steps),
                                      double(r.migrants - b.report.migrants), double(r.rebuilds - b.report.rebuilds),
                                      double(r.traffic.messages - b.report.traffic.messages),
                                      double(r.traffic.bytes - b.report.traffic.bytes), comm, t.predict, t.search - comm, t.forces, t.correct};
    const std::vector<double> all = v.comm().gather(mine);
    RunReport out;
    out.steps = steps;
    const std::size_t w = mine.size();
    for (std::size_t i = 0; i + w <= all.size(); i += w) {
        const double* q = &all[i];
        RankShare s;
        s.report = {int(q[0]), std::int64_t(q[1]), std::int64_t(q[2]), std::int64_t(q[3]), std::int64_t(q[4]), std::int64_t(q[5]),
                    std::int64_t(q[6]), Traffic{std::int64_t(q[7]), std::int64_t(q[8]), q[9]}};
        s.communicate = q[9];
        s.per_step = {q[10], q[11], q[12], q[13]};
        out.ranks.push_back(s);
    }
    return out;
}

RunReport median_report(std::vector<RunReport> reps)
{
    std::sort(reps.begin(), reps.end(), [](const RunReport& a, const RunReport& b) { return a.total() < b.total(); });
    return reps[reps.size() / 2];
}

namespace {
struct Spread {
    double mean = 0.0, max = 0.0;
};
template <class F>
Spread spread(const RunReport& r, F&& f)
{
    Spread s;
    for (const RankShare& q : r.ranks) {
        const double x = f(q);
        s.mean += x;
        s.max = std::max(s.max, x);
    }
    if (!r.ranks.empty()) s.mean /= double(r.ranks.size());
    return s;
}
double per_step(const RankShare& q, std::int64_t v) { return q.report.steps > 0 ? double(v) / double(q.report.steps) : 0.0; }
} // namespace

void print_report(std::ostream& out, const RunReport& r, double particles)
{
    auto slowest = [&](auto f) { return spread(r, f).max; };
    const double total = r.total();
    out << fmt::format("steps per second {:.1f}  ({:.4f} us per particle-step)\n", 1.0 / total, total / particles * 1e6);
    out << fmt::format("per step (the slowest rank in each): predict {:.3e} s  communicate {:.3e} s  search {:.3e} s  forces {:.3e} s  "
                       "correct {:.3e} s  total {:.3e} s\n",
                       slowest([](const RankShare& q) { return q.per_step.predict; }), slowest([](const RankShare& q) { return q.communicate; }),
                       slowest([](const RankShare& q) { return q.per_step.search; }), slowest([](const RankShare& q) { return q.per_step.forces; }),
                       slowest([](const RankShare& q) { return q.per_step.correct; }), total);
    const Spread owned = spread(r, [](const RankShare& q) { return double(q.report.owned); });
    const Spread most = spread(r, [](const RankShare& q) { return double(q.report.owned_max); });
    const Spread ghosts = spread(r, [](const RankShare& q) { return double(q.report.ghosts); });
    out << fmt::format("particles per rank max {:.0f} mean {:.1f} (imbalance max/mean {:.3f}; the most a rank held {:.0f})  ghosts per rank "
                       "max {:.0f} mean {:.1f}\n",
                       owned.max, owned.mean, owned.mean > 0 ? owned.max / owned.mean : 0.0, most.max, ghosts.max, ghosts.mean);
    const Spread msg = spread(r, [](const RankShare& q) { return per_step(q, q.report.traffic.messages); });
    const Spread bytes = spread(r, [](const RankShare& q) { return per_step(q, q.report.traffic.bytes); });
    const Spread mig = spread(r, [](const RankShare& q) { return per_step(q, q.report.migrants); });
    const double rebuilds = r.ranks.empty() ? 0.0 : per_step(r.ranks[0], r.ranks[0].report.rebuilds);
    out << fmt::format("halo per step per rank (ghosts and migrants sent): messages mean {:.2f} max {:.2f}  bytes mean {:.0f} max {:.0f}  "
                       "migrants mean {:.3f}  (neighbour list rebuilt at {:.3f} of the steps)\n", msg.mean, msg.max, bytes.mean, bytes.max,
                       mig.mean, rebuilds);
}

nlohmann::json report_json(const RunReport& r, const MpiVariant& v)
{
    nlohmann::json ranks = nlohmann::json::array();
    for (const RankShare& q : r.ranks)
        ranks.push_back({{"rank", q.report.rank},
                         {"particles", q.report.owned},
                         {"particles_most", q.report.owned_max},
                         {"ghosts", q.report.ghosts},
                         {"messages_per_step", per_step(q, q.report.traffic.messages)},
                         {"bytes_per_step", per_step(q, q.report.traffic.bytes)},
                         {"migrants_per_step", per_step(q, q.report.migrants)},
                         {"rebuilds_per_step", per_step(q, q.report.rebuilds)},
                         {"seconds_per_step", {{"predict", q.per_step.predict}, {"communicate", q.communicate}, {"search", q.per_step.search},
                                               {"forces", q.per_step.forces}, {"correct", q.per_step.correct}, {"total", q.total()}}}});
    const Bricks& b = v.bricks();
    nlohmann::json cuts;
    for (std::size_t a = 0; a < 3; ++a)  // the interior planes (the ends are infinite)
        cuts[std::string(1, "xyz"[a])] = std::vector<double>(b.cuts[a].begin() + 1, b.cuts[a].end() - 1);
    return {{"processes", r.ranks.size()}, {"grid", b.grid()}, {"cuts", cuts}, {"face_area_m2", b.shared_area_per_rank()},
            {"halo_m", v.halo()}, {"steps", r.steps},
            {"seconds_per_step_slowest_rank", r.total()}, {"ranks", ranks}};
}

} // namespace demmat::mpi
