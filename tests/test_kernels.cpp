// The shared kernels on problems with known answers: the Gear scheme (free fall, harmonic oscillator)
// and the contact law (hand-computed values; packed lanes against the scalar law, bit for bit).
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "demmat/contact_law.hpp"
#include "demmat/gear.hpp"
#include "support.hpp"

using namespace demmat;

namespace {

// One degree of freedom x'' = f(x, v) integrated by the shared kernels.
template <class F>
double integrate(double x0, double v0, double dt, std::int64_t steps, F accel)
{
    const auto k = GearCoefficients<double>::make(dt);
    double x = x0, v = v0, a = accel(x0, v0), b3 = 0, b4 = 0, b5 = 0;
    for (std::int64_t s = 0; s < steps; ++s) {
        gear_predict(x, v, a, b3, b4, b5, k);
        const double da = accel(x, v) - a;
        gear_correct(x, v, a, b3, b4, b5, da, k);
    }
    return x;
}

} // namespace

TEST(Gear, FreeFallIsExactUpToRounding)
{
    // A constant acceleration has b3 = b4 = b5 = 0 forever: the predictor is the exact Taylor polynomial.
    const double g = -10.0, dt = 1e-3;
    const std::int64_t n = 1000;
    const double x = integrate(2.0, 3.0, dt, n, [&](double, double) { return g; });
    const double t = double(n) * dt;
    EXPECT_NEAR(x, 2.0 + 3.0 * t + 0.5 * g * t * t, 1e-12);
}

TEST(Gear, HarmonicOscillatorConvergesAtTheExpectedOrder)
{
    // x'' = -ω² x, x(0) = 1, v(0) = 0; position error at t = 2 against cos(ωt) as Δt halves. The
    // 6-value Gear scheme converges at global order 4 in position on this problem (with c0 = 3/16 it
    // approaches 4 from above: 4.4, 4.2, 4.1 for ω·Δt from 0.03 to 0.004; with 3/20 from below). The
    // test asserts the observed order over three halvings, well clear of rounding (errors >= 1e-12).
    const double w = 2.0 * 3.14159265358979323846, tend = 2.0;
    auto err = [&](double dt) {
        const auto n = std::int64_t(std::llround(tend / dt));
        const double x = integrate(1.0, 0.0, dt, n, [&](double x, double) { return -w * w * x; });
        return std::abs(x - std::cos(w * tend));
    };
    double prev = err(5e-3);
    for (double dt : {2.5e-3, 1.25e-3, 6.25e-4}) {
        const double e = err(dt);
        const double order = std::log2(prev / e);
        EXPECT_GT(order, 3.9) << "dt " << dt;
        EXPECT_LT(order, 4.6) << "dt " << dt;
        prev = e;
    }
    EXPECT_LT(prev, 2e-12);
}

TEST(ContactLaw, HandComputedNormalDampedAndCoulombFriction)
{
    ContactParams<double> p{1.0, 1.0, 0.1, 0.2, 0.5};
    // Unit spheres of unit mass 1.9 apart along x: h = 0.1, n = x, R* = 0.5, m* = 0.5.
    ContactForce<double> c;
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.9, 0, 0}, Vec3d{1, 0.5, 0}, Vec3d{0, 0, 0}, Vec3d{}, Vec3d{},
                                            1.0, 1.0, 1.0, 1.0, p, c));
    const double fe = std::sqrt(0.5) * 0.1 * std::sqrt(0.1);  // (4/3)E* = 1
    const double fn = fe + 0.1 * 0.5 * 1.0;                    // + γn·m*·u_n, u_n = 1
    const double ft = std::min(0.5 * fn, 0.2 * 0.5 * 0.5);     // Coulomb limit 0.036 < viscous 0.05
    EXPECT_NEAR(c.overlap, 0.1, 1e-15);
    EXPECT_NEAR(c.f_i.x, -fn, 1e-15);
    EXPECT_NEAR(c.f_i.y, -ft, 1e-15);
    EXPECT_EQ(c.f_i.z, 0.0);
    EXPECT_NEAR(ft, 0.5 * fn, 1e-15);  // this configuration is in the Coulomb regime
    // Lever arms ±0.95 n; both torques are (0, 0, -0.95·ft).
    EXPECT_NEAR(c.t_i.z, -0.95 * ft, 1e-15);
    EXPECT_NEAR(c.t_j.z, -0.95 * ft, 1e-15);
    EXPECT_EQ(c.t_i.x, 0.0);
    EXPECT_EQ(c.t_i.y, 0.0);
}

