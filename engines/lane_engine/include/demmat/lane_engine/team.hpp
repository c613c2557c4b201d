#pragma once
// The fast variant's threads: who is in the team, each thread's share of the particles, and the claims
// through which two threads sweep a piece of the storage from its two ends (canonical_sweep.hpp).
// Serial where OpenMP is missing.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "heap_bytes.hpp"

namespace demmat::fast {

#ifdef _OPENMP
inline int thread_index() { return omp_get_thread_num(); }
inline int thread_count() { return omp_get_num_threads(); }
inline int thread_limit() { return omp_get_max_threads(); }
#else
inline int thread_index() { return 0; }
inline int thread_count() { return 1; }
inline int thread_limit() { return 1; }
#endif

// This thread's share of n particles, [lo, hi) (inside a parallel region; all of them outside).
inline std::pair<std::size_t, std::size_t> thread_range(std::size_t n)
{
    const std::size_t nt = std::size_t(thread_count()), t = std::size_t(thread_index());
    return {n * t / nt, n * (t + 1) / nt};
}

// Runs body() on a team of threads where `parallel` asks for one and OpenMP may give more than one
// thread; otherwise on this thread alone, outside any parallel region. libgomp makes a team of one all
// the same (`#pragma omp parallel if (false)` too), and every barrier of a team (a region's end, a
// single's, an explicit one) ends in a futex wake, a system call, each step. Alone, the body's directives
// are orphaned and cost nothing: a barrier or a single is no wait, a worksharing loop runs its whole
// range, thread_count() is 1. What a body sums across threads it adds to shared atomics, not through a
// reduction clause, so that both ways run the same code.
template <class Body>
void in_team(bool parallel, Body&& body)
{
#ifdef _OPENMP
    if (parallel && omp_get_max_threads() > 1) {
#pragma omp parallel
        body();
        return;
    }
#endif
    body();
}

// Where each of `team` threads' shares ends (thread_range's ends).
inline std::size_t range_end(std::size_t n, std::size_t u, std::size_t team) { return n * (u + 1) / team; }

// One T per thread (a list it grows, its ring, its loads), each on cache lines of its own. Side by side
// in a plain vector, two threads' vector headers would share a line, and each push_back or resize by
// one would take that line from the other (false sharing): the list's scan ran no faster on two
// threads than on one.
template <class T>
class PerThread {
public:
    std::size_t size() const { return cells_.size(); }
    void resize(std::size_t threads) { cells_.resize(threads); }
    T& operator[](std::size_t t) { return cells_[t].value; }
    const T& operator[](std::size_t t) const { return cells_[t].value; }
    std::size_t bytes() const
    {
        std::size_t b = cells_.capacity() * sizeof(Cell);
        for (const Cell& c : cells_) b += heap_bytes(c.value);
        return b;
    }

private:
    struct alignas(64) Cell {
        T value;
    };
    std::vector<Cell> cells_;
};

// A piece's claims: the next chunk up (low 32 bits) and one past the next chunk down (high 32 bits);
// the sweep ends where they meet. One cache line each.
struct alignas(64) Claim {
    std::atomic<std::uint64_t> v{0};

    void reset(std::size_t begin, std::size_t end) { v.store(std::uint64_t(end) << 32 | std::uint64_t(begin), std::memory_order_relaxed); }
    // Where the two ends met (once the sweep is over).
    std::size_t met() const { return std::size_t(v.load(std::memory_order_relaxed) & 0xffffffffu); }

    bool up(std::size_t& ch)
    {
        std::uint64_t cur = v.load(std::memory_order_relaxed);
        for (;;) {
            const std::uint64_t lo = cur & 0xffffffffu, hi = cur >> 32;
            if (lo >= hi) return false;
            if (v.compare_exchange_weak(cur, hi << 32 | (lo + 1), std::memory_order_relaxed)) {
                ch = std::size_t(lo);
                return true;
            }
        }
    }
    bool down(std::size_t& ch)
    {
        std::uint64_t cur = v.load(std::memory_order_relaxed);
        for (;;) {
            const std::uint64_t lo = cur & 0xffffffffu, hi = cur >> 32;
            if (lo >= hi) return false;
            if (v.compare_exchange_weak(cur, (hi - 1) << 32 | lo, std::memory_order_relaxed)) {
                ch = std::size_t(hi - 1);
                return true;
            }
        }
    }
};

} // namespace demmat::fast
