#pragma once
// The fast variant's options and its few extra observables, for the tests (the registry creates it with
// the defaults; the Variant interface knows no options).
#include <cstddef>
#include <cstdint>
#include <memory>

#include "demmat/variant.hpp"

namespace demmat {

struct FastOptions {
    // Neighbour-list skin in units of R_max: pairs closer than R_i + R_j + skin are listed, and the list
    // is rebuilt (particles re-sorted into cell order) when twice the largest displacement since the
    // last rebuild passes 0.9·skin (walls need no list: each is tested every step). 0 rebuilds every step.
    double skin = 0.3;
    // true: each particle's force is summed in the canonical order of physics.md §6 (bit-identical to
    // arrays for any thread count). false: plain accumulation in storage order, each pair's force added
    // to both particles as it is computed (the trajectory differs from arrays in the last bits).
    bool canonical = true;
    // Below this many particles the variant runs on one thread whatever the thread count: a fork and
    // join per phase costs more than the work it shares (docs/variants/fast.md). The tests set 0, so
    // that their small scenes run on the threads they ask for.
    std::size_t min_parallel = 3000;
    // From this many particles on the pair kernel prefetches its partners' records (docs/variants/engine.md:
    // a hint to the caches, which changes no result). The tests set 0, so that their small
    // scenes take that path too.
    std::size_t prefetch_from = 8000;
    // From this many particles on, predict()'s pass writes the kernels' records with non-temporal stores
    // (Particles::refresh_records): well past the last-level cache the records leave it before the force
    // pass reads them, and a plain store first reads each line it overwrites; nearer the cache's size
    // they would have stayed (docs/variants/engine.md; no result changes). The tests set 0, so that
    // their small scenes take that path too.
    std::size_t stream_records_from = 48000;
};

class FastVariant : public Variant {
public:
    virtual std::int64_t rebuilds() const = 0;  // neighbour-list rebuilds since init (init's own included)
};

std::unique_ptr<FastVariant> make_fast_variant(const FastOptions& options);

} // namespace demmat