TEST(ContactLaw, ViscousTangentialRegimeAndSpinContribution)
{
    ContactParams<double> p{1.0, 1.0, 0.0, 0.2, 10.0};
    ContactForce<double> c;
    // i spins about z at 1 rad/s: ω × d_i = (0, 0, 1) × (0.95, 0, 0) = (0, 0.95, 0) at the contact.
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.9, 0, 0}, Vec3d{}, Vec3d{}, Vec3d{0, 0, 1}, Vec3d{}, 1.0, 1.0,
                                            1.0, 1.0, p, c));
    EXPECT_NEAR(c.f_i.y, -0.2 * 0.5 * 0.95, 1e-15);  // viscous: γt·m*·|u_t| < μ·Fn
}

TEST(ContactLaw, NoAttractionAndNoContactWhenApart)
{
    ContactParams<double> p{1.0, 1.0, 100.0, 0.2, 0.5};
    ContactForce<double> c;
    // Separating fast: the damping term exceeds the elastic one, F_n is clipped to zero.
    ASSERT_TRUE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{1.99, 0, 0}, Vec3d{-1, 0.3, 0}, Vec3d{}, Vec3d{}, Vec3d{}, 1.0, 1.0,
                                            1.0, 1.0, p, c));
    EXPECT_EQ(c.f_i.x, 0.0);
    EXPECT_EQ(c.f_i.y, 0.0);
    EXPECT_FALSE(particle_contact<FullModel>(Vec3d{0, 0, 0}, Vec3d{2.0, 0, 0}, Vec3d{}, Vec3d{}, Vec3d{}, Vec3d{}, 1.0, 1.0, 1.0,
                                             1.0, p, c));
    EXPECT_TRUE(may_touch(Vec3d{0, 0, 0}, Vec3d{1.9999999, 0, 0}, 1.0, 1.0));
}

TEST(ContactLaw, WallUsesParticleRadiusAndMassAndWallVelocity)
{
    ContactParams<double> p{0.0, 2.0, 0.5, 0.0, 0.0};
    ContactForce<double> c;
    // Particle of radius 1, mass 2, centre 0.9 above a floor moving up at 1 m/s: h = 0.1, u_n = +1.
    ASSERT_TRUE(wall_contact<FullModel>(Vec3d{0, 0, 0.9}, Vec3d{}, Vec3d{}, 1.0, 2.0, Vec3d{0, 0, 0}, Vec3d{0, 0, 1},
                                        Vec3d{0, 0, 1}, p, c));
    const double fn = 2.0 * std::sqrt(1.0) * 0.1 * std::sqrt(0.1) + 0.5 * 2.0 * 1.0;
    EXPECT_NEAR(c.f_i.z, fn, 1e-15);  // pushes the particle up, into the domain
}

TEST(Material, EffectiveModulusAndRayleighTime)
{
    Scene s = paper_scene();
    const auto c = s.contact_params();
    const double estar = 0.3e6 / (2.0 * (1.0 - 0.09));
    EXPECT_NEAR(c.hertz_pp, 4.0 / 3.0 * estar, 1e-9);
    EXPECT_NEAR(c.hertz_pw, c.hertz_pp, 1e-9);  // choice: walls have the particles' material
    // T_R = π R sqrt(ρ/G) / (0.1631 ν + 0.8766) for R = 3 mm.
    EXPECT_NEAR(rayleigh_time(s.material, 0.003), 3.14159265358979 * 0.003 * std::sqrt(1000.0 / 0.11e6) / (0.1631 * 0.3 + 0.8766),
                1e-15);
}

namespace {

// Random pairs of every kind the law meets: overlapping and apart, approaching fast enough to be
// clipped, with no tangential motion (the select that avoids 0/0), sliding and sticking.
template <class T>
struct PairSample {
    Vec3<T> xi, xj, vi, vj, wi, wj;
    T ri, rj, mi, mj;
};

template <class T>
std::vector<PairSample<T>> pair_samples(std::size_t count)
{
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.5, 1.5);
    auto vec = [&](double s) { return Vec3<T>{T(s * u(rng)), T(s * u(rng)), T(s * u(rng))}; };
    std::vector<PairSample<T>> out;
    for (std::size_t k = 0; k < count; ++k) {
        PairSample<T> p;
        p.ri = T(1e-3 * pos(rng));
        p.rj = T(1e-3 * pos(rng));
        p.mi = T(1e-6 * pos(rng));
        p.mj = T(1e-6 * pos(rng));
        // Centre distance from 0.9 to 1.1 of R_i + R_j: about half the pairs overlap.
        const Vec3<T> dir = vec(1.0);
        const double len = std::sqrt(double(dot(dir, dir)));
        const double d = (double(p.ri) + double(p.rj)) * (0.9 + 0.2 * (u(rng) + 1.0) / 2.0);
        p.xi = vec(0.1);
        p.xj = p.xi + T(d / len) * dir;
        switch (k % 4) {
        case 0:  // no relative motion at all: u_t = 0
            p.vi = p.vj = vec(0.0);
            break;
        case 1:  // fast separation: the damping term clips F_n to zero
            p.vi = T(-50.0 / len) * dir;
            p.vj = T(50.0 / len) * dir;
            p.wi = vec(10.0);
            break;
        default:
            p.vi = vec(1.0);
            p.vj = vec(1.0);
            p.wi = vec(100.0);
            p.wj = vec(100.0);
        }
        out.push_back(p);
    }
    return out;
}

