#pragma once
// The fast variant's unit of data movement (docs/variants.md, "fast"): a quad, four doubles loaded and
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
    if constexpr (W == 8 || W == 4) {
        Quad r[W];
        for (int l = 0; l < W; ++l) r[l] = rows[l];
        transpose4(r[0], r[1], r[2], r[3]);
        if constexpr (W == 8) {
            transpose4(r[4], r[5], r[6], r[7]);
            for (int c = 0; c < 4; ++c) out[c] = __builtin_shufflevector(r[c], r[4 + c], 0, 1, 2, 3, 4, 5, 6, 7);
        } else {
            for (int c = 0; c < 4; ++c) out[c] = r[c];
        }
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
        Quad lo[4], hi[4];
        for (int c = 0; c < 4; ++c) {
            lo[c] = __builtin_shufflevector(in[c], in[c], 0, 1, 2, 3);
            hi[c] = __builtin_shufflevector(in[c], in[c], 4, 5, 6, 7);
        }
        transpose4(lo[0], lo[1], lo[2], lo[3]);
        transpose4(hi[0], hi[1], hi[2], hi[3]);
        for (int l = 0; l < 4; ++l) {
            rows[l] = lo[l];
            rows[4 + l] = hi[l];
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
