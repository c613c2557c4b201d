#pragma once
// The fast variant's unit of data movement (docs/variants/engine.md): a quad, four doubles loaded and
// stored as one vector, and the transposes that move a pack's worth of per-particle quads into the
// lanes of the law (one lane per pair) and back. They move bits and compute nothing.
#include <cstdint>
#include <cstring>

#include "demmat/lanes.hpp"

namespace demmat::fast {

using Index = std::int32_t;  // a particle's storage slot, or a pair's slot in the list

using Quad = Pack<double, 4>;
// The law runs on packs of kLanes pairs: the widest vector the target has.
using Lanes = Pack<double, native_lanes<double>>;
inline constexpr int kLanes = native_lanes<double>;

// Quads go by reference, never by value: built for the baseline (DEMMAT_FAST_NATIVE off), a 32-byte
// vector passed or returned by value changes the calling convention (GCC's -Wpsabi notes).
[[gnu::always_inline]] inline void load_quad(Quad& q, const double* p) { std::memcpy(&q, p, sizeof(q)); }

// In-place transpose of a 4×4 block: afterwards a[c] holds what was lane c of the four, and so on.
[[gnu::always_inline]] inline void transpose4(Quad& a, Quad& b, Quad& c, Quad& d)
{
    const Quad t0 = __builtin_shufflevector(a, b, 0, 4, 2, 6), t1 = __builtin_shufflevector(a, b, 1, 5, 3, 7);
    const Quad t2 = __builtin_shufflevector(c, d, 0, 4, 2, 6), t3 = __builtin_shufflevector(c, d, 1, 5, 3, 7);
    a = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    b = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    c = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    d = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

// rows[l] is lane l's quad; out[c][l] = rows[l][c]. A transpose of whole vectors (a few shuffles per
// pack) instead of one scalar load and one lane insert per value. (Always inlined: called out of line,
// as GCC chose once the kernel had a few callers, the vectors go through memory, which costs the step.)
template <class V>
[[gnu::always_inline]] inline void rows_to_lanes(const Quad* rows, V out[4])
{
    constexpr int W = lane_count<V>;
    if constexpr (W == 8) {
        // Rows l and l + 4 side by side in one vector, then two rounds of two-source shuffles (unpack
        // within 128-bit pairs, then a permute across them): twelve shuffles for the pack.
        using O = Pack<double, 8>;
        O a[4], t[4];
        for (int l = 0; l < 4; ++l) a[l] = __builtin_shufflevector(rows[l], rows[l + 4], 0, 1, 2, 3, 4, 5, 6, 7);
        t[0] = __builtin_shufflevector(a[0], a[1], 0, 8, 2, 10, 4, 12, 6, 14);  // x0 x1 z0 z1 | x4 x5 z4 z5
        t[1] = __builtin_shufflevector(a[0], a[1], 1, 9, 3, 11, 5, 13, 7, 15);  // y0 y1 w0 w1 | y4 y5 w4 w5
        t[2] = __builtin_shufflevector(a[2], a[3], 0, 8, 2, 10, 4, 12, 6, 14);
        t[3] = __builtin_shufflevector(a[2], a[3], 1, 9, 3, 11, 5, 13, 7, 15);
        out[0] = __builtin_shufflevector(t[0], t[2], 0, 1, 8, 9, 4, 5, 12, 13);
        out[1] = __builtin_shufflevector(t[1], t[3], 0, 1, 8, 9, 4, 5, 12, 13);
        out[2] = __builtin_shufflevector(t[0], t[2], 2, 3, 10, 11, 6, 7, 14, 15);
        out[3] = __builtin_shufflevector(t[1], t[3], 2, 3, 10, 11, 6, 7, 14, 15);
    } else if constexpr (W == 4) {
        Quad r[4] = {rows[0], rows[1], rows[2], rows[3]};
        transpose4(r[0], r[1], r[2], r[3]);
        for (int c = 0; c < 4; ++c) out[c] = r[c];
    } else if constexpr (W == 2) {
        out[0] = __builtin_shufflevector(rows[0], rows[1], 0, 4);
        out[1] = __builtin_shufflevector(rows[0], rows[1], 1, 5);
        out[2] = __builtin_shufflevector(rows[0], rows[1], 2, 6);
        out[3] = __builtin_shufflevector(rows[0], rows[1], 3, 7);
    } else {
        for (int c = 0; c < 4; ++c)
            for (int l = 0; l < W; ++l) out[c][l] = rows[l][c];
    }
}

// The inverse: rows[l] = {in[0][l], in[1][l], in[2][l], in[3][l]}.
template <class V>
[[gnu::always_inline]] inline void lanes_to_rows(const V in[4], Quad* rows)
{
    constexpr int W = lane_count<V>;
    if constexpr (W == 8) {
        // The same shuffles backwards: u[l] holds rows l and l + 4.
        using O = Pack<double, 8>;
        const O t0 = __builtin_shufflevector(in[0], in[1], 0, 8, 2, 10, 4, 12, 6, 14);  // x0 y0 x2 y2 | x4 y4 x6 y6
        const O t1 = __builtin_shufflevector(in[0], in[1], 1, 9, 3, 11, 5, 13, 7, 15);  // x1 y1 x3 y3 | x5 y5 x7 y7
        const O t2 = __builtin_shufflevector(in[2], in[3], 0, 8, 2, 10, 4, 12, 6, 14);
        const O t3 = __builtin_shufflevector(in[2], in[3], 1, 9, 3, 11, 5, 13, 7, 15);
        const O u[4] = {__builtin_shufflevector(t0, t2, 0, 1, 8, 9, 4, 5, 12, 13), __builtin_shufflevector(t1, t3, 0, 1, 8, 9, 4, 5, 12, 13),
                        __builtin_shufflevector(t0, t2, 2, 3, 10, 11, 6, 7, 14, 15),
                        __builtin_shufflevector(t1, t3, 2, 3, 10, 11, 6, 7, 14, 15)};
        for (int l = 0; l < 4; ++l) {
            rows[l] = __builtin_shufflevector(u[l], u[l], 0, 1, 2, 3);
            rows[4 + l] = __builtin_shufflevector(u[l], u[l], 4, 5, 6, 7);
        }
    } else if constexpr (W == 4) {
        Quad r[4] = {in[0], in[1], in[2], in[3]};
        transpose4(r[0], r[1], r[2], r[3]);
        for (int l = 0; l < 4; ++l) rows[l] = r[l];
    } else {
        for (int l = 0; l < W; ++l) rows[l] = Quad{in[0][l], in[1][l], in[2][l], in[3][l]};
    }
}

// Gather the quads row(l) of the kLanes lanes into four lane vectors.
template <class Row>
[[gnu::always_inline]] inline void gather_lanes(Row&& row, Lanes out[4])
{
    Quad rows[kLanes];
    for (int l = 0; l < kLanes; ++l) rows[l] = row(l);
    rows_to_lanes<Lanes>(rows, out);
}

} // namespace demmat::fast