template <class T>
bool same_bits(T a, T b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }

// Runs the packed law on samples W at a time and checks every lane against the scalar law, bit for bit;
// lanes out of contact must hold +0.
template <class M, class T, int W>
void check_lanes_against_scalar()
{
    using V = Pack<T, W>;
    const ContactParams<T> p{T(4e5), T(6e5), T(60), T(60), T(0.6)};
    const auto samples = pair_samples<T>(64 * W);
    const Coefficients<T> mono = pair_coefficients(T(1e-3), T(1e-3), T(1e-6), T(1e-6), p);
    const Coefficients<V> mono_lanes{splat<V>(mono.kn), splat<V>(mono.cn), splat<V>(mono.ct)};
    int touching = 0, clipped = 0;
    for (std::size_t b = 0; b < samples.size(); b += W) {
        Vec3<V> xi, xj, vi, vj, wi, wj;
        V ri{}, rj{}, mi{}, mj{};
        for (int l = 0; l < W; ++l) {
            const PairSample<T>& s = samples[b + std::size_t(l)];
            for (int c = 0; c < 3; ++c) {
                component(xi, c)[l] = component(s.xi, c);
                component(xj, c)[l] = component(s.xj, c);
                component(vi, c)[l] = component(s.vi, c);
                component(vj, c)[l] = component(s.vj, c);
                component(wi, c)[l] = component(s.wi, c);
                component(wj, c)[l] = component(s.wj, c);
            }
            ri[l] = s.ri; rj[l] = s.rj; mi[l] = s.mi; mj[l] = s.mj;
        }
        ContactForce<V> lanes;
        const auto touch = particle_contact_lanes<M>(xi, xj, vi, vj, wi, wj, ri, rj, mi, mj, p, mono_lanes, lanes);
        for (int l = 0; l < W; ++l) {
            const PairSample<T>& s = samples[b + std::size_t(l)];
            ContactForce<T> one;
            const bool hit = particle_contact<M>(s.xi, s.xj, s.vi, s.vj, s.wi, s.wj, s.ri, s.rj, s.mi, s.mj, p, mono, one);
            ASSERT_EQ(hit, touch[l] != 0) << "pair " << b + std::size_t(l);
            if (!hit) one = ContactForce<T>{};
            touching += hit;
            clipped += hit && one.f_i.x == T(0) && one.f_i.y == T(0) && one.f_i.z == T(0);
            const Vec3<T>* want[3] = {&one.f_i, &one.t_i, &one.t_j};
            const Vec3<V>* got[3] = {&lanes.f_i, &lanes.t_i, &lanes.t_j};
            for (int q = 0; q < (M::rotation ? 3 : 1); ++q)
                for (int c = 0; c < 3; ++c)
                    ASSERT_TRUE(same_bits(component(*want[q], c), component(*got[q], c)[l]))
                        << "pair " << b + std::size_t(l) << ", quantity " << q << ", component " << c << ": scalar "
                        << component(*want[q], c) << ", lane " << component(*got[q], c)[l];
        }
    }
    // The samples must exercise what they are for.
    EXPECT_GT(touching, int(samples.size()) / 4);
    if constexpr (M::damping) {
        EXPECT_GT(clipped, 0);
    }
}

} // namespace

TEST(ContactLaw, EveryLaneOfAPackHasTheScalarLawsBits)
{
    check_lanes_against_scalar<FullModel, double, native_lanes<double>>();
    check_lanes_against_scalar<FullModel, float, native_lanes<float>>();
    check_lanes_against_scalar<Model<true, true, true, true, true, false>, double, native_lanes<double>>();  // monodisperse
    check_lanes_against_scalar<Model<false, false, false>, double, native_lanes<double>>();                 // normal force only
    check_lanes_against_scalar<Model<false, false, true>, double, native_lanes<double>>();                  // with damping
    // A pack wider than the machine's vectors (lowered to several) and the generic sqrt fallback.
    check_lanes_against_scalar<FullModel, double, 2 * native_lanes<double>>();
}

