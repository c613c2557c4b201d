// The rule for negligible derivatives (physics.md §3): after the corrector, each of a, b3, b4, b5 whose
// magnitude is below the bound (2^-900 in double, 2^-100 in float) is set to +0.
//
// A grain in free flight (no contact, no gravity) that carries nonzero scaled derivatives, as a grain
// leaving a contact does. With a_c = 0 the predictor–corrector acts on (b3, b4, b5) as a 3×3 matrix whose
// cube is exactly zero (checked below in rationals), so three steps would clear them in exact arithmetic;
// in floating point each three steps leave only a rounding residue, about ε of what was there, and the
// values fall through the subnormal numbers, where some stay (a residue of a denormal can be a fixed point).
// The reference here integrates one component as physics.md §3 writes the scheme, without the rule, and
// shows that; every registered variant must match it bit for bit while the rule has nothing to do, and
// end with every a, b3, b4, b5 exactly +0.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>

#include <gtest/gtest.h>

#include "demmat/integrators.hpp"
#include "support.hpp"

using namespace demmat;
using namespace demmat::test;

namespace {

constexpr std::int64_t kSteps = 150;

// One grain, moving and spinning in empty space, with the scaled derivatives of a grain that has just
// left a contact (b3 ≈ Δt³/6·jerk for a Hertz impact at 1 m/s, Δt = 1e-5 s, and smaller b4, b5).
State free_flight_state(const Scene& s)
{
    Problem base(s);
    State st = base.state();
    st.trans.v[0] = {0.3, -0.2, 0.1};
    st.trans.b3[0] = {1.1e-9, -2.3e-9, 3.7e-10};
    st.trans.b4[0] = {-3.1e-10, 5.3e-11, 1.9e-10};
    st.trans.b5[0] = {7.3e-11, -1.7e-11, 2.9e-11};
    st.rot.v[0] = {5.0, -3.0, 2.0};
    st.rot.b3[0] = {2.3e-7, 1.3e-7, -4.1e-8};
    st.rot.b4[0] = {-6.7e-8, 2.1e-8, 1.1e-8};
    st.rot.b5[0] = {1.3e-8, -3.3e-9, 4.7e-9};
    return st;
}

Scene free_flight_scene(IntegratorChoice choice = {})
{
    Scene s = drop_scene(0.05, 0.004);
    s.walls.clear();
    s.gravity = {0.0, 0.0, 0.0};
    s.integrator = choice;
    return s;
}

// The six values of one component, stepped as physics.md §3 writes the scheme with a_c = 0 (no force,
// no gravity), without the rule; T is the precision. Coefficients as §3 defines them, in double.
template <class T>
struct Reference {
    T x, v, a, b3, b4, b5;
    void step(double dt)
    {
        const double h2 = dt * dt / 2.0;
        const T kdt = T(dt), kh2 = T(h2), k2 = T(2.0 / (dt * dt)), cx = T(3.0 / 16.0 * h2), cv = T(251.0 / 360.0 * (dt / 2.0)),
                c3 = T(11.0 / 18.0 * h2), c4 = T(1.0 / 6.0 * h2), c5 = T(1.0 / 60.0 * h2);
        x = x + kdt * v + kh2 * a + b3 + b4 + b5;
        v = v + kdt * a + (T(3) * b3 + T(4) * b4 + T(5) * b5) / kdt;
        a = a + k2 * (T(3) * b3 + T(6) * b4 + T(10) * b5);
        b3 = b3 + T(4) * b4 + T(10) * b5;
        b4 = b4 + T(5) * b5;
        const T da = T(0) - a;
        x = x + cx * da;
        v = v + cv * da;
        a = a + da;
        b3 = b3 + c3 * da;
        b4 = b4 + c4 * da;
        b5 = b5 + c5 * da;
    }
    T largest() const { return std::max({std::abs(a), std::abs(b3), std::abs(b4), std::abs(b5)}); }
};

template <class T>
bool is_positive_zero(T u)
{
    return u == T(0) && !std::signbit(u);
}

// True while the rule would leave these values alone: each is +0 or at least the bound in magnitude.
template <class T>
bool rule_idle(const Reference<T>& r, T bound)
{
    for (T u : {r.a, r.b3, r.b4, r.b5})
        if (!(is_positive_zero(u) || !(std::abs(u) < bound))) return false;
    return true;
}

template <class T>
bool any_subnormal(const Reference<T>& r)
{
    for (T u : {r.a, r.b3, r.b4, r.b5})
        if (std::fpclassify(u) == FP_SUBNORMAL) return true;
    return false;
}

// The six components (translation x, y, z, rotation x, y, z) of a state as references.
template <class T>
std::vector<Reference<T>> components(const State& st)
{
    std::vector<Reference<T>> out;
    for (const GearState* g : {&st.trans, &st.rot})
        for (int c = 0; c < 3; ++c)
            out.push_back({T(component(g->x[0], c)), T(component(g->v[0], c)), T(component(g->a[0], c)), T(component(g->b3[0], c)),
                           T(component(g->b4[0], c)), T(component(g->b5[0], c))});
    return out;
}

std::vector<Reference<double>> saved_components(const Variant& v)
{
    State st;
    v.save(st);
    return components<double>(st);
}

bool same_bits(double p, double q) { return std::memcmp(&p, &q, sizeof p) == 0; }

} // namespace

