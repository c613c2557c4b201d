#pragma once
// The benchmark tests of Chung & Ooi, "Benchmark tests for verifying discrete element modelling codes at
// particle impact level", Granular Matter 13 (2011) 643–656, tests 1–8, as scenes the suite writes
// (`demmat scene chung-ooi --test K`, the validation study and the ctests all build them here), and the one
// measurement of a two-body impact they are judged on. Where each number comes from: docs/validation.md.
#include <string>
#include <vector>

#include "demmat/integrators.hpp"
#include "demmat/problem.hpp"
#include "demmat/scene.hpp"

namespace demmat {

struct ChungOoiMaterial {
    std::string name;
    double young, poisson, density;  // Pa, –, kg/m³
};

// What the test varies, one run per value: nothing, the named restitution e, the incident angle (degrees,
// constant speed), the tangential speed (m/s, constant normal speed) or the initial spin (rad/s).
enum class ChungOoiSweep { none, restitution, angle, tangential_speed, spin };

struct ChungOoiTest {
    int number;
    std::string title;
    ChungOoiSweep sweep;
    std::vector<ChungOoiMaterial> materials;
    double radius, radius2;  // m; radius2 is the second sphere's (pair tests), 0 for a sphere on the rigid plane
    double speed;            // m/s: each sphere's (tests 1, 7), the mover's (8), towards the plane (2, 3, 5, 6), resultant (4)
    double mu, restitution;  // friction and the named e of the damped tests (test 3 sweeps e)
    std::vector<double> values;      // the sweep
    std::vector<std::string> laws;   // the laws that apply: paper, restitution, linear_history, mindlin
    bool wall() const { return radius2 == 0.0; }
};

const std::vector<ChungOoiTest>& chung_ooi_tests();
const ChungOoiTest& chung_ooi_test(int number);  // Error naming the tests for any other number
const ChungOoiMaterial& chung_ooi_material(const ChungOoiTest& test, const std::string& name);  // "" = the first
const char* name(ChungOoiSweep s);

// One run: a test, a material, one value of its sweep, a law and Δt = t_c / per_tc (t_c: Hertz's contact
// time at this run's normal speed), with an integrator.
struct ChungOoiCase {
    int test = 1;
    std::string material;  // "" = the test's first
    double value = 0.0;    // ignored by test 1 and 2
    std::string law = "paper";
    double per_tc = 200.0;
    IntegratorChoice integrator;
    StretchUpdate stretch_update = StretchUpdate::first_order;  // the history laws' (physics.md §9)
};

// The case's constants as the scene uses them (also what the study writes beside its measures).
struct ChungOoiSetup {
    double mstar, rstar, estar;  // kg, m, Pa (a rigid plane adds nothing to E*)
    double normal_speed;         // m/s, relative, at impact
    double tangential_slip;      // m/s, initial relative tangential velocity of the contact points
    double contact_time;         // s, Hertz's exact t_c at normal_speed (elastic)
    double peak_overlap;         // m, Hertz's δ_max at normal_speed (elastic)
};
ChungOoiSetup chung_ooi_setup(const ChungOoiCase& c);
Scene chung_ooi_scene(const ChungOoiCase& c);

// Hertz's closed forms for an elastic normal impact at relative speed v (Johnson, Contact Mechanics §11.4),
// beside δ_max = hertz_max_overlap (stability.hpp): F_max = (4/3)E*·sqrt(R*)·δ_max^(3/2) and
// t_c = 2·(δ_max/v)·∫₀¹(1 − x^(5/2))^(−1/2)dx = 3.2145…·δ_max/v.
double hertz_peak_force(double mstar, double rstar, double estar, double v);
double hertz_exact_contact_time(double mstar, double rstar, double estar, double v);

// What an impact is judged on, measured from a run sampled every step (no gravity, so flight is straight):
// contact start and end from the free flights before and after (exact lines through the first and the
// last sample), peak overlap and force from a parabola through the three samples about the largest.
struct ImpactSample {
    double t, overlap, normal_force;
};
struct ImpactResult {
    bool separated = false;
    std::int64_t steps = 0;
    double contact_time = 0, peak_overlap = 0, peak_force = 0, normal_restitution = 0;
    Vec3d v1, w1, v2, w2;  // final velocities and spins (the second body's are zero for the plane)
    std::vector<ImpactSample> curve;  // every step in contact and one either side, when asked for
};
// Runs `variant` on the problem until the bodies have separated (or `max_contact_times` Hertz times).
ImpactResult run_impact(Variant& variant, const Problem& problem, bool keep_curve, double max_contact_times = 20.0);

} // namespace demmat
