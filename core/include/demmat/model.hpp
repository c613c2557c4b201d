#pragma once
// Compile-time model features. The shared kernels (contact_law.hpp) and the phases of the specialising
// variants are templates on a Model, and test its flags with `if constexpr`, so that a scene that does
// not use a feature runs an instantiation that does no work for it, without a copy of the code. A run
// derives what its scene needs (features_of, features.hpp) and picks the smallest instantiated model
// that has all of it (with_model, below). See docs/design.md, "Model features".
#include <string>
#include <utility>

#ifndef DEMMAT_ALL_MODELS
#define DEMMAT_ALL_MODELS 1
#endif

namespace demmat {

// Whether this build instantiates every specialised model (CMake's DEMMAT_ALL_MODELS), or only the two
// ends of each chain: every feature off, every feature on (the sanitizer build, for its compile time;
// every `if constexpr` on a feature still runs both ways).
inline constexpr bool kAllModels = DEMMAT_ALL_MODELS != 0;

// The last three flags are the contact laws beyond the paper's (physics.md §9, contact_memory.hpp); their
// defaults are the paper's law, so Model<R, F, D, W, MW, P> is the very type it was before they existed.
template <bool Rotation, bool Friction, bool Damping, bool Walls = true, bool MovingWalls = true, bool Polydisperse = true,
          bool RestitutionDamping = false, bool History = false, bool Rolling = false>
struct Model {
    static_assert(!Friction || Rotation, "friction implies rotation (the tangential force is what makes torques)");
    static_assert(!MovingWalls || Walls, "moving walls imply walls");
    static_assert(!History || Friction, "a tangential spring is a friction law");
    static_assert(!Rolling || Rotation, "rolling resistance acts as torques");
    static constexpr bool rotation = Rotation;          // torques and the rotational Gear state
    static constexpr bool friction = Friction;          // tangential force
    static constexpr bool damping = Damping;            // velocity-dependent normal term γ_n·m*·u_n
    static constexpr bool walls = Walls;                // wall search and particle–wall contacts
    static constexpr bool moving_walls = MovingWalls;   // wall positions per step, wall velocity in u
    static constexpr bool polydisperse = Polydisperse;  // R*, m* per contact (else once per run)
    static constexpr bool restitution_damping = RestitutionDamping;  // η_n = α·sqrt(m*·k_n) (tsuji, restitution)
    static constexpr bool history = History;            // tangential spring with a stretch per contact
    static constexpr bool rolling = Rolling;            // rolling resistance (sds) with a stretch per contact
    static constexpr bool memory = History || Rolling;  // a stretch per contact, carried from step to step
};

// The paper's full model: what every variant runs unless a scene asks for less.
using FullModel = Model<true, true, true, true, true, true>;

// The same flags at run time: what a scene needs (features_of) or what an instantiation models.
struct ModelFeatures {
    bool rotation = false, friction = false, damping = false, walls = false, moving_walls = false, polydisperse = false;
    bool restitution_damping = false, history = false, rolling = false;  // the laws of physics.md §9

    // The paper's full model (its law, every feature): what a variant that does not specialise runs.
    static constexpr ModelFeatures full() { return {true, true, true, true, true, true}; }
    template <class M>
    static constexpr ModelFeatures of()
    {
        return {M::rotation, M::friction, M::damping, M::walls, M::moving_walls, M::polydisperse, M::restitution_damping, M::history, M::rolling};
    }
    // True when the contact law is not the paper's (§9): only variants that implement it may run it.
    constexpr bool beyond_paper() const { return restitution_damping || history || rolling; }

