#pragma once
// The 5th-order Gear predictor–corrector of physics.md §3 (six values per degree of freedom), written
// once. The kernels are templates on the value type V: a variant calls them on one double (a plain
// loop), on one float, or on a whole Eigen array (an element-wise expression evaluates exactly the same
// operations in the same order for every element).
#include <type_traits>

#include "demmat/host_device.hpp"

namespace demmat {

// Per-run constants, computed once in double from Δt and rounded to T. Every variant and every port
// uses these very values, so no variant can fold the constants differently.
template <class T>
struct GearCoefficients {
    T dt{};            // Δt
    T half_dt2{};      // Δt²/2
    T two_over_dt2{};  // 2/Δt²
    T cx{};            // c0·Δt²/2, c0 = 3/16
    T cv{};            // c1·Δt/2,  c1 = 251/360
    T c3{};            // c3·Δt²/2, c3 = 11/18
    T c4{};            // c4·Δt²/2, c4 = 1/6
    T c5{};            // c5·Δt²/2, c5 = 1/60   (c2 = 1: a = a_p + Δa)

    static GearCoefficients make(double dt)
    {
        const double h2 = dt * dt / 2.0;
        GearCoefficients k;
        k.dt = T(dt);
        k.half_dt2 = T(h2);
        k.two_over_dt2 = T(2.0 / (dt * dt));
        k.cx = T(3.0 / 16.0 * h2);
        k.cv = T(251.0 / 360.0 * (dt / 2.0));
        k.c3 = T(11.0 / 18.0 * h2);
        k.c4 = T(1.0 / 6.0 * h2);
        k.c5 = T(1.0 / 60.0 * h2);
        return k;
    }
};

// The rule for negligible derivatives (physics.md §3): after the corrector, each of a, b3, b4, b5 whose
// magnitude is below this bound is set to +0, so that the derivatives of a grain in free flight or at
// rest end at zero instead of decaying into the subnormal numbers (a microcode assist per operation on
// most CPUs). Double 2^-900, float 2^-100: far above each type's smallest normal, far below anything
// they could change (the choice is argued in physics.md §3). The ports receive the double bound from
// C++ (port_variant.hpp), so it is written only here.
template <class T>
DEMMAT_HD constexpr T negligible_derivative()
{
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, float>);
    if constexpr (std::is_same_v<T, float>)
        return 0x1p-100f;
    else
        return 0x1p-900;
}

// u ← +0 when |u| < the bound (both signs and −0 included); NaN and ±inf pass unchanged. A compare
// and a select, no FTZ/DAZ mode: the same bits in every language and on the GPU; in a loop it
// vectorises to two compares and a blend. On a Vec3 or an Eigen array, the same select per element.
template <class V>
DEMMAT_HD inline void zero_if_negligible(V& u)
{
    if constexpr (std::is_floating_point_v<V>) {
        constexpr V bound = negligible_derivative<V>();
        u = (u < bound && u > -bound) ? V(0) : u;
    } else if constexpr (requires { u.x, u.y, u.z; }) {  // a Vec3 (oop): each component
        zero_if_negligible(u.x);
        zero_if_negligible(u.y);
        zero_if_negligible(u.z);
    } else {
        using S = typename V::Scalar;
        u = u.unaryExpr([](S e) {
            zero_if_negligible(e);
            return e;
        });
    }
}

// Predictor: Taylor expansion of the six values (Pascal's triangle on the scaled derivatives).
// Updated in place in this order so that each line reads only values not yet predicted.
template <class V, class T>
DEMMAT_HD inline void gear_predict(V& x, V& v, V& a, V& b3, V& b4, const V& b5, const GearCoefficients<T>& k)
{
    x = x + k.dt * v + k.half_dt2 * a + b3 + b4 + b5;
    v = v + k.dt * a + (T(3) * b3 + T(4) * b4 + T(5) * b5) / k.dt;
    a = a + k.two_over_dt2 * (T(3) * b3 + T(6) * b4 + T(10) * b5);
    b3 = b3 + T(4) * b4 + T(10) * b5;
    b4 = b4 + T(5) * b5;
}

// Corrector, with da = a_corrected − a_predicted already evaluated (a value, not a lazy expression),
// then the rule for negligible derivatives on a, b3, b4, b5.
template <class V, class D, class T>
DEMMAT_HD inline void gear_correct(V& x, V& v, V& a, V& b3, V& b4, V& b5, const D& da, const GearCoefficients<T>& k)
{
    x = x + k.cx * da;
    v = v + k.cv * da;
    a = a + da;
    b3 = b3 + k.c3 * da;
    b4 = b4 + k.c4 * da;
    b5 = b5 + k.c5 * da;
    zero_if_negligible(a);
    zero_if_negligible(b3);
    zero_if_negligible(b4);
    zero_if_negligible(b5);
}

} // namespace demmat