// The decay the test relies on, in exact arithmetic: the free-flight map of (b3, b4, b5) after one
// predict–correct (a_c = 0 leaves a = 0 after each correction) is nilpotent of index 3.
TEST(NegligibleDerivatives, FreeFlightMapOfTheGearScaledDerivativesIsNilpotent)
{
    // Rows: b3' = b3p − (11/18)·e, b4' = b4p − (1/6)·e, b5' = b5p − (1/60)·e, e = 3b3 + 6b4 + 10b5 (the
    // predicted a in units of 2/Δt²), in 3600ths so that the products stay integers.
    const std::int64_t m[3][3] = {{-3000, 1200, 14000}, {-1800, 0, 12000}, {-180, -360, 3000}};
    std::int64_t m2[3][3] = {}, m3[3][3] = {};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) m2[i][j] += m[i][k] * m[k][j];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            for (int k = 0; k < 3; ++k) m3[i][j] += m2[i][k] * m[k][j];
            EXPECT_EQ(m3[i][j], 0) << i << "," << j;
        }
    // and the map really is the scheme: one step of the reference from (b3, b4, b5) = (1, 0, 0)·2^-20
    Reference<double> r{0, 0, 0, 0x1p-20, 0, 0};
    r.step(1e-5);
    EXPECT_NEAR(r.b3, -3000.0 / 3600.0 * 0x1p-20, 1e-12 * 0x1p-20);
    EXPECT_NEAR(r.b4, -1800.0 / 3600.0 * 0x1p-20, 1e-12 * 0x1p-20);
    EXPECT_NEAR(r.b5, -180.0 / 3600.0 * 0x1p-20, 1e-12 * 0x1p-20);
}

TEST(NegligibleDerivatives, BoundsAndTheSelect)
{
    EXPECT_EQ(negligible_derivative<double>(), std::ldexp(1.0, -900));
    EXPECT_EQ(negligible_derivative<float>(), std::ldexp(1.0f, -100));
    EXPECT_GT(negligible_derivative<double>(), std::numeric_limits<double>::min());
    EXPECT_GT(negligible_derivative<float>(), std::numeric_limits<float>::min());
    auto check = [](auto bound) {
        using T = decltype(bound);
        const T below = std::nextafter(bound, T(0));
        for (T u : {below, -below, T(-0.0), std::numeric_limits<T>::denorm_min(), -std::numeric_limits<T>::denorm_min()}) {
            T w = u;
            zero_if_negligible(w);
            EXPECT_TRUE(is_positive_zero(w)) << u;
        }
        for (T u : {bound, -bound, T(1), std::numeric_limits<T>::infinity(), -std::numeric_limits<T>::infinity()}) {
            T w = u;
            zero_if_negligible(w);
            EXPECT_TRUE(same_bits(double(w), double(u))) << u;
        }
        T n = std::numeric_limits<T>::quiet_NaN();
        zero_if_negligible(n);
        EXPECT_TRUE(std::isnan(n));
    };
    check(negligible_derivative<double>());
    check(negligible_derivative<float>());
}

