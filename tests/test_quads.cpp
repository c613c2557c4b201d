// The transposes that move fast's per-particle quads into the lanes of the law and back (quads.hpp):
// every value to its place, for each pack width a target may give (2, 4 and 8 doubles; each width has
// its own shuffles), and back again. They only move bits, so a value that lands in the wrong lane is
// a wrong force on the wrong particle, which the equivalence tests find only on targets of that width.
#include <gtest/gtest.h>

#include "demmat/lane_engine/quads.hpp"

using namespace demmat;
using namespace demmat::fast;

namespace {

template <int W>
void check_round_trip()
{
    using V = Pack<double, W>;
    Quad rows[W];
    for (int l = 0; l < W; ++l)
        for (int c = 0; c < 4; ++c) rows[l][c] = 10.0 * l + c;  // lane l, component c
    V lanes[4];
    rows_to_lanes<V>(rows, lanes);
    for (int c = 0; c < 4; ++c)
        for (int l = 0; l < W; ++l) EXPECT_EQ(lanes[c][l], 10.0 * l + c) << "width " << W << ", lane " << l << ", component " << c;
    Quad back[W];
    lanes_to_rows<V>(lanes, back);
    for (int l = 0; l < W; ++l)
        for (int c = 0; c < 4; ++c) EXPECT_EQ(back[l][c], 10.0 * l + c) << "width " << W << ", row " << l << ", component " << c;
}

} // namespace

TEST(Quads, TransposesPutEveryValueInItsLaneAndBackAtEachWidth)
{
    check_round_trip<2>();
    check_round_trip<4>();
    check_round_trip<8>();
}
