#pragma once
// The fast variant's canonical sums: each particle sums, in the order of physics.md §6, the slots where
// it is j (partners of lower id, ascending), then those where it is i (partners of higher id, ascending),
// then its walls, so that its bits are those of arrays whichever thread sums it, and when. The slots come
// from a thread's ring (the sweep, canonical_sweep.hpp) or from the list of all slots. At each rebuild
// this plans, for the sweep, which chunk's slots each sum waits for, and cuts each chunk's schedule into
// groups of kGroup particles summed side by side.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "heap_bytes.hpp"
#include "neighbour_list.hpp"
#include "pair_kernel.hpp"
#include "particles.hpp"
#include "team.hpp"
#include "wall_contacts.hpp"

namespace demmat::fast {

// Where a sum reads slot k: lo at k & mask below `split`, hi at k & mask from it on (a ring: mask + 1
// slots, plus the slot of zeros; the whole list: mask all ones).
struct SlotSource {
    SlotView lo, hi;
    std::size_t mask, split;
};

class CanonicalSums {
public:
    static constexpr std::size_t kChunk = 128;  // particles per chunk of the sweep
    static constexpr int kGroup = 4;            // particles per sum group (sum_group)
    // Where t_j, f and t_i start in a slot's line (pair_kernel.hpp's Slot), in doubles; t_i.z is not in
    // the line.
    static constexpr std::size_t kTorqueJ = 0, kForce = 3, kTorqueI = 6;

    // A group of sums (sum_group): its particles (-1: none), the longest of their lists as j and as i,
    // and where its table starts in the schedule's table.
    struct Group {
        Index grain[kGroup] = {};
        std::int32_t count = 0, as_j = 0, as_i = 0;
        std::uint32_t table = 0;
    };

    // The sweep's schedule: each chunk's particles in groups (chunk c's from group_start[c]), and the
    // groups' tables of ring places (8·(k & mask) for slot k, the byte where its t_i.z lies, and an
    // eighth of where its line does). A particle is summed with its own chunk, where its last slot is.
    struct Schedule {
        std::vector<Index> group_start;
        std::vector<Group> groups;
        std::vector<std::uint32_t> table;  // at least as long as the groups' tables (it only grows)
        std::size_t bytes() const { return heap_bytes(group_start, groups, table); }
    };

    // Per particle, the chunk where its first slot is stored (its last is in its own chunk).
    std::vector<Index> first_chunk;
    // The sweep's schedule, by each particle's own chunk.
    Schedule by_last;
    // The most chunks from a particle's first slot to its last (the sweep's span), and a ring of
    // ring_slots slots (a power of two) that holds every slot a sum reads: at least the slots of any
    // span_chunks + 1 chunks in a row, where a particle's reach (its first chunk to its last) lies, and
    // where the downward thread's sums read (canonical_sweep.hpp).
    std::size_t span_chunks = 0, ring_slots = 1;

    static std::size_t chunks(std::size_t n) { return (n + kChunk - 1) / kChunk; }
    // The particles of chunk c, [begin, end).
    static std::pair<std::size_t, std::size_t> chunk_range(std::size_t c, std::size_t n) { return {c * kChunk, std::min(n, (c + 1) * kChunk)}; }