// Every scheme applies the rule to the derivatives it carries: a subnormal new acceleration is stored as
// +0 (every scheme carries a), and gear5 and gear3 clear b3 (and b4, b5) that fall below the bound.
TEST(NegligibleDerivatives, EverySchemeClearsWhatItCarries)
{
    auto check = [](auto scheme, auto zero) {
        using S = decltype(scheme);
        using T = decltype(zero);
        const auto k = S::template Coefficients<T>::make(1e-5);
        const T tiny = std::numeric_limits<T>::denorm_min() * T(3);
        T x = 1, v = 1, a = tiny, b3 = tiny, b4 = tiny, b5 = tiny;
        S::correct(x, v, a, b3, b4, b5, tiny, k);
        EXPECT_TRUE(is_positive_zero(a)) << name(S::id) << " " << a;
        if constexpr (S::id == Integrator::gear5 || S::id == Integrator::gear3) {
            EXPECT_TRUE(is_positive_zero(b3)) << name(S::id);
        }
        if constexpr (S::id == Integrator::gear5) {
            EXPECT_TRUE(is_positive_zero(b4) && is_positive_zero(b5));
        }
        // a value at the bound is kept
        const T bound = negligible_derivative<T>();
        a = bound;
        S::correct(x, v, a, b3, b4, b5, bound, k);
        EXPECT_EQ(a, bound) << name(S::id);
    };
    for (Integrator id : all_integrators)
        with_scheme(id, [&](auto s) {
            check(s, 0.0);
            check(s, 0.0f);
        });
}

class NegligibleDerivativesIn : public ::testing::TestWithParam<std::string> {};

// Without the rule (the reference) the derivatives pass through the subnormals and some stay there;
// every variant matches the reference bit for bit while the rule has nothing to do, never holds a
// subnormal, and ends with every a, b3, b4, b5 exactly +0.
TEST_P(NegligibleDerivativesIn, FreeFlightDerivativesEndAtPositiveZero)
{
    const Scene scene = free_flight_scene();
    Problem p(scene, free_flight_state(scene));
    std::vector<Reference<double>> ref = components<double>(p.state());
    const double bound = negligible_derivative<double>();

    VariantRun run(GetParam(), p.setup());
    std::vector<bool> idle(ref.size(), true);
    std::vector<std::vector<double>> largest(ref.size());
    std::vector<bool> passed(ref.size(), false);  // the reference held a subnormal at some step
    for (std::int64_t k = 1; k <= kSteps; ++k) {
        run.driver->step();
        const std::vector<Reference<double>> got = saved_components(*run.variant);
        for (std::size_t c = 0; c < ref.size(); ++c) {
            EXPECT_FALSE(any_subnormal(got[c])) << GetParam() << " component " << c << " step " << k << " holds a subnormal";
            largest[c].push_back(ref[c].largest());
            ref[c].step(scene.dt);
            passed[c] = passed[c] || any_subnormal(ref[c]);
            idle[c] = idle[c] && rule_idle(ref[c], bound);
            if (!idle[c]) continue;
            // the decay (M³ = 0): three steps leave at most a rounding residue of what was there
            if (k > 3) {
                EXPECT_LE(ref[c].largest(), 0x1p-40 * largest[c][std::size_t(k - 3)]) << "component " << c << " step " << k;
            }
            for (auto q : {&Reference<double>::x, &Reference<double>::v, &Reference<double>::a, &Reference<double>::b3, &Reference<double>::b4,
                           &Reference<double>::b5})
                ASSERT_TRUE(same_bits(got[c].*q, ref[c].*q)) << GetParam() << " component " << c << " step " << k << ": "
                                                             << got[c].*q << " against the reference " << ref[c].*q;
        }
    }
    // Without the rule: most components pass through the subnormals, and several end there for good
    // (a residue of a denormal or two that the scheme carries on): for these start values, 5 and 4 of the
    // six components (translation and rotation, x, y, z).
    int through = 0, stuck = 0;
    for (std::size_t c = 0; c < ref.size(); ++c) {
        EXPECT_LT(ref[c].largest(), bound) << "component " << c;
        through += passed[c];
        stuck += any_subnormal(ref[c]);
    }
    EXPECT_GE(through, 5) << "without the rule most derivatives should pass through the subnormals";
    EXPECT_GE(stuck, 4) << "without the rule some derivatives should end subnormal";
    const std::vector<Reference<double>> got = saved_components(*run.variant);
    for (std::size_t c = 0; c < got.size(); ++c)
        for (double u : {got[c].a, got[c].b3, got[c].b4, got[c].b5})
            EXPECT_TRUE(is_positive_zero(u)) << GetParam() << " component " << c << ": " << u;
}

