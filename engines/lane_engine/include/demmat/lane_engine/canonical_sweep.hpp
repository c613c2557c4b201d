#pragma once
// The fast variant's force pass in the canonical order: the pair kernel and the canonical sums in one
// sweep over the storage order, a chunk at a time, so that each particle's slots are summed from a small
// per-thread ring that stays in cache (slot k at k mod R), not from a list of them all, written to
// memory and read back every step. A piece of the storage (one per two threads) is swept by two threads,
// chunk by chunk, one upwards from its start and one downwards from its end, until they meet wherever
// the machine lets them (neither waits for the other). After each chunk c, the upward thread sums the
// particles of c (their last slot, as i or as j, is in it), the downward one those of c + span (no sum
// reaches back more than span chunks, so all their slots are in c … c + span, now swept). The others,
// those of the span chunks above the meeting point and those that reach into the piece before, are
// summed after the sweep. Which thread sums a particle, and when, changes no bit of its sum. A chunk's
// wall contacts are computed with its pairs, so that the sums find their results in cache: every
// particle's walls are computed with its own chunk, swept before its sum.
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "canonical_sums.hpp"
#include "heap_bytes.hpp"
#include "neighbour_list.hpp"
#include "pair_kernel.hpp"
#include "particles.hpp"
#include "team.hpp"
#include "wall_contacts.hpp"

namespace demmat::fast {

class CanonicalSweep {
public:
    struct Counts {
        std::int64_t pairs = 0, walls = 0;  // contacts found
        std::size_t team = 1;               // the threads that ran it
    };

    template <class M>
    Counts run(const NeighbourList& list, CanonicalSums& sums, WallContacts& walls, Particles& p, const LawInputs& law,
               Quad* stretches, bool prefetch, bool parallel)
    {
        constexpr std::size_t kChunk = CanonicalSums::kChunk;
        const std::size_t n = p.n;
        std::atomic<std::int64_t> pp{0}, pw{0};
        std::size_t team = 1;
        const Index* pstart = list.start.data();
        const Index* first_chunk = sums.first_chunk.data();
        const std::size_t chunks = CanonicalSums::chunks(n), span = sums.span_chunks, ring_slots = sums.ring_slots;
        const std::size_t limit = std::size_t(thread_limit());
        if (nclaims_ < limit) {
            claims_ = std::make_unique<Claim[]>(limit);
            nclaims_ = limit;
        }
        if (rings_.size() < limit) rings_.resize(limit);
        const PairKernel<M> kernel(list, p, law, stretches, prefetch);
        in_team(parallel, [&] {
            const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
            if (t == 0) team = nt;
            // Two threads to a piece, one from each end; an odd thread count leaves the last piece one.
            const std::size_t pieces = (nt + 1) / 2, pc = t / 2;
            const bool down = t % 2 == 1;
            // No barrier after the single: the rings below do not read what it sets, and the barrier after
            // them waits for it (a barrier costs a system call, and the slower thread's wait).
#pragma omp single nowait
            {
                cut_pieces(list, pieces, chunks);
                for (std::size_t q = 0; q < pieces; ++q) claims_[q].reset(piece_chunk_[q], piece_chunk_[q + 1]);
                if (pieces > 1 && all_.size() < list.pairs()) all_.assign(list.pairs());
            }
            SlotStore& ring = rings_[t];
            // + 1: the slot of zeros at ring_slots (the groups' padding).
            if (ring.size() < ring_slots + 1) ring.assign(ring_slots + 1);
            ring.zero(ring_slots);  // a larger ring from before may hold a slot there
            // The kernel's records and every list of wall candidates are ready (predict(), or a rebuild).
            std::int64_t my_pp = 0, my_pw = 0;  // this thread's contacts, added to pp and pw once
#pragma omp barrier
            const std::size_t c0 = piece_chunk_[pc], c1 = piece_chunk_[pc + 1];
            const SlotSink in_ring{ring.view(), ring_slots - 1, {}};
            for (std::size_t ch; down ? claims_[pc].down(ch) : claims_[pc].up(ch);) {
                // Slots near the end of a piece are also kept in all_, for the sums that straddle two pieces.
                const bool edge = (pc > 0 && ch < c0 + span) || (pc + 1 < pieces && ch + span >= c1);
                const SlotSink sink{in_ring.ring, in_ring.mask, edge ? all_.view() : SlotView{}};
                const std::size_t k0 = std::size_t(pstart[ch * kChunk]), k1 = std::size_t(pstart[std::min(n, (ch + 1) * kChunk)]);
                // The downward thread goes on with the chunk below: the prefetches past this one go there.
                const std::size_t next = down && ch > c0 ? std::size_t(pstart[(ch - 1) * kChunk]) : k1;
                my_pp += kernel.template run<true>(k0, k1, nullptr, sink, next);
                if constexpr (M::walls) my_pw += walls.compute_range<M>(p, law, ch * kChunk, std::min(n, (ch + 1) * kChunk));
                const CanonicalSums::Schedule& schedule = sums.by_last;
                if (down) {  // the particles of ch + span, each slot of theirs in ch … ch + span, in this piece
                    const std::size_t last = ch + span;
                    if (last < c1)
                        for (Index q = schedule.group_start[last]; q < schedule.group_start[last + 1]; ++q)
                            sums.sum_group(schedule, schedule.groups[std::size_t(q)], in_ring.ring, walls, p);
                    continue;
                }
                // The groups of this chunk; a group with a particle that reaches into the piece before
                // (three threads or more) goes a particle at a time, without that one.
                const SlotSource from{in_ring.ring, in_ring.ring, in_ring.mask, 0};
                for (Index q = schedule.group_start[ch]; q < schedule.group_start[ch + 1]; ++q) {
                    const CanonicalSums::Group& g = schedule.groups[std::size_t(q)];
                    auto inside = [&](Index s) { return std::size_t(first_chunk[s]) >= c0; };
                    bool all = pieces == 1;  // one piece (one or two threads): every sum is inside
                    if (!all) {
                        all = true;
                        for (int l = 0; l < g.count; ++l) all = all && inside(g.grain[l]);
                    }
                    if (all) {
                        sums.sum_group(schedule, g, in_ring.ring, walls, p);
                        continue;
                    }
                    std::size_t mine[CanonicalSums::kGroup];
                    int count = 0;
                    for (int l = 0; l < g.count; ++l)
                        if (inside(g.grain[l])) mine[count++] = std::size_t(g.grain[l]);
                    if (count > 0) sums.sum_particles(mine, count, from, list, walls, p);
                }
            }
#pragma omp barrier
            {
                // The particles of this piece not yet summed, those of the span chunks from its meeting
                // point m on (the downward thread summed those above): their slots below m are in the
                // upward thread's ring, those from m on in the downward one's (each holds the last
                // ring_slots it wrote, and no sum reaches over more). The piece's two threads take half
                // of them each, counted (a cut by chunk would leave most to one thread), in runs (not
                // every other one: neighbours in storage share the cache lines of the sums they store),
                // kGroup side by side. A piece of one thread met at its end.
                const std::size_t m = claims_[pc].met();
                const std::size_t up = down ? t - 1 : t, other = !down && t + 1 == nt ? t : up + 1;
                const SlotSource split{rings_[up].view(), rings_[other].view(), ring_slots - 1, std::size_t(pstart[std::min(n, m * kChunk)])};
                const std::size_t e1 = std::min(c1, m + span);
                auto for_each_straddler = [&](auto&& f) {
                    for (std::size_t s = m * kChunk; s < std::min(n, e1 * kChunk); ++s)
                        if (std::size_t(first_chunk[s]) >= c0) f(s);  // not those that reach into the piece before
                };
                std::size_t count = 0, at = 0;
                for_each_straddler([&](std::size_t) { ++count; });
                const std::size_t from = down ? count / 2 : 0, to = down ? count : count / 2;
                Batch batch(sums, split, list, walls, p);
                for_each_straddler([&](std::size_t s) {
                    if (at >= from && at < to) batch.add(s);
                    ++at;
                });
            }
            if (!down && pc > 0) {
                // Those whose first slot is in the piece before (all_ holds all the slots they read).
                const SlotSource everything{all_.view(), all_.view(), ~std::size_t(0), 0};
                const std::size_t b0 = piece_chunk_[pc - 1];
                Batch batch(sums, everything, list, walls, p);
                for (std::size_t s = c0 * kChunk; s < std::min(n, (c0 + span + 1) * kChunk); ++s) {
                    const std::size_t f = std::size_t(first_chunk[s]);
                    if (f >= b0 && f < c0) batch.add(s);
                }
            }
            pp += my_pp;
            pw += my_pw;
        });
        return {pp.load(), pw.load(), team};
    }