    // After a canonical list is built: a particle's sum needs the slots of the chunks from the first
    // where one of its slots is stored (the list's earliest) to its own (a slot is stored with the pair's
    // particle that comes first, so none of a particle's slots lies above it). Each chunk's groups and
    // their tables are planned apart from the others', so the team shares them: the groups first, then,
    // once the tables' lengths are added up and the ring's size known, the tables.
    void plan(const NeighbourList& list, std::size_t n, bool parallel)
    {
        const Index* earliest = list.earliest.data();
        const Index* pstart = list.start.data();
        const std::size_t nch = chunks(n);
        first_chunk.resize(n);
        by_last.group_start.resize(nch + 1);
        for (std::size_t c = 0; c <= nch; ++c) by_last.group_start[c] = Index((std::min(n, c * kChunk) + kGroup - 1) / kGroup);
        by_last.groups.resize(std::size_t(by_last.group_start[nch]));
        rows_.resize(nch + 1);
        if (scratch_.size() < std::size_t(thread_limit())) scratch_.resize(std::size_t(thread_limit()));
        // The most chunks from a particle's first chunk to its last.
        std::atomic<std::size_t> most_chunks{0};
        auto raise = [](std::atomic<std::size_t>& to, std::size_t v) {
            for (std::size_t cur = to.load(std::memory_order_relaxed); v > cur && !to.compare_exchange_weak(cur, v, std::memory_order_relaxed);) {
            }
        };
        in_team(parallel, [&] {
            std::size_t chunks_here = 0;
            Scratch& scratch = scratch_[std::size_t(thread_index())];
#pragma omp for schedule(static) nowait
            for (std::size_t c = 0; c < nch; ++c) {
                const auto [b, e] = chunk_range(c, n);
                for (std::size_t s = b; s < e; ++s) {
                    const std::size_t first = std::size_t(earliest[s]) / kChunk;
                    first_chunk[s] = Index(first);
                    chunks_here = std::max(chunks_here, c - first);
                }
                rows_[c + 1] = group(list, c, n, scratch);
            }
            raise(most_chunks, chunks_here);
        });
        span_chunks = most_chunks.load();
        // The most slots in span_chunks + 1 chunks in a row.
        std::size_t reach = 0;
        for (std::size_t c = 0; c < nch; ++c)
            reach = std::max(reach, std::size_t(pstart[std::min(n, (c + span_chunks + 1) * kChunk)] - pstart[c * kChunk]));
        ring_slots = std::bit_ceil(std::max<std::size_t>(reach, 1));
        // The tables hold places in a ring as 32-bit words.
        if ((ring_slots + 1) * sizeof(double) > std::size_t(UINT32_MAX))
            throw CapacityError(fmt::format("the fast variant's canonical sweep needs a ring of {} slots, more than its 32-bit places "
                                            "reach (the {} chunks a sum reaches over hold up to {} slots)", ring_slots, span_chunks + 1, reach));
        rows_[0] = 0;
        for (std::size_t c = 0; c < nch; ++c) rows_[c + 1] += rows_[c];
        if (rows_[nch] > UINT32_MAX)
            throw CapacityError(fmt::format("the fast variant's canonical sums need {} table entries, more than their 32-bit offsets reach", rows_[nch]));
        if (by_last.table.size() < rows_[nch]) by_last.table.resize(rows_[nch]);
        in_team(parallel, [&] {
#pragma omp for schedule(static)
            for (std::size_t c = 0; c < nch; ++c) tabulate(list, c);
        });
    }

    // The sums of up to kGroup particles (grain[0 … count)) from `from`, side by side, each with its
    // walls added and stored in p's f and t (Newton's law comes in the next step's pass, vectorised, with
    // the corrector: here, a grain at a time, its scalar divisions would lengthen the force pass). For
    // the sums the groups' tables cannot name (those that read two rings, or the list of all slots): the
    // slots are looked up from the particles' lists as they are read. As in sum_group, a chain of
    // additions per particle, the chains side by side, and a list that ends early goes on with a slot of
    // zeros, which adds nothing. The three components of a sum go as lanes of one quad (lane by lane,
    // the scalar additions; x - y is x + (-y)); add_as_j and add_as_i read them.
    void sum_particles(const std::size_t* grain, int count, const SlotSource& from, const NeighbourList& list, const WallContacts& walls,
                       Particles& p) const
    {
        static constexpr Slot kZeros{};
        const std::size_t mask = from.mask, split = from.split;
        auto at = [&](Index k) {  // slot k: its line and its t_i.z
            const SlotView& v = std::size_t(k) < split ? from.lo : from.hi;
            const std::size_t i = std::size_t(k) & mask;
            return std::pair<const double*, double>{v.line[i].v, v.tz[i]};
        };
        const Index* as_j = list.as_j.data();
        const Index* as_i = list.as_i.data();
        Index j0[kGroup], jn[kGroup], i0[kGroup], in[kGroup], most_j = 0, most_i = 0;  // each list's start and length
        Quad f[kGroup], tq[kGroup];
        for (int l = 0; l < kGroup; ++l) {
            const std::size_t s = grain[l < count ? l : 0];
            j0[l] = list.jstart[s];
            i0[l] = list.istart[s];
            jn[l] = l < count ? list.jstart[s + 1] - j0[l] : 0;
            in[l] = l < count ? list.istart[s + 1] - i0[l] : 0;
            most_j = std::max(most_j, jn[l]);
            most_i = std::max(most_i, in[l]);
            f[l] = tq[l] = Quad{};
        }
        for (Index e = 0; e < most_j; ++e)
            for (int l = 0; l < kGroup; ++l) add_as_j(e < jn[l] ? at(as_j[j0[l] + e]).first : kZeros.v, f[l], tq[l]);
        for (Index e = 0; e < most_i; ++e)
            for (int l = 0; l < kGroup; ++l) {
                const auto [line, tz] = e < in[l] ? at(as_i[i0[l] + e]) : std::pair<const double*, double>{kZeros.v, 0.0};
                add_as_i(line, tz, f[l], tq[l]);
            }
        for (int l = 0; l < count; ++l) {
            walls.add(grain[l], f[l], tq[l]);
            p.store_sum(grain[l], f[l], tq[l]);
        }
    }

