#pragma once
// The host backend: the cuda variant's kernels (kernels.hpp) on the CPU, one thread at a time, the
// grid's blocks in a shuffled order and each block's threads in a shuffled order, both drawn from a
// seeded generator at every launch. A GPU runs blocks in an order nobody chooses; a kernel whose
// result depended on it would give different bits for different seeds here, which the tests check.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

namespace demmat::gpu {

class HostBackend {
public:
    struct Options {
        std::uint64_t seed = 1;
        unsigned threads_per_block = 128;
    };
    explicit HostBackend(Options o) : opt_(o), rng_(o.seed) {}

    template <class T>
    T* alloc(std::size_t count)
    {
        blocks_.emplace_back(std::make_unique<unsigned char[]>(std::max<std::size_t>(count, 1) * sizeof(T)));  // zeroed
        bytes_ += count * sizeof(T);
        return reinterpret_cast<T*>(blocks_.back().get());
    }
    void release()
    {
        blocks_.clear();
        bytes_ = 0;
    }
    template <class T>
    void upload(T* dst, const T* src, std::size_t count) { if (count) std::memcpy(dst, src, count * sizeof(T)); }
    template <class T>
    void download(T* dst, const T* src, std::size_t count) const { if (count) std::memcpy(dst, src, count * sizeof(T)); }
    void sync() {}
    std::size_t bytes() const { return bytes_; }

    template <class Body>
    void launch(std::uint64_t count, const Body& body)
    {
        const unsigned dim = opt_.threads_per_block;
        const std::uint64_t blocks = (count + dim - 1) / dim;
        order_.resize(blocks);
        std::iota(order_.begin(), order_.end(), std::uint64_t(0));
        std::shuffle(order_.begin(), order_.end(), rng_);
        threads_.resize(dim);
        std::iota(threads_.begin(), threads_.end(), 0u);
        std::shuffle(threads_.begin(), threads_.end(), rng_);
        for (std::uint64_t b : order_)
            for (unsigned t : threads_) body(unsigned(b), t, dim);
    }

    // Keys are distinct, so the sorted order is unique: any correct sort gives the device's result.
    void sort(const std::uint64_t* key, std::uint64_t* key_out, const std::uint32_t* val, std::uint32_t* val_out, std::size_t n, int)
    {
        pairs_.resize(n);
        for (std::size_t i = 0; i < n; ++i) pairs_[i] = {key[i], val[i]};
        std::sort(pairs_.begin(), pairs_.end());
        for (std::size_t i = 0; i < n; ++i) {
            key_out[i] = pairs_[i].first;
            val_out[i] = pairs_[i].second;
        }
    }

private:
    Options opt_;
    std::mt19937_64 rng_;
    std::vector<std::unique_ptr<unsigned char[]>> blocks_;
    std::size_t bytes_ = 0;
    std::vector<std::uint64_t> order_;
    std::vector<unsigned> threads_;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> pairs_;
};

} // namespace demmat::gpu