    std::size_t bytes() const { return heap_bytes(piece_chunk_, rings_) + all_.bytes() + nclaims_ * sizeof(Claim); }

private:
    // The sums that straddle a meeting point or two pieces, as they are found, kGroup side by side
    // (sum_particles); the last few when it goes.
    class Batch {
    public:
        Batch(const CanonicalSums& sums, const SlotSource& from, const NeighbourList& list, const WallContacts& walls, Particles& p)
            : sums_(sums), from_(from), list_(list), walls_(walls), p_(p)
        {
        }
        Batch(const Batch&) = delete;
        Batch& operator=(const Batch&) = delete;
        ~Batch() { flush(); }
        void add(std::size_t s)
        {
            grain_[count_++] = s;
            if (count_ == CanonicalSums::kGroup) flush();
        }

    private:
        void flush()
        {
            if (count_ > 0) sums_.sum_particles(grain_, count_, from_, list_, walls_, p_);
            count_ = 0;
        }
        const CanonicalSums& sums_;
        const SlotSource& from_;
        const NeighbourList& list_;
        const WallContacts& walls_;
        Particles& p_;
        std::size_t grain_[CanonicalSums::kGroup];
        int count_ = 0;
    };

    // piece_chunk_[q], q = 0 … pieces: where each piece of the sweep starts, in chunks, cut so that the
    // pieces hold about as many slots each.
    void cut_pieces(const NeighbourList& list, std::size_t pieces, std::size_t chunks)
    {
        piece_chunk_.resize(pieces + 1);
        const std::size_t total = list.pairs();
        std::size_t ch = 0;
        piece_chunk_[0] = 0;
        for (std::size_t q = 1; q < pieces; ++q) {
            const std::size_t want = total * q / pieces;
            while (ch < chunks && std::size_t(list.start[ch * CanonicalSums::kChunk]) < want) ++ch;
            piece_chunk_[q] = ch;
        }
        piece_chunk_[pieces] = chunks;
    }

    std::vector<std::size_t> piece_chunk_;
    std::unique_ptr<Claim[]> claims_;  // per piece
    std::size_t nclaims_ = 0;
    PerThread<SlotStore> rings_;
    SlotStore all_;                 // every slot, where the sums that straddle two pieces read (several pieces)
};

} // namespace demmat::fast
