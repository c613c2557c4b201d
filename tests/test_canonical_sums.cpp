// fast's canonical sums (canonical_sums.hpp): a group of particles summed side by side, in either of
// its two forms (eight lanes a particle, for AVX-512; a quad each for force and torque, for narrower
// targets), must give each particle the bits of its sum alone (sum_particle), the order of physics.md
// §6. A build runs only the form its target's width picks, so the equivalence tests see one of them on
// a given machine; this runs both here, on a list with random slot values of mixed magnitudes, where
// any change of order, sign or lane changes bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "demmat/soa/canonical_sums.hpp"

using namespace demmat;
using namespace demmat::fast;

namespace {

// n particles (ids their storage indices), each storing slots with a few random partners of higher index
// within `window`, as their owner; as_i and as_j as the list's build makes them.
NeighbourList random_list(std::size_t n, std::size_t window, std::mt19937_64& rng)
{
    NeighbourList list;
    list.start.assign(n + 1, 0);
    std::uniform_int_distribution<std::size_t> count(0, 7), offset(1, window);
    for (std::size_t s = 0; s < n; ++s) {
        list.start[s] = Index(list.partner.size());
        std::vector<std::size_t> partners;
        for (std::size_t c = count(rng); c > 0; --c) {
            const std::size_t q = s + offset(rng);
            if (q < n && std::find(partners.begin(), partners.end(), q) == partners.end()) partners.push_back(q);
        }
        std::sort(partners.begin(), partners.end());
        for (std::size_t q : partners) {
            list.owner.push_back(Index(s));
            list.partner.push_back(Index(q));
        }
    }
    list.start[n] = Index(list.partner.size());
    std::vector<Index> id(n);
    for (std::size_t s = 0; s < n; ++s) id[s] = Index(s);
    list.index_by_particle(id, false);
    return list;
}

// The bits of particle s's sum in p (force, then torque).
std::vector<std::uint64_t> bits_of(const Particles& p, std::size_t s)
{
    std::vector<std::uint64_t> out;
    for (const std::vector<double>* a : {&p.f, &p.t})
        for (int c = 0; c < 3; ++c) {
            std::uint64_t b;
            const double v = (*a)[std::size_t(c) * p.n + s];
            std::memcpy(&b, &v, sizeof b);
            out.push_back(b);
        }
    return out;
}

} // namespace

TEST(CanonicalSums, BothGroupFormsGiveEachParticleTheBitsOfItsSumAlone)
{
    std::mt19937_64 rng(12345);
    const std::size_t n = 3 * CanonicalSums::kChunk + 17;  // several chunks, the last one partial
    const NeighbourList list = random_list(n, 60, rng);
    ASSERT_GT(list.pairs(), 4 * n / 2);
    CanonicalSums sums;
    sums.plan(list, n, false);

    // The ring as the sweep leaves it after the last chunk: slot k at k & mask (a slot overwritten by a
    // later one is read alike by every form), the slot of zeros at ring_slots, one more past it.
    const std::size_t mask = sums.ring_slots - 1;
    std::vector<Slot> ring(sums.ring_slots + 2, Slot{});
    std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
    std::uniform_int_distribution<int> exponent(-30, 30);
    auto value = [&] { return std::ldexp(mantissa(rng), exponent(rng)); };
    for (std::size_t k = 0; k < list.pairs(); ++k) {
        Slot& s = ring[k & mask];
        for (Vec3d* v : {&s.tj, &s.f, &s.ti}) *v = {value(), value(), value()};
    }

    WallContacts walls;
    walls.init({}, 1e-5, n);
    Particles alone, eight, quads;
    for (Particles* p : {&alone, &eight, &quads}) {
        p->n = n;
        p->f.assign(3 * n, -1.0);
        p->t.assign(3 * n, -1.0);
    }
    const SlotSource from{ring.data(), ring.data(), mask, 0};
    for (std::size_t s = 0; s < n; ++s) sums.sum_particle(s, from, list, walls, alone);
    std::size_t grouped = 0;
    for (const CanonicalSums::Group& g : sums.by_last.groups) {
        sums.sum_group_eight(sums.by_last, g, ring.data(), walls, eight);
        sums.sum_group_quads(sums.by_last, g, ring.data(), walls, quads);
        grouped += std::size_t(g.count);
    }
    ASSERT_EQ(grouped, n);  // every particle is in one group

    std::size_t with_slots = 0;
    for (std::size_t s = 0; s < n; ++s) {
        with_slots += list.jstart[s + 1] > list.jstart[s] && list.istart[s + 1] > list.istart[s];
        EXPECT_EQ(bits_of(eight, s), bits_of(alone, s)) << "eight lanes, particle " << s;
        EXPECT_EQ(bits_of(quads, s), bits_of(alone, s)) << "quads, particle " << s;
    }
    EXPECT_GT(with_slots, n / 2);  // most sums read slots both as j and as i
}
