#pragma once
// Time scales and energy bookkeeping for numerical stability (docs/stability.md): the Hertz contact
// time of physics.md §8 at the scene's largest impact speed, the time-step check that `demmat run`
// makes before starting, and the mechanical energy the driver's energy-growth check bounds.
#include <string>
#include <vector>

#include "demmat/integrators.hpp"
#include "demmat/scene.hpp"
#include "demmat/state.hpp"
#include "demmat/vec3.hpp"

namespace demmat {

// Undamped Hertz contact, head-on at relative normal speed v (physics.md §8): maximum overlap and
// contact time t_c = 2.87·(m*²/(R*·E*²·v))^(1/5).
double hertz_max_overlap(double mstar, double rstar, double estar, double speed);
double hertz_contact_time(double mstar, double rstar, double estar, double speed);

// The fastest a grain can move by what the scene explains, v_p = fastest initial grain + a free fall
// across the domain's diagonal + the fastest wall (the driver's speed check allows ten times it).
double explained_speed(const Scene& scene, const State& state);
double fastest_wall_speed(const State& state);

// The largest impact speed a scene can explain (docs/stability.md): two grains can meet head-on at 2·v_p,
// a single grain meets a wall at v_p + the fastest wall.
double impact_speed_bound(const Scene& scene, const State& state);

// The shortest Hertz contact time of the scene at `speed`: the pair of two smallest grains, and (with
// walls) the smallest grain against a wall, whichever is shorter.
struct ContactTime {
    double tc = 0.0;      // s
    double speed = 0.0;   // m/s, the impact speed it was computed at
    bool wall = false;    // true when the particle–wall contact is the shorter one
};
ContactTime shortest_contact_time(const Scene& scene, const State& state, double speed);

// The largest Δt/t_c at which the integrator stayed stable in every two-body case of the stability study
// (results/stability/, docs/stability.md), rounded down: above it `demmat run` refuses the scene.
double stable_fraction_of_contact_time(Integrator scheme);
// Above this Δt/t_c (fewer than 20 steps per contact) `demmat run` warns: the restitution is then off
// by more than about 1 % for the paper's Gear scheme (docs/stability.md).
inline constexpr double kWarnFractionOfContactTime = 0.05;

// The smallest Δt a run in precision p can take: the Gear values hold Δt²/2·a, which must stay a normal
// number, so Δt >= sqrt(2·smallest normal), rounded up (below it the scaled accelerations underflow to
// zero and the run turns to NaN at its second step).
inline double min_time_step(Precision p) { return p == Precision::float64 ? 2.2e-154 : 1.7e-19; }

// Refuses (throws Error, one line) a scene whose numbers, each in range, make quantities a double cannot
// hold: a Δt below min_time_step, a grain's mass or moment of inertia that underflows, a contact
// stiffness, Rayleigh time, impact speed or Hertz contact time that overflows or underflows. Such a
// run would end as "unstable" (exit 3) rather than as the bad input it is. check_time_step calls it;
// a run with --allow-unstable calls it alone.
void check_magnitudes(const Scene& scene, const State& state);

// A warning (empty if none) when a scene that continues a saved state gives a wall the state knows another
// plane than the state has it at its step: a continued wall stands where the state left it (continue_walls),
// so an edit of its point or normal in the scene file is not applied, and the user is told so.
std::string check_continued_walls(const Scene& scene, const State& state);

// Refuses a time step above the Rayleigh time of the smallest particle (a scene that cannot be stable)
// and returns a warning (empty if none) when Δt exceeds 0.2 of it, the usual rule of thumb; likewise for
// the Hertz contact time at the scene's largest impact speed (check_contact_time_step, below).
std::string check_time_step(const Scene& scene, const State& state);

// Refuses (throws Error, one line) a Δt above the scene's integrator's stability limit in units of the
// shortest contact time at the largest impact speed; returns a warning (empty if none) above
// kWarnFractionOfContactTime of it.
std::string check_contact_time_step(const Scene& scene, const State& state);

// Elastic energy stored in the Hertz contacts at positions x: (8/15)·E*·sqrt(R*)·h^(5/2) per contact
// (physics.md §8), particle pairs and particle–wall contacts (walls at `step`).
double elastic_energy(const std::vector<Vec3d>& x, const std::vector<double>& radius, const std::vector<Wall>& walls,
                      std::int64_t step, double dt, const ContactParams<double>& params);

// The energy-growth check (docs/stability.md): kinetic + elastic energy may not exceed what the grains
// held at the start plus the work gravity has done since, Σ m_i·g·(x_i − x_i(0)), by more than this
// fraction of (start energy + |work of gravity|) plus a floor. Walls that move are exempt (their work is
// not tracked); the speed bound still applies.
inline constexpr double kEnergyGrowthTolerance = 0.05;

} // namespace demmat