    // The sums of a group of up to kGroup particles of one chunk's schedule, side by side: a chain of
    // additions per particle, all from the ring. One particle's sum alone is a chain of
    // dependent additions ended by two loop exits whose trip counts no predictor learns; here the chains
    // overlap and a group has two exits. The group's table (schedule()) holds the ring places in the
    // canonical order, as j then as i, a row of kGroup a step; a particle's list that ends before the
    // group's longest goes on with the ring's slot of zeros, which adds nothing (the sum starts at +0 and
    // is never -0, and x + ±0 = x for every other x), so each particle's bits are those of its sum alone
    // (sum_particles, which looks its slots up in the lists, for the sums that read two rings or the
    // list of all slots, which the tables' ring places cannot name).
    // Where vectors have eight lanes (AVX-512) a particle's force and torque are one vector, and each
    // slot it reads one load of its line (sum_group_eight). Where they are narrower, a vector of eight
    // is two registers and four sums with their inputs would not fit the register file, so the force
    // and the torque are a quad each (sum_group_quads). The same additions either way, lane by lane.
    void sum_group(const Schedule& from, const Group& g, const SlotView& ring, const WallContacts& walls, Particles& p) const
    {
        if constexpr (kLanes >= 8)
            sum_group_eight(from, g, ring, walls, p);
        else
            sum_group_quads(from, g, ring, walls, p);
    }

    // The two forms, public so that tests/test_canonical_sums.cpp runs both on any machine (a build
    // runs only the one its target's width picks).
    // As j, a slot's line is added whole, its force's sign flipped (x - f bit for bit): the lanes hold
    // the torque (t_j), then the force, then two unused. As i, the torque's x and y move to the last
    // two lanes, under t_i.x and t_i.y in the line, its z to a scalar, which adds t_i.z; the first
    // three lanes are then unused. Unused lanes add values that are never read.
    void sum_group_eight(const Schedule& from, const Group& g, const SlotView& ring, const WallContacts& walls, Particles& p) const
    {
        using Eight = Pack<double, 8>;
        using Bits = Pack<std::uint64_t, 8>;
        constexpr std::uint64_t kSign = std::uint64_t(1) << 63;
        constexpr Bits flip_force = {0, 0, 0, kSign, kSign, kSign, 0, 0};
        const char* lines = reinterpret_cast<const char*>(ring.line);
        const char* tz = reinterpret_cast<const char*>(ring.tz);
        // Through a reference, not a return value: a returned vector of 64 bytes has its own ABI
        // without AVX-512 (GCC's -Wpsabi), though the call is always inlined.
        auto load = [](Eight& v, const char* at) { std::memcpy(&v, at, sizeof(v)); };
        const std::uint32_t* row = from.table.data() + g.table;
        Eight sum[kGroup];
        double z[kGroup];
        for (int l = 0; l < kGroup; ++l) sum[l] = Eight{};  // element by element, as in sum_group_quads
        for (std::int32_t e = 0; e < g.as_j; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) {
                Eight v;
                load(v, lines + 8 * std::size_t(row[l]));
                sum[l] += Eight(Bits(v) ^ flip_force);
            }
        for (int l = 0; l < kGroup; ++l) {
            z[l] = sum[l][2];
            sum[l] = __builtin_shufflevector(sum[l], sum[l], 0, 1, 2, 3, 4, 5, 0, 1);
        }
        for (std::int32_t e = 0; e < g.as_i; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) {
                Eight v;
                load(v, lines + 8 * std::size_t(row[l]));
                sum[l] += v;
                double w;
                std::memcpy(&w, tz + row[l], sizeof(w));
                z[l] += w;
            }
        for (int l = 0; l < g.count; ++l) {
            const std::size_t s = std::size_t(g.grain[l]);
            Quad f = __builtin_shufflevector(sum[l], sum[l], 3, 4, 5, 0), tq = {sum[l][6], sum[l][7], z[l], 0.0};
            walls.add(s, f, tq);
            p.store_sum(s, f, tq);
        }
    }

