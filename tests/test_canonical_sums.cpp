// fast's canonical sums (canonical_sums.hpp): a group of particles summed side by side, in either of
// its two forms from a schedule's table (eight lanes a particle, for AVX-512; a quad each for force and
// torque, for narrower targets) or from the lists (sum_particles, the sums that straddle), must give
// each particle the bits of its sum alone (sum_particles of one), the order of physics.md §6. A build
// runs only the table form its target's width picks, so the equivalence tests see one of them on a
// given machine; this runs both here, on a list with random slot values of mixed magnitudes, where
// any change of order, sign or lane changes bits. The sum alone is checked in turn against the order
// written out from every slot of the list, with ids that do not follow storage. The list's per-particle
// indexes (as_i, as_j, earliest), made at each rebuild by counting sorts, and the plan's chunk range
// are checked against the same rules, from one thread and from a team.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "demmat/lane_engine/canonical_sums.hpp"

using namespace demmat;
using namespace demmat::fast;

namespace {

// n particles with ids in a random order (storage is not id order), each storing slots with a few
// random partners of higher index within `window`, the lower id of each pair its owner (the law's i);
// as_i and as_j as the list's build makes them.
NeighbourList random_list(std::size_t n, std::size_t window, std::mt19937_64& rng, std::vector<Index>& id)
{
    id.resize(n);
    for (std::size_t s = 0; s < n; ++s) id[s] = Index(s);
    std::shuffle(id.begin(), id.end(), rng);
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
        for (std::size_t q : partners) {
            const bool swap = id[q] < id[s];
            list.owner.push_back(Index(swap ? q : s));
            list.partner.push_back(Index(swap ? s : q));
        }
    }
    list.start[n] = Index(list.partner.size());
    std::vector<Index> pos(n);
    for (std::size_t s = 0; s < n; ++s) pos[std::size_t(id[s])] = Index(s);
    list.index_by_particle(pos, false);
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

// The list's canonical indexes (as_i, as_j, earliest), built by counting sorts, and the plan's chunk
// range per particle, against the rules written out slot by slot; the same bits from a team of three
// as from one thread.
TEST(CanonicalSums, IndexesAndPlanFollowTheRulesWrittenOut)
{
    std::mt19937_64 rng(777);
    const std::size_t n = 5 * CanonicalSums::kChunk + 3;
    std::vector<Index> id;
    const NeighbourList list = random_list(n, 300, rng, id);
    std::vector<std::vector<std::pair<Index, Index>>> as_i(n), as_j(n);  // (other's id, slot)
    std::vector<Index> earliest(n);
    for (std::size_t s = 0; s < n; ++s) earliest[s] = Index(s);
    for (std::size_t k = 0; k < list.pairs(); ++k) {
        const Index i = list.owner[k], j = list.partner[k], at = std::min(i, j);
        as_i[std::size_t(i)].push_back({id[std::size_t(j)], Index(k)});
        as_j[std::size_t(j)].push_back({id[std::size_t(i)], Index(k)});
        for (Index q : {i, j}) earliest[std::size_t(q)] = std::min(earliest[std::size_t(q)], at);
    }
    std::size_t far = 0;  // particles whose earliest slot lies in an earlier chunk
    for (std::size_t s = 0; s < n; ++s) {
        std::sort(as_i[s].begin(), as_i[s].end());
        std::sort(as_j[s].begin(), as_j[s].end());
        auto slots_of = [](const std::vector<Index>& start, const std::vector<Index>& slots, std::size_t s) {
            return std::vector<Index>(slots.begin() + start[s], slots.begin() + start[s + 1]);
        };
        std::vector<Index> want_i, want_j;
        for (const auto& e : as_i[s]) want_i.push_back(e.second);
        for (const auto& e : as_j[s]) want_j.push_back(e.second);
        EXPECT_EQ(slots_of(list.istart, list.as_i, s), want_i) << "as_i of particle " << s;
        EXPECT_EQ(slots_of(list.jstart, list.as_j, s), want_j) << "as_j of particle " << s;
        EXPECT_EQ(list.earliest[s], earliest[s]) << "earliest of particle " << s;
        far += std::size_t(earliest[s]) / CanonicalSums::kChunk < s / CanonicalSums::kChunk;
    }
    EXPECT_GT(far, n / 20);

    CanonicalSums sums;
    sums.plan(list, n, false);
    std::size_t span = 0;  // the most chunks from a particle's first slot to its last
    for (std::size_t s = 0; s < n; ++s) {
        EXPECT_EQ(sums.first_chunk[s], Index(std::size_t(earliest[s]) / CanonicalSums::kChunk)) << "particle " << s;
        span = std::max(span, s / CanonicalSums::kChunk - std::size_t(earliest[s]) / CanonicalSums::kChunk);
    }
    EXPECT_EQ(sums.span_chunks, span);
    for (std::size_t c = 0; c < CanonicalSums::chunks(n); ++c) {  // the ring holds any span + 1 chunks' slots
        const std::size_t end = std::min(n, (c + span + 1) * CanonicalSums::kChunk);
        EXPECT_LE(std::size_t(list.start[end] - list.start[c * CanonicalSums::kChunk]), sums.ring_slots) << "from chunk " << c;
    }

    const int saved = omp_get_max_threads();
    omp_set_num_threads(3);
    NeighbourList team = list;
    team.as_i.assign(team.as_i.size(), -1);
    team.as_j.assign(team.as_j.size(), -1);
    team.earliest.assign(n, -1);
    std::vector<Index> pos(n);
    for (std::size_t s = 0; s < n; ++s) pos[std::size_t(id[s])] = Index(s);
    team.index_by_particle(pos, true);
    omp_set_num_threads(saved);
    EXPECT_EQ(team.istart, list.istart);
    EXPECT_EQ(team.as_i, list.as_i);
    EXPECT_EQ(team.jstart, list.jstart);
    EXPECT_EQ(team.as_j, list.as_j);
    EXPECT_EQ(team.earliest, list.earliest);
}

// Each chunk's groups and tables are planned apart from the others', shared by the team: a plan made
// on a team of three (repeated, so that the threads meet in every order) is that of one thread.
TEST(CanonicalSums, PlanOnATeamIsThePlanOfOneThread)
{
    std::mt19937_64 rng(778);
    const std::size_t n = 400 * CanonicalSums::kChunk + 5;
    std::vector<Index> id;
    const NeighbourList list = random_list(n, 300, rng, id);
    CanonicalSums alone;
    alone.plan(list, n, false);
    const int saved = omp_get_max_threads();
    omp_set_num_threads(3);
    for (int round = 0; round < 3; ++round) {
        CanonicalSums team;
        team.plan(list, n, true);
        EXPECT_EQ(team.first_chunk, alone.first_chunk);
        EXPECT_EQ(team.span_chunks, alone.span_chunks);
        EXPECT_EQ(team.ring_slots, alone.ring_slots);
        EXPECT_EQ(team.by_last.group_start, alone.by_last.group_start);
        ASSERT_EQ(team.by_last.groups.size(), alone.by_last.groups.size());
        std::size_t differ = 0;
        for (std::size_t q = 0; q < alone.by_last.groups.size(); ++q) {
            const CanonicalSums::Group &a = team.by_last.groups[q], &b = alone.by_last.groups[q];
            const auto ta = team.by_last.table.begin() + a.table, tb = alone.by_last.table.begin() + b.table;
            differ += !(std::equal(a.grain, a.grain + CanonicalSums::kGroup, b.grain) && a.count == b.count && a.as_j == b.as_j &&
                        a.as_i == b.as_i && a.table == b.table && std::equal(ta, ta + (b.as_j + b.as_i) * CanonicalSums::kGroup, tb));
        }
        EXPECT_EQ(differ, 0u) << "groups planned otherwise on the team, round " << round;
    }
    omp_set_num_threads(saved);
}

TEST(CanonicalSums, EveryGroupFormGivesEachParticleTheBitsOfItsSumAlone)
{
    std::mt19937_64 rng(12345);
    const std::size_t n = 3 * CanonicalSums::kChunk + 17;  // several chunks, the last one partial
    std::vector<Index> id;
    const NeighbourList list = random_list(n, 60, rng, id);
    ASSERT_GT(list.pairs(), 4 * n / 2);
    CanonicalSums sums;
    sums.plan(list, n, false);

    // The ring as the sweep leaves it after the last chunk: slot k at k & mask (a slot overwritten by a
    // later one is read alike by every form), the slot of zeros at ring_slots.
    const std::size_t mask = sums.ring_slots - 1;
    SlotStore ring;
    ring.assign(sums.ring_slots + 1);
    std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
    std::uniform_int_distribution<int> exponent(-30, 30);
    auto value = [&] { return std::ldexp(mantissa(rng), exponent(rng)); };
    for (std::size_t k = 0; k < list.pairs(); ++k) {
        for (double& v : ring.line[k & mask].v) v = value();
        ring.tz[k & mask] = value();
    }

    WallContacts walls;
    walls.init({}, 1e-5, n);
    Particles alone, eight, quads, side_by_side;
    for (Particles* p : {&alone, &eight, &quads, &side_by_side}) {
        p->n = n;
        p->f.assign(3 * n, -1.0);
        p->t.assign(3 * n, -1.0);
    }
    const SlotSource from{ring.view(), ring.view(), mask, 0};
    for (std::size_t s = 0; s < n; ++s) sums.sum_particles(&s, 1, from, list, walls, alone);
    // Side by side in twos, threes and fours, each set out of storage order.
    for (std::size_t s = 0, count = 2; s < n; s += count, count = count % 4 + 2) {
        std::size_t set[CanonicalSums::kGroup];
        const std::size_t c = std::min(count, n - s);
        for (std::size_t l = 0; l < c; ++l) set[l] = s + c - 1 - l;
        sums.sum_particles(set, int(c), from, list, walls, side_by_side);
    }
    std::size_t grouped = 0;
    for (const CanonicalSums::Group& g : sums.by_last.groups) {
        sums.sum_group_eight(sums.by_last, g, ring.view(), walls, eight);
        sums.sum_group_quads(sums.by_last, g, ring.view(), walls, quads);
        grouped += std::size_t(g.count);
    }
    ASSERT_EQ(grouped, n);  // every particle is in one group

    std::size_t with_slots = 0;
    for (std::size_t s = 0; s < n; ++s) {
        with_slots += list.jstart[s + 1] > list.jstart[s] && list.istart[s + 1] > list.istart[s];
        EXPECT_EQ(bits_of(eight, s), bits_of(alone, s)) << "eight lanes, particle " << s;
        EXPECT_EQ(bits_of(quads, s), bits_of(alone, s)) << "quads, particle " << s;
        EXPECT_EQ(bits_of(side_by_side, s), bits_of(alone, s)) << "sum_particles side by side, particle " << s;
    }
    EXPECT_GT(with_slots, n / 2);  // most sums read slots both as j and as i

    // A sum alone against physics.md §6 written out: every slot of particle s, by the other particle's
    // id (as j below s's id, the force subtracted and t_j added; as i above, f and t_i added).
    std::vector<std::vector<std::pair<Index, std::size_t>>> mine(n);  // (other's id, slot)
    for (std::size_t k = 0; k < list.pairs(); ++k) {
        const auto i = std::size_t(list.owner[k]), j = std::size_t(list.partner[k]);
        ASSERT_LT(id[i], id[j]);
        mine[i].push_back({id[j], k});
        mine[j].push_back({id[i], k});
    }
    std::size_t swapped = 0;  // slots whose i comes later in storage than their j
    for (std::size_t k = 0; k < list.pairs(); ++k) swapped += list.owner[k] > list.partner[k];
    EXPECT_GT(swapped, list.pairs() / 4);
    for (std::size_t s = 0; s < n; ++s) {
        std::sort(mine[s].begin(), mine[s].end());
        double f[3] = {0.0, 0.0, 0.0}, t[3] = {0.0, 0.0, 0.0};
        for (const auto& [other, k] : mine[s]) {
            const Slot& slot = ring.line[k & mask];
            const bool as_j = other < id[s];
            const Vec3d fv = slot.f(), tq = as_j ? slot.tj() : ring.ti(k & mask);
            const double fc[3] = {fv.x, fv.y, fv.z}, tc[3] = {tq.x, tq.y, tq.z};
            for (int c = 0; c < 3; ++c) {
                f[c] = as_j ? f[c] - fc[c] : f[c] + fc[c];
                t[c] = t[c] + tc[c];
            }
        }
        std::vector<std::uint64_t> want;
        for (const double* a : {f, t})
            for (int c = 0; c < 3; ++c) {
                std::uint64_t b;
                std::memcpy(&b, &a[c], sizeof b);
                want.push_back(b);
            }
        EXPECT_EQ(bits_of(alone, s), want) << "particle " << s << " against the canonical order written out";
    }
}
