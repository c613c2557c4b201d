#pragma once
// The models the fast variant is instantiated for, and which one a run gets. Not with_model's 24: fast's
// kernels are large (each model is seconds of compile time and most of a megabyte of code), so it keeps
// the chain of the cost-per-feature table, each level one feature more than the one before, for one
// radius and for many (10 models), and the laws of physics.md §9 on the full model (7). A run gets the
// lowest level that covers what its scene needs: the features a level has beyond the need are inert
// there (μ·F_n or γ_t·m*·|u_t| zero, γ_n·m*·u_n zero, no walls, walls at rest), so the trajectory is
// the same bit for bit (tests/test_fast.cpp). Each kind is built in a file of its own, so that they
// compile side by side. Without kAllModels (model.hpp) only the chain's two ends.
#include <memory>

#include "demmat/model.hpp"
#include "fast.hpp"

namespace demmat::fast {

// The chain: 0 normal force only, 1 + damping, 2 + rotation and friction, 3 + walls, 4 + moving walls.
inline int paper_level(const ModelFeatures& need)
{
    if (need.moving_walls) return 4;
    if (need.walls) return 3;
    if (need.rotation || need.friction) return 2;
    return need.damping ? 1 : 0;
}

template <bool Polydisperse, class Make>
decltype(auto) with_paper_level(int level, Make&& make)
{
    constexpr bool P = Polydisperse;
    if constexpr (!kAllModels) {  // the chain's two ends (model.hpp)
        if (level == 0) return make.template operator()<Model<false, false, false, false, false, P>>();
        return make.template operator()<Model<true, true, true, true, true, P>>();
    } else {
        switch (level) {
        case 0: return make.template operator()<Model<false, false, false, false, false, P>>();
        case 1: return make.template operator()<Model<false, false, true, false, false, P>>();
        case 2: return make.template operator()<Model<true, true, true, false, false, P>>();
        case 3: return make.template operator()<Model<true, true, true, true, false, P>>();
        default: return make.template operator()<Model<true, true, true, true, true, P>>();
        }
    }
}

std::unique_ptr<FastVariant> make_fast_paper_mono(int level, const FastOptions& options);  // fast_paper_mono.cpp
std::unique_ptr<FastVariant> make_fast_paper_poly(int level, const FastOptions& options);  // fast_paper_poly.cpp
std::unique_ptr<FastVariant> make_fast_law(const ModelFeatures& need, const FastOptions& options);  // fast_laws.cpp

} // namespace demmat::fast