    // The force and the torque a quad each, slot by slot as sum_particles adds them.
    void sum_group_quads(const Schedule& from, const Group& g, const SlotView& ring, const WallContacts& walls, Particles& p) const
    {
        const char* lines = reinterpret_cast<const char*>(ring.line);
        const char* tz = reinterpret_cast<const char*>(ring.tz);
        auto line = [lines](std::uint32_t at) { return reinterpret_cast<const double*>(lines + 8 * std::size_t(at)); };
        auto z = [tz](std::uint32_t at) { return *reinterpret_cast<const double*>(tz + at); };
        const std::uint32_t* row = from.table.data() + g.table;
        // Zeroed element by element: `{}` on the arrays is a block clear, which GCC may emit as `rep stos`,
        // slow to start for a few vectors (it showed in perf); vector by vector it is a register clear.
        Quad f[kGroup], tq[kGroup];
        for (int l = 0; l < kGroup; ++l) f[l] = tq[l] = Quad{};
        for (std::int32_t e = 0; e < g.as_j; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) add_as_j(line(row[l]), f[l], tq[l]);
        for (std::int32_t e = 0; e < g.as_i; ++e, row += kGroup)
            for (int l = 0; l < kGroup; ++l) add_as_i(line(row[l]), z(row[l]), f[l], tq[l]);
        for (int l = 0; l < g.count; ++l) {
            const std::size_t s = std::size_t(g.grain[l]);
            walls.add(s, f[l], tq[l]);
            p.store_sum(s, f[l], tq[l]);
        }
    }

    std::size_t bytes() const
    {
        return heap_bytes(first_chunk, rows_) + scratch_.bytes() + by_last.bytes();
    }

private:
    // One chunk's particles while they are grouped, and the counting sort's places (a thread's own).
    struct Scratch {
        std::vector<Index> grain, at;
        std::size_t bytes() const { return heap_bytes(grain, at); }
    };

    // One slot (its line, and t_i.z) into a particle's force and torque as quads, each read as the quad
    // that starts at it in the line (the fourth lane, the next value along, is not used): as j, the
    // force subtracted and t_j added; as i, the force and t_i added.
    [[gnu::always_inline]] static void add_as_j(const double* line, Quad& f, Quad& tq)
    {
        Quad q;
        load_quad(q, line + kForce);
        f -= q;
        load_quad(q, line + kTorqueJ);
        tq += q;
    }
    [[gnu::always_inline]] static void add_as_i(const double* line, double tz, Quad& f, Quad& tq)
    {
        Quad q;
        load_quad(q, line + kForce);
        f += q;
        tq += Quad{line[kTorqueI], line[kTorqueI + 1], tz, 0.0};
    }

