#pragma once
// The time integrators a run can choose (docs/accuracy.md), written once. Each scheme is a small policy
// type whose predict/correct are templates on the value type V, exactly like gear.hpp: a variant calls
// them on one double, one float, or a whole Eigen array. Every scheme works on the same six values per
// degree of freedom (x, v, a, b3, b4, b5) so that one state layout and one state file serve them all;
// a scheme leaves the values it does not use untouched (zero from the initial state). Every scheme ends
// its corrector with the rule for negligible derivatives (gear.hpp) on the derivatives it carries: a,
// b3, b4, b5 for gear5; a, b3 for gear3; a for verlet and symplectic_euler.
//
// The step keeps the paper's phases for every scheme: predict → search → forces (at the predicted
// positions and velocities) → correct with the new acceleration a_new = F/m + g.
#include <optional>
#include <string>
#include <string_view>

#include "demmat/gear.hpp"

namespace demmat {

enum class Integrator {
    gear5,             // the paper's 5th-order Gear predictor–corrector, 6 values (gear.hpp)
    gear3,             // 3rd-order Gear predictor–corrector, 4 values (x, v, a, b3)
    verlet,            // velocity Verlet (kick–drift–kick), forces at the Euler-predicted velocity
    symplectic_euler,  // semi-implicit Euler: v ← v + Δt·a, then x ← x + Δt·v
};
enum class Precision { float64, float32 };

inline constexpr Integrator all_integrators[] = {Integrator::gear5, Integrator::gear3, Integrator::verlet, Integrator::symplectic_euler};
inline constexpr Precision all_precisions[] = {Precision::float64, Precision::float32};

inline const char* name(Integrator s)
{
    switch (s) {
    case Integrator::gear5: return "gear5";
    case Integrator::gear3: return "gear3";
    case Integrator::verlet: return "verlet";
    case Integrator::symplectic_euler: return "symplectic_euler";
    }
    return "?";
}
inline const char* name(Precision p) { return p == Precision::float64 ? "double" : "float"; }

inline std::optional<Integrator> parse_integrator(std::string_view s)
{
    for (Integrator i : all_integrators)
        if (s == name(i)) return i;
    return std::nullopt;
}
inline std::optional<Precision> parse_precision(std::string_view s)
{
    for (Precision p : all_precisions)
        if (s == name(p)) return p;
    return std::nullopt;
}
inline constexpr const char* integrator_names = "gear5, gear3, verlet or symplectic_euler";
inline constexpr const char* precision_names = "double or float";

// A run's choice; the default is the paper's (and every variant's) scheme in double.
struct IntegratorChoice {
    Integrator scheme = Integrator::gear5;
    Precision precision = Precision::float64;
    bool is_default() const { return scheme == Integrator::gear5 && precision == Precision::float64; }
    bool operator==(const IntegratorChoice&) const = default;
    std::string describe() const { return std::string(name(scheme)) + " in " + name(precision); }
};

// ---- the schemes ------------------------------------------------------------------------------------
// Each: `id`, `Coefficients<T>` (per-run constants computed once in double from Δt, rounded to T),
// predict(x, v, a, b3, b4, b5 (read only), k) and correct(x, v, a, b3, b4, b5, a_new, k).

// The paper's scheme, through gear.hpp unchanged (same operations, so the same bits as before).
struct Gear5Scheme {
    static constexpr Integrator id = Integrator::gear5;
    template <class T>
    using Coefficients = GearCoefficients<T>;

    template <class V, class T>
    static void predict(V& x, V& v, V& a, V& b3, V& b4, const V& b5, const GearCoefficients<T>& k)
    {
        gear_predict(x, v, a, b3, b4, b5, k);
    }
    template <class V, class D, class T>
    static void correct(V& x, V& v, V& a, V& b3, V& b4, V& b5, const D& a_new, const GearCoefficients<T>& k)
    {
        const V da = a_new - a;  // a value, not a lazy expression: a changes before b3 … b5 use it
        gear_correct(x, v, a, b3, b4, b5, da, k);
    }
};

template <class T>
struct Gear3Coefficients {
    T dt{}, half_dt2{}, two_over_dt2{};
    T cx{};  // c0·Δt²/2, c0 = 1/6
    T cv{};  // c1·Δt/2,  c1 = 5/6
    T c3{};  // c3·Δt²/2, c3 = 1/3   (c2 = 1)
    static Gear3Coefficients make(double dt)
    {
        const double h2 = dt * dt / 2.0;
        return {T(dt), T(h2), T(2.0 / (dt * dt)), T(1.0 / 6.0 * h2), T(5.0 / 6.0 * (dt / 2.0)), T(1.0 / 3.0 * h2)};
    }
};

// Gear's 4-value predictor–corrector for a second-order equation (Allen & Tildesley, Table E.1):
// the 6-value scheme of physics.md §3 truncated after b3, with Gear's 4-value correctors.
struct Gear3Scheme {
    static constexpr Integrator id = Integrator::gear3;
    template <class T>
    using Coefficients = Gear3Coefficients<T>;

