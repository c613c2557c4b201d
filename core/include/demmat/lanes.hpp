#pragma once
// Packs of lanes for the shared contact law (GCC and Clang vector extensions). The law is written once
// on a value type T that is either a scalar or a pack of W scalars; for a pack, +, −, ×, ÷, comparisons
// and lane_sqrt are the scalar IEEE operations applied lane by lane (correctly rounded, no fusion under
// -ffp-contract=off), so every lane holds the bits the scalar law gives for that pair. Branches of the
// law are written as selects, `cond ? a : b`, which C++ evaluates lane by lane for a pack.
#include <cmath>
#include <concepts>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "demmat/host_device.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace demmat {

namespace detail {
template <class T, int W>
struct PackOf {
    typedef T type __attribute__((vector_size(W * sizeof(T))));
};
} // namespace detail

// W values of T in one vector register (or in several, where W is wider than the machine's vectors).
template <class T, int W>
using Pack = typename detail::PackOf<T, W>::type;

// The widest vector the compilation target has (AVX-512, AVX, else SSE2's 16 bytes), in lanes of T.
template <class T>
inline constexpr int native_lanes =
#if defined(__AVX512F__)
    int(64 / sizeof(T));
#elif defined(__AVX__)
    int(32 / sizeof(T));
#else
    int(16 / sizeof(T));
#endif

template <class V>
concept LanePack = requires(V v) { v[0]; } && std::is_trivially_copyable_v<V> && !std::is_arithmetic_v<V>;

template <LanePack V>
using LaneScalar = std::remove_cvref_t<decltype(std::declval<V&>()[0])>;

template <LanePack V>
inline constexpr int lane_count = int(sizeof(V) / sizeof(LaneScalar<V>));

DEMMAT_HD inline double lane_sqrt(double a) { return std::sqrt(a); }
DEMMAT_HD inline float lane_sqrt(float a) { return std::sqrt(a); }

template <LanePack V>
inline V lane_sqrt(V a)
{
    using S = LaneScalar<V>;
    // The packed square roots are IEEE's correctly rounded sqrt, as sqrtsd / sqrtss are.
#if defined(__AVX512F__)
    // (The masked forms, all lanes selected: GCC 12 warns about the unmasked ones' undefined source.)
    if constexpr (sizeof(V) == 64 && std::same_as<S, double>) return (V)_mm512_mask_sqrt_pd((__m512d)a, __mmask8(0xff), (__m512d)a);
    if constexpr (sizeof(V) == 64 && std::same_as<S, float>) return (V)_mm512_mask_sqrt_ps((__m512)a, __mmask16(0xffff), (__m512)a);
#endif
#if defined(__AVX__)
    if constexpr (sizeof(V) == 32 && std::same_as<S, double>) return (V)_mm256_sqrt_pd((__m256d)a);
    if constexpr (sizeof(V) == 32 && std::same_as<S, float>) return (V)_mm256_sqrt_ps((__m256)a);
#endif
#if defined(__SSE2__)
    if constexpr (sizeof(V) == 16 && std::same_as<S, double>) return (V)_mm_sqrt_pd((__m128d)a);
    if constexpr (sizeof(V) == 16 && std::same_as<S, float>) return (V)_mm_sqrt_ps((__m128)a);
#endif
    V r{};
    for (int l = 0; l < lane_count<V>; ++l) r[l] = std::sqrt(a[l]);
    return r;
}

// std::min's definition, (b < a) ? b : a, for scalars and lane by lane for packs.
template <class T>
DEMMAT_HD inline T lane_min(T a, T b) { return b < a ? b : a; }

// Whether a condition holds in any lane (a comparison of packs), or the condition itself for a scalar.
// Where no lane takes a select's branch, the law can skip computing that branch: every lane's bits are
// the same either way.
DEMMAT_HD inline bool lane_any(bool c) { return c; }
template <class Mask>
    requires LanePack<Mask>
inline bool lane_any(const Mask& c)
{
#if defined(__AVX512F__)
    if constexpr (sizeof(Mask) == 64 && sizeof(c[0]) == 8) return _mm512_test_epi64_mask((__m512i)c, (__m512i)c) != 0;
#endif
    for (int l = 0; l < lane_count<Mask>; ++l)
        if (c[l]) return true;
    return false;
}

namespace detail {
// One initialiser of every lane, which compiles to one broadcast (a loop of lane stores compiled to
// one masked broadcast per lane).
template <class V, class S, std::size_t... L>
inline V splat_lanes(S s, std::index_sequence<L...>)
{
    return V{((void)L, s)...};
}
} // namespace detail

// Every lane s (a pack built from a scalar), or s itself for a scalar type.
template <class V, class S>
DEMMAT_HD inline V splat(S s)
{
    if constexpr (std::is_arithmetic_v<V>) {
        return V(s);
    } else {
        return detail::splat_lanes<V>(LaneScalar<V>(s), std::make_index_sequence<std::size_t(lane_count<V>)>{});
    }
}

} // namespace demmat