    // Chunk c's particles in groups of kGroup (by_last.groups from group_start[c]), each group with its
    // particles and the longest of their lists as j and as i; returns the length of the chunk's tables.
    // The particles by count as j, and within a count by count as i, ascending for an even count as j
    // and descending for an odd one: a group that straddles two counts as j then takes its lists as i
    // from the same end of both, so that fewer are padded (the groups' rows are the longest list of
    // each kind). A stable counting sort by that key, of the chunk's particles in storage order.
    std::size_t group(const NeighbourList& list, std::size_t c, std::size_t n, Scratch& scratch)
    {
        const Index* jstart = list.jstart.data();
        const Index* istart = list.istart.data();
        const auto [b, e] = chunk_range(c, n);
        const std::size_t size = e - b;
        std::size_t most_i = 0;
        for (std::size_t s = b; s < e; ++s) most_i = std::max(most_i, std::size_t(istart[s + 1] - istart[s]));
        auto key_of = [&](std::size_t s) {
            const std::size_t j = std::size_t(jstart[s + 1] - jstart[s]), i = std::size_t(istart[s + 1] - istart[s]);
            return j * (most_i + 1) + (j % 2 == 0 ? i : most_i - i);
        };
        std::size_t most = 0;
        for (std::size_t s = b; s < e; ++s) most = std::max(most, key_of(s));
        scratch.at.assign(most + 2, 0);
        for (std::size_t s = b; s < e; ++s) ++scratch.at[key_of(s) + 1];
        for (std::size_t k = 0; k <= most; ++k) scratch.at[k + 1] += scratch.at[k];
        scratch.grain.resize(size);
        for (std::size_t s = b; s < e; ++s) scratch.grain[std::size_t(scratch.at[key_of(s)]++)] = Index(s);
        Group* g = by_last.groups.data() + by_last.group_start[c];
        std::size_t rows = 0;
        for (std::size_t g0 = 0; g0 < size; g0 += kGroup, ++g) {
            *g = Group{};
            g->count = std::int32_t(std::min<std::size_t>(kGroup, size - g0));
            for (int l = 0; l < kGroup; ++l) {
                const Index s = l < g->count ? scratch.grain[g0 + std::size_t(l)] : -1;
                g->grain[l] = s;
                if (s < 0) continue;
                g->as_j = std::max(g->as_j, jstart[s + 1] - jstart[s]);
                g->as_i = std::max(g->as_i, istart[s + 1] - istart[s]);
            }
            rows += std::size_t(g->as_j + g->as_i) * kGroup;
        }
        return rows;
    }

    // Chunk c's groups' tables, from rows_[c] on: a row of ring places a step, the lists as j to the
    // group's longest, then as i, padded with the place of the ring's slot of zeros (ring_slots).
    void tabulate(const NeighbourList& list, std::size_t c)
    {
        const Index* jstart = list.jstart.data();
        const Index* as_j = list.as_j.data();
        const Index* istart = list.istart.data();
        const Index* as_i = list.as_i.data();
        const std::size_t mask = ring_slots - 1;
        auto place = [mask](Index k) { return std::uint32_t((std::size_t(k) & mask) * sizeof(double)); };
        const std::uint32_t zeros = std::uint32_t(ring_slots * sizeof(double));
        std::size_t at = rows_[c];
        for (Index q = by_last.group_start[c]; q < by_last.group_start[c + 1]; ++q) {
            Group& g = by_last.groups[std::size_t(q)];
            g.table = std::uint32_t(at);
            std::uint32_t* rows = by_last.table.data() + at;
            at += std::size_t(g.as_j + g.as_i) * kGroup;
            // The slot of zeros wherever a list has ended, then each list down its column.
            std::fill(rows, by_last.table.data() + at, zeros);
            for (int l = 0; l < g.count; ++l) {
                const Index s = g.grain[l];
                for (Index e = 0; e < jstart[s + 1] - jstart[s]; ++e) rows[std::size_t(e) * kGroup + std::size_t(l)] = place(as_j[jstart[s] + e]);
                for (Index e = 0; e < istart[s + 1] - istart[s]; ++e)
                    rows[std::size_t(g.as_j + e) * kGroup + std::size_t(l)] = place(as_i[istart[s] + e]);
            }
        }
    }

    PerThread<Scratch> scratch_;
    std::vector<std::size_t> rows_;  // per chunk, where its groups' tables start (plan())
};
static_assert(sizeof(Slot) == 8 * sizeof(double) && CanonicalSums::kTorqueI + 2 == 8);

} // namespace demmat::fast