namespace {

// The particle–wall law on packs, lane by lane against the scalar law, bit for bit: random particles
// around random walls (each lane its own wall, as the fast variant packs them), half of them touching,
// moving walls, no tangential motion, fast separation (clipped), sliding and sticking.
template <class M, class T, int W>
void check_wall_lanes_against_scalar()
{
    using V = Pack<T, W>;
    const ContactParams<T> p{T(4e5), T(6e5), T(60), T(60), T(0.6)};
    const Coefficients<T> mono = wall_coefficients(T(1e-3), T(1e-6), p);
    const Coefficients<V> mono_lanes{splat<V>(mono.kn), splat<V>(mono.cn), splat<V>(mono.ct)};
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.5, 1.5);
    auto vec = [&](double s) { return Vec3<T>{T(s * u(rng)), T(s * u(rng)), T(s * u(rng))}; };
    int touching = 0, clipped = 0;
    for (int b = 0; b < 64; ++b) {
        Vec3<T> x[W], v[W], w[W], point[W], normal[W], vw[W];
        T r[W], m[W];
        Vec3<V> xl, vl, wl, pl, nl, vwl;
        V rl{}, ml{};
        for (int l = 0; l < W; ++l) {
            r[l] = T(1e-3 * pos(rng));
            m[l] = T(1e-6 * pos(rng));
            const Vec3<T> dir = vec(1.0);
            normal[l] = T(1.0 / std::sqrt(double(dot(dir, dir)))) * dir;
            point[l] = vec(0.1);
            // Distance to the plane from 0.9 to 1.1 of R: about half touch.
            const Vec3<T> along = vec(1e-3);  // an offset along the plane
            x[l] = point[l] + T(double(r[l]) * (1.0 + 0.1 * u(rng))) * normal[l] + (along - dot(along, normal[l]) * normal[l]);
            vw[l] = l % 2 ? vec(0.1) : Vec3<T>{};
            switch ((b * W + l) % 4) {
            case 0: v[l] = vw[l]; w[l] = {}; break;                      // no relative motion: u_t = 0
            case 1: v[l] = T(50) * normal[l]; w[l] = vec(10.0); break;  // leaving fast: F_n clipped to zero
            default: v[l] = vec(1.0); w[l] = vec(100.0);
            }
            for (int c = 0; c < 3; ++c) {
                component(xl, c)[l] = component(x[l], c);
                component(vl, c)[l] = component(v[l], c);
                component(wl, c)[l] = component(w[l], c);
                component(pl, c)[l] = component(point[l], c);
                component(nl, c)[l] = component(normal[l], c);
                component(vwl, c)[l] = component(vw[l], c);
            }
            rl[l] = r[l];
            ml[l] = m[l];
        }
        ContactForce<V> lanes;
        const auto touch = wall_contact_lanes<M>(xl, vl, wl, rl, ml, pl, nl, vwl, p, mono_lanes, lanes);
        for (int l = 0; l < W; ++l) {
            ContactForce<T> one;
            const bool hit = wall_contact<M>(x[l], v[l], w[l], r[l], m[l], point[l], normal[l], vw[l], p, mono, one);
            ASSERT_EQ(hit, touch[l] != 0) << "sample " << b << ", lane " << l;
            if (!hit) one = ContactForce<T>{};
            touching += hit;
            clipped += hit && one.f_i.x == T(0) && one.f_i.y == T(0) && one.f_i.z == T(0);
            const Vec3<T>* want[2] = {&one.f_i, &one.t_i};
            const Vec3<V>* got[2] = {&lanes.f_i, &lanes.t_i};
            for (int q = 0; q < (M::rotation ? 2 : 1); ++q)
                for (int c = 0; c < 3; ++c)
                    ASSERT_TRUE(same_bits(component(*want[q], c), component(*got[q], c)[l]))
                        << "sample " << b << ", lane " << l << ", quantity " << q << ", component " << c << ": scalar "
                        << component(*want[q], c) << ", lane " << component(*got[q], c)[l];
        }
    }
    EXPECT_GT(touching, 64 * W / 4);
    EXPECT_LT(touching, 64 * W * 3 / 4);
    if constexpr (M::damping) {
        EXPECT_GT(clipped, 0);
    }
}

} // namespace

TEST(ContactLaw, EveryLaneOfAWallPackHasTheScalarLawsBits)
{
    check_wall_lanes_against_scalar<FullModel, double, native_lanes<double>>();
    check_wall_lanes_against_scalar<FullModel, float, native_lanes<float>>();
    check_wall_lanes_against_scalar<Model<true, true, true, true, true, false>, double, native_lanes<double>>();  // monodisperse
    check_wall_lanes_against_scalar<Model<false, false, false>, double, native_lanes<double>>();                 // normal force only
    check_wall_lanes_against_scalar<FullModel, double, 2 * native_lanes<double>>();
}
