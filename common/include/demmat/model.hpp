#pragma once
// Compile-time model features. The shared kernels are templates on a Model so that a scene that does
// not use a feature (friction, damping, rotation) can run a specialisation that does no work for it,
// without a copy of the code (see docs/design.md, "Model features").

namespace demmat {

template <bool Rotation, bool Friction, bool Damping>
struct Model {
    static constexpr bool rotation = Rotation;  // torques and the rotational Gear state
    static constexpr bool friction = Friction;  // tangential force (needs rotation to be meaningful)
    static constexpr bool damping = Damping;    // velocity-dependent normal term
};

// The paper's full model: what every variant runs unless a scene asks for less.
using FullModel = Model<true, true, true>;

} // namespace demmat