    template <class V, class T>
    static void predict(V& x, V& v, V& a, V& b3, V&, const V&, const Gear3Coefficients<T>& k)
    {
        x = x + k.dt * v + k.half_dt2 * a + b3;
        v = v + k.dt * a + (T(3) * b3) / k.dt;
        a = a + k.two_over_dt2 * (T(3) * b3);
    }
    template <class V, class D, class T>
    static void correct(V& x, V& v, V& a, V& b3, V&, V&, const D& a_new, const Gear3Coefficients<T>& k)
    {
        const V da = a_new - a;
        x = x + k.cx * da;
        v = v + k.cv * da;
        a = a + da;
        b3 = b3 + k.c3 * da;
        zero_if_negligible(a);
        zero_if_negligible(b3);
    }
};

template <class T>
struct VerletCoefficients {
    T dt{}, half_dt{}, half_dt2{};
    static VerletCoefficients make(double dt) { return {T(dt), T(dt / 2.0), T(dt * dt / 2.0)}; }
};

// Velocity Verlet written as a predictor–corrector (it is Gear's 3-value scheme with c0 = 0, c1 = 1):
//   predict  x ← x + Δt·v + (Δt²/2)·a        (the Verlet drift with the half kick folded in)
//            v ← v + Δt·a                   (Euler prediction of v(t+Δt): the velocity the forces see)
//   correct  v ← v + (Δt/2)·(a_new − a)     (= v_old + (Δt/2)·(a_old + a_new), the second half kick)
//            a ← a_new
// Choice (docs/accuracy.md): velocity-dependent forces (damping, friction) are evaluated at the
// Euler-predicted v(t+Δt), whose error is O(Δt²), so the scheme stays second order with damping; the
// common alternative, the half-step velocity v(t+Δt/2) (LAMMPS, LIGGGHTS), is only first order in the
// damping term. A build configured with -DDEMMAT_VERLET_VELOCITY=half_step takes LAMMPS's instead, to
// show by experiment how much of the distance from LAMMPS it makes (scripts/run_peers.sh --diagnose,
// docs/peers.md); like the lever arms of contact_law.hpp it is not a scheme of the suite.
#ifdef DEMMAT_VERLET_HALF_STEP_VELOCITY
inline constexpr bool kVerletHalfStepVelocity = true;
#else
inline constexpr bool kVerletHalfStepVelocity = false;
#endif
struct VerletScheme {
    static constexpr Integrator id = Integrator::verlet;
    template <class T>
    using Coefficients = VerletCoefficients<T>;

    template <class V, class T>
    static void predict(V& x, V& v, V& a, V&, V&, const V&, const VerletCoefficients<T>& k)
    {
        x = x + k.dt * v + k.half_dt2 * a;
        if constexpr (kVerletHalfStepVelocity)
            v = v + k.half_dt * a;  // v(t+Δt/2): LAMMPS's fix nve/sphere
        else
            v = v + k.dt * a;
    }
    template <class V, class D, class T>
    static void correct(V&, V& v, V& a, V&, V&, V&, const D& a_new, const VerletCoefficients<T>& k)
    {
        if constexpr (kVerletHalfStepVelocity)
            v = v + k.half_dt * a_new;
        else
            v = v + k.half_dt * (a_new - a);
        a = a_new;
        zero_if_negligible(a);
    }
};

template <class T>
struct EulerCoefficients {
    T dt{};
    static EulerCoefficients make(double dt) { return {T(dt)}; }
};

// Symplectic (semi-implicit) Euler: v(t+Δt) = v + Δt·a(t), x(t+Δt) = x + Δt·v(t+Δt); the forces of the
// step are then evaluated at the new x and v, and the corrector only stores them. First order.
struct SymplecticEulerScheme {
    static constexpr Integrator id = Integrator::symplectic_euler;
    template <class T>
    using Coefficients = EulerCoefficients<T>;

    template <class V, class T>
    static void predict(V& x, V& v, V& a, V&, V&, const V&, const EulerCoefficients<T>& k)
    {
        v = v + k.dt * a;
        x = x + k.dt * v;
    }
    template <class V, class D, class T>
    static void correct(V&, V&, V& a, V&, V&, V&, const D& a_new, const EulerCoefficients<T>&)
    {
        a = a_new;
        zero_if_negligible(a);
    }
};

// Calls f(S{}) with the scheme type of `id`, f(T{}) with the value type of `p`: code that picks an
// instantiation from a run-time choice (the arrays variant, the accuracy study, stability searches).
template <class F>
decltype(auto) with_scheme(Integrator id, F&& f)
{
    switch (id) {
    case Integrator::gear3: return f(Gear3Scheme{});
    case Integrator::verlet: return f(VerletScheme{});
    case Integrator::symplectic_euler: return f(SymplecticEulerScheme{});
    case Integrator::gear5: break;
    }
    return f(Gear5Scheme{});
}
template <class F>
decltype(auto) with_precision(Precision p, F&& f)
{
    if (p == Precision::float32) return f(float{});
    return f(double{});
}

} // namespace demmat