INSTANTIATE_TEST_SUITE_P(AllVariants, NegligibleDerivativesIn, ::testing::ValuesIn(variant_names()),
                         [](const auto& info) { return param_name(info.param); });

// The other schemes and float, which only arrays runs: the carried derivatives end at +0; for gear5 in
// float the reference in float shows that without the rule they would have passed through the subnormals.
TEST(NegligibleDerivatives, ArraysEveryIntegratorAndPrecisionEndsAtPositiveZero)
{
    for (Integrator id : all_integrators)
        for (Precision prec : all_precisions) {
            const Scene scene = free_flight_scene({id, prec});
            Problem p(scene, free_flight_state(scene));
            VariantRun run("arrays", p.setup());
            run.driver->run(kSteps);
            const std::vector<Reference<double>> start = components<double>(p.state());
            const std::vector<Reference<double>> got = saved_components(*run.variant);
            for (std::size_t c = 0; c < got.size(); ++c) {
                // gear5 carries a, b3, b4, b5; gear3 a, b3; verlet and symplectic_euler a. The others stay.
                const bool b3 = id == Integrator::gear5 || id == Integrator::gear3, b45 = id == Integrator::gear5;
                auto kept = [&](double u) { return prec == Precision::float32 ? double(float(u)) : u; };
                EXPECT_TRUE(is_positive_zero(got[c].a)) << name(id) << " in " << name(prec) << " component " << c;
                EXPECT_TRUE(b3 ? is_positive_zero(got[c].b3) : got[c].b3 == kept(start[c].b3)) << name(id) << " in " << name(prec);
                EXPECT_TRUE(b45 ? is_positive_zero(got[c].b4) : got[c].b4 == kept(start[c].b4)) << name(id) << " in " << name(prec);
                EXPECT_TRUE(b45 ? is_positive_zero(got[c].b5) : got[c].b5 == kept(start[c].b5)) << name(id) << " in " << name(prec);
            }
            if (id == Integrator::gear5 && prec == Precision::float32) {
                std::vector<Reference<float>> ref = components<float>(p.state());
                int through = 0;
                for (Reference<float>& c : ref) {
                    bool passed = false;
                    for (std::int64_t k = 0; k < kSteps; ++k) {
                        c.step(scene.dt);
                        passed = passed || any_subnormal(c);
                    }
                    through += passed;
                }
                EXPECT_GE(through, 5) << "without the rule gear5 in float should pass through the subnormals";
            }
        }
}
