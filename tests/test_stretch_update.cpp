// The trapezoidal stretch update of physics.md §9 on one contact, by hand: a new contact's stretch is u_t·τ
// with τ = h/u_n the time since its onset within the step, the store keeps ζ = ξ + (Δt/2)·u_t, and the next
// evaluation's stretch is the trapezoidal rule ξ + (Δt/2)·(u_old + u_new). Its convergence and its error
// against an independent integration: tests/test_stretch_update.py (ctest analysis.stretch_update).
#include <gtest/gtest.h>

#include "demmat/contact_memory.hpp"
#include "demmat/error.hpp"
#include "demmat/model.hpp"
#include "demmat/scene_toml.hpp"

using namespace demmat;

namespace {

using History = Model<true, true, true, true, true, true, false, true, false>;  // linear_history, no rolling

struct OneWallContact {
    ContactParams<double> p{4e5, 6e5, 0.0, 0.0, 0.5};  // no damping: the tangential force is the spring's
    MemoryParams<double> q;
    OneWallContact(bool trapezoidal)
    {
        q.kt = 100.0;
        q.dt = 1e-5;
        q.trapezoidal = trapezoidal;
    }
    // A grain of radius 4 mm on the floor z = 0 with overlap h, moving with (ut, 0, -un): F_t's x component.
    double force_x(Stretch<double>& s, double h, double ut, double un) const
    {
        ContactForce<double> c;
        const bool hit = wall_contact_memory<History>(Vec3d{0.0, 0.0, 0.004 - h}, Vec3d{ut, 0.0, -un}, Vec3d{}, 0.004, 2.7e-4,
                                                       Vec3d{}, Vec3d{0.0, 0.0, 1.0}, Vec3d{}, p, q, s, true, c);
        EXPECT_TRUE(hit);
        return c.f_i.x;
    }
};

TEST(StretchUpdate, ANewContactStartsAtItsOnsetWithinTheStep)
{
    const double dt = 1e-5, un = 0.1, ut = 0.002, h = 0.3 * un * dt;  // the overlap began 0.3·Δt ago; it sticks
    OneWallContact trap(true), lammps(false);
    Stretch<double> s, s0;
    const double f = trap.force_x(s, h, ut, un);
    EXPECT_NEAR(f, -100.0 * ut * (h / un), 1e-15);
    EXPECT_NEAR(s.t.x, ut * (h / un) + 0.5 * dt * ut, 1e-18);  // ζ: half a step on
    EXPECT_NEAR(lammps.force_x(s0, h, ut, un), -100.0 * ut * dt, 1e-15);  // LAMMPS's: a whole step
    EXPECT_EQ(s0.t.x, ut * dt);
    // An overlap deeper than one step's approach is an older contact's: τ = Δt.
    Stretch<double> deep;
    EXPECT_NEAR(trap.force_x(deep, 3.0 * un * dt, ut, un), -100.0 * ut * dt, 1e-15);
}

TEST(StretchUpdate, AContinuingContactTakesTheTrapezoidalRule)
{
    const double dt = 1e-5, un = 0.1, h = 2.0 * un * dt;
    OneWallContact trap(true);
    Stretch<double> s;
    trap.force_x(s, h, 0.02, un);          // first evaluation, τ = Δt
    const double xi_old = 0.02 * dt;         // its stretch
    const double f = trap.force_x(s, h + un * dt, 0.05, un);  // u_t changes from 0.02 to 0.05
    EXPECT_NEAR(f, -100.0 * (xi_old + 0.5 * dt * (0.02 + 0.05)), 1e-15);
    EXPECT_NEAR(s.t.x, xi_old + 0.5 * dt * (0.02 + 0.05) + 0.5 * dt * 0.05, 1e-18);
}

TEST(StretchUpdate, ASlideSetsTheStretchBackAndStoresItHalfAStepOn)
{
    const double dt = 1e-5, un = 0.1, ut = 50.0, h = 2.0 * un * dt;  // u_t·Δt·k_t far above μ·F_n
    OneWallContact trap(true);
    Stretch<double> s;
    const double f = trap.force_x(s, h, ut, un);
    const double cap = 0.5 * 6e5 * std::sqrt(0.004) * h * std::sqrt(h);
    EXPECT_NEAR(f, -cap, 1e-12 * cap);
    EXPECT_NEAR(s.t.x, cap / 100.0 + 0.5 * dt * ut, 1e-15);
}

TEST(StretchUpdate, TheKeyIsReadWrittenAndFingerprinted)
{
    ContactModel m;
    m.tangential = TangentialModel::mindlin;
    const auto before = m.fingerprint_values();
    EXPECT_EQ(m.toml().find("stretch_update"), std::string::npos);  // the default is not written: old scenes as they were
    m.stretch_update = StretchUpdate::trapezoidal;
    EXPECT_NE(m.fingerprint_values(), before);
    EXPECT_NE(m.toml().find("stretch_update = \"trapezoidal\""), std::string::npos);
    EXPECT_NE(m.describe().find("stretch update trapezoidal"), std::string::npos);
    EXPECT_THROW(contact_model_from_options({"stretch_update=trapezoidal"}), Error);  // no spring, no stretch to update
    EXPECT_EQ(contact_model_from_options({"tangential=mindlin", "tangential_damping_ratio=0", "stretch_update=trapezoidal"}).stretch_update,
              StretchUpdate::trapezoidal);
    EXPECT_THROW(contact_model_from_options({"tangential=mindlin", "tangential_damping_ratio=0", "stretch_update=midpoint"}), Error);
}

} // namespace