    // True when a model with these features computes everything `need` asks for.
    constexpr bool covers(const ModelFeatures& need) const
    {
        return (rotation || !need.rotation) && (friction || !need.friction) && (damping || !need.damping) &&
               (walls || !need.walls) && (moving_walls || !need.moving_walls) && (polydisperse || !need.polydisperse) &&
               restitution_damping == need.restitution_damping && history == need.history && rolling == need.rolling;
    }
    constexpr ModelFeatures operator|(const ModelFeatures& o) const
    {
        return {rotation || o.rotation, friction || o.friction, damping || o.damping, walls || o.walls, moving_walls || o.moving_walls,
                polydisperse || o.polydisperse, restitution_damping || o.restitution_damping, history || o.history, rolling || o.rolling};
    }
    constexpr bool operator==(const ModelFeatures&) const = default;

    // "rotation+friction+damping+walls+moving_walls+polydisperse", or "normal" with none of them.
    std::string name() const
    {
        std::string s;
        auto put = [&s](bool on, const char* n) {
            if (!on) return;
            if (!s.empty()) s += '+';
            s += n;
        };
        put(rotation, "rotation");
        put(friction, "friction");
        put(damping, "damping");
        put(walls, "walls");
        put(moving_walls, "moving_walls");
        put(polydisperse, "polydisperse");
        put(restitution_damping, "restitution_damping");
        put(history, "history");
        put(rolling, "rolling");
        return s.empty() ? "normal" : s;
    }
};

namespace detail {
template <class F>
decltype(auto) branch(bool on, F&& f)
{
    return on ? std::forward<F>(f).template operator()<true>() : std::forward<F>(f).template operator()<false>();
}
} // namespace detail

// Calls make.template operator()<M>() with the smallest instantiated model M that covers `need`, and
// returns what it returns (every instantiation must return the same type, e.g. unique_ptr<Variant>).
// The instantiated set, 2 × 2 × 3 × 2 = 24 models, leaves out the combinations that are never the
// smallest cover of a real scene: friction without rotation (no torque without a tangential force is
// impossible to use) and rotation without friction (rotation is needed without friction only to carry
// a given initial spin; the rotation+friction model then runs, exactly, with μ·F_n or γ_t·m*·|u_t|
// zero), moving walls without walls. Without kAllModels the set is 2 × 2: the need's polydispersity
// with every other feature off (a scene that needs none of them) or on.
template <class Make>
decltype(auto) with_model(const ModelFeatures& need, Make&& make)
{
    if constexpr (!kAllModels) {
        const bool any = need.rotation || need.friction || need.damping || need.walls || need.moving_walls;
        return detail::branch(any, [&]<bool A>() -> decltype(auto) {
            return detail::branch(need.polydisperse, [&]<bool P>() -> decltype(auto) { return make.template operator()<Model<A, A, A, A, A, P>>(); });
        });
    } else {
        const bool spin = need.rotation || need.friction;
        const int walls = need.moving_walls ? 2 : need.walls ? 1 : 0;
        return detail::branch(spin, [&]<bool RF>() -> decltype(auto) {
            return detail::branch(need.damping, [&]<bool D>() -> decltype(auto) {
                return detail::branch(need.polydisperse, [&]<bool P>() -> decltype(auto) {
                    switch (walls) {
                    case 0: return make.template operator()<Model<RF, RF, D, false, false, P>>();
                    case 1: return make.template operator()<Model<RF, RF, D, true, false, P>>();
                    default: return make.template operator()<Model<RF, RF, D, true, true, P>>();
                    }
                });
            });
        });
    }
}

// with_model, and also the laws of physics.md §9: a scene with the paper's law gets exactly with_model's
// instantiation; a scene with another law gets the full model with that law's flags (7 more models; the
// finer features are not specialised for these laws). Only a variant that implements the laws calls it.
template <class Make>
decltype(auto) with_law_model(const ModelFeatures& need, Make&& make)
{
    if (!need.beyond_paper()) return with_model(need, std::forward<Make>(make));
    return detail::branch(need.restitution_damping, [&]<bool A>() -> decltype(auto) {
        return detail::branch(need.history, [&]<bool H>() -> decltype(auto) {
            return detail::branch(need.rolling, [&]<bool R>() -> decltype(auto) {
                return make.template operator()<Model<true, true, true, true, true, true, A, H, R>>();
            });
        });
    });
}

} // namespace demmat
