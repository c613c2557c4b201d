#pragma once
// The eigen_soa variant's contact memory (physics.md §9): the stretches of the contacts that were live
// at the last force evaluation, in compressed rows like its neighbour store (row i: particle i's
// contacts with partners j > i, or with walls in a second store, keys ascending), the components in Eigen
// arrays of shape (K, 3), K = N·cap, column-major like every other per-particle vector of the variant:
//   offset (N + 1)   row i is [offset(i), offset(i + 1))
//   key    (K)       partner id j, or wall index
//   t, r   (K, 3)    tangential and rolling stretch (only those the law has)
// Each evaluation reads the rows of the previous one by key and writes a new set, then the two swap: a
// contact found again takes its stretch, a new one starts at zero, one that opened is not written and so
// forgotten. Keyed by the partner, not by a slot, the store is the same whatever the search found.
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "demmat/contact_memory.hpp"
#include "demmat/state.hpp"

namespace demmat::eigen_soa {

class StretchRows {
public:
    using Index = std::int32_t;
    using IndexArr = Eigen::Array<Index, Eigen::Dynamic, 1>;
    using Arr3 = Eigen::Array<double, Eigen::Dynamic, 3, Eigen::ColMajor>;

private:
    struct Rows {
        IndexArr offset, key;
        Arr3 t, r;
    };

public:
    void reset(Eigen::Index n, Index cap, bool tangential, bool rolling)
    {
        n_ = n;
        for (Rows* r : {&cur_, &next_}) {
            r->offset.setZero(n + 1);
            r->key.setZero(n * cap);
            r->t.setZero(tangential ? n * cap : 0, 3);
            r->r.setZero(rolling ? n * cap : 0, 3);
        }
    }

    // Row i of the previous evaluation, read by ascending key: take(key) for keys in ascending order.
    class Reader {
    public:
        Reader(const StretchRows& s, Eigen::Index i) : r_(s.cur_), k_(r_.offset(i)), end_(r_.offset(i + 1)) {}
        Stretch<double> take(Index key)
        {
            while (k_ < end_ && r_.key(k_) < key) ++k_;
            if (k_ == end_ || r_.key(k_) != key) return {};
            return get(r_, k_);
        }

    private:
        const Rows& r_;
        Index k_, end_;
    };
    Reader reader(Eigen::Index i) const { return Reader(*this, i); }

    // This evaluation's rows, in particle order: begin_row(i), then put() in ascending key order.
    void begin_row(Eigen::Index i) { next_.offset(i) = used_; }
    void put(Index key, const Stretch<double>& s)
    {
        next_.key(used_) = key;
        if (next_.t.rows() > 0) next_.t.row(used_) << s.t.x, s.t.y, s.t.z;
        if (next_.r.rows() > 0) next_.r.row(used_) << s.r.x, s.r.y, s.r.z;
        ++used_;
    }
    void finish_evaluation()
    {
        next_.offset(n_) = used_;
        used_ = 0;
        std::swap(cur_, next_);
    }

    // The live contacts as a state holds them (ids, never slots), `wall` marking the wall store.
    void save(std::vector<ContactStretch>& out, bool wall) const
    {
        for (Eigen::Index i = 0; i < n_; ++i)
            for (Index k = cur_.offset(i); k < cur_.offset(i + 1); ++k) {
                const Stretch<double> s = get(cur_, k);
                out.push_back({std::int64_t(i), std::int64_t(cur_.key(k)), wall, s.t, s.r});
            }
    }
    // From a state: its contacts of this store's kind, in canonical order (so each row ascends). False
    // when they do not fit in the rows' capacity.
    bool load(const std::vector<ContactStretch>& in, bool wall)
    {
        Index used = 0;
        Eigen::Index row = 0;
        cur_.offset(0) = 0;
        for (const ContactStretch& c : in) {
            if (c.wall != wall) continue;
            if (used == cur_.key.size()) return false;
            for (; row < c.i; ++row) cur_.offset(row + 1) = used;
            cur_.key(used) = Index(c.partner);
            if (cur_.t.rows() > 0) cur_.t.row(used) << c.tangential.x, c.tangential.y, c.tangential.z;
            if (cur_.r.rows() > 0) cur_.r.row(used) << c.rolling.x, c.rolling.y, c.rolling.z;
            ++used;
        }
        for (; row < n_; ++row) cur_.offset(row + 1) = used;
        return true;
    }

    std::size_t memory_bytes() const
    {
        std::size_t bytes = 0;
        for (const Rows* r : {&cur_, &next_})
            bytes += std::size_t(r->offset.size() + r->key.size()) * sizeof(Index) + std::size_t(r->t.size() + r->r.size()) * sizeof(double);
        return bytes;
    }

private:
    static Stretch<double> get(const Rows& r, Index k)
    {
        Stretch<double> s;
        if (r.t.rows() > 0) s.t = {r.t(k, 0), r.t(k, 1), r.t(k, 2)};
        if (r.r.rows() > 0) s.r = {r.r(k, 0), r.r(k, 1), r.r(k, 2)};
        return s;
    }

    Eigen::Index n_ = 0;
    Index used_ = 0;
    Rows cur_, next_;
};

} // namespace demmat::eigen_soa
