#pragma once
// The object-oriented processor's contacts: a particle's neighbour is a PairContact (the partner with a
// higher id), its wall neighbour a WallContact, and under a contact law with memory (physics.md §9) each
// owns the springs of that contact: the tangential and rolling stretches, and whether the contact was
// live (h > 0) at the last force evaluation. When the search rebuilds a particle's lists, each new
// contact takes the springs of the old one with the same partner, found by the partner's identity (its
// id for a particle, the wall object itself for a wall); a contact that opens forgets its springs.
// Without memory (the paper's law, restitution damping alone) a neighbour is only a pointer to its
// partner, as it always was.
#include <algorithm>
#include <type_traits>
#include <vector>

#include "demmat/contact_memory.hpp"

namespace demmat::oop {

template <class M>
class SphericalParticle;
template <class M>
class Body;

// True for a law of physics.md §9 (restitution damping, a tangential spring, rolling resistance).
template <class M>
inline constexpr bool beyond_paper = M::restitution_damping || M::history || M::rolling;

template <bool Memory>
struct SpringsOf {  // a law without memory: nothing to carry, the law gets a zero stretch each time
    Stretch<double>& stretch_or(Stretch<double>& scratch) { return scratch; }
    void note(bool) {}
};
template <>
struct SpringsOf<true> {
    Stretch<double> stretch;  // zero for a new contact
    bool live = false;        // in contact at the last force evaluation: what save() writes

    Stretch<double>& stretch_or(Stretch<double>&) { return stretch; }
    // After an evaluation: a contact that has opened forgets its springs (one that closes again starts at zero).
    void note(bool touch)
    {
        live = touch;
        if (!touch) stretch = {};
    }
};
template <class M>
using Springs = SpringsOf<M::memory>;

template <class M>
struct PairContact {
    SphericalParticle<M>* partner;
    Springs<M> springs;
};

template <class M>
struct WallContact {
    Body<M>* wall;
    Springs<M> springs;
};

// What a particle's neighbour lists hold: contact objects under a law with memory, else the partners.
template <class M>
using Neighbour = std::conditional_t<M::memory, PairContact<M>, SphericalParticle<M>*>;
template <class M>
using WallNeighbour = std::conditional_t<M::memory, WallContact<M>, Body<M>*>;

template <class M>
SphericalParticle<M>* partner_of(SphericalParticle<M>* p) { return p; }
template <class M>
SphericalParticle<M>* partner_of(const PairContact<M>& c) { return c.partner; }

// The new list's contacts take the springs of the old list's contact with the same partner: both lists
// ascend by partner id, so one walk through the old list finds them.
template <class M>
void recall_springs(const std::vector<PairContact<M>>& old, std::vector<PairContact<M>>& now)
{
    auto o = old.begin();
    for (PairContact<M>& c : now) {
        while (o != old.end() && o->partner->id() < c.partner->id()) ++o;
        if (o != old.end() && o->partner == c.partner) c.springs = o->springs;
    }
}
// Walls: at most a handful per particle, each found by the wall object itself.
template <class M>
void recall_springs(const std::vector<WallContact<M>>& old, std::vector<WallContact<M>>& now)
{
    for (WallContact<M>& c : now) {
        const auto o = std::find_if(old.begin(), old.end(), [&](const WallContact<M>& w) { return w.wall == c.wall; });
        if (o != old.end()) c.springs = o->springs;
    }
}

} // namespace demmat::oop
