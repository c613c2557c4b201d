#pragma once
// The arrays variant's contact memory (physics.md §9): the stretches of every live contact, in fixed-
// capacity per-particle rows keyed by partner id, the way DEMMAT_F90 would hold them. Row i holds the
// contacts of particle i with partners j > i (or with walls, in a second store), partners ascending:
//   count(i)                 live contacts of particle i                          (N)
//   key(i, k)                partner id j, or wall index, k < count(i)           (N, cap), row i at [i·cap]
//   t(i, k, c), r(i, k, c)   tangential and rolling stretch, component c          (3, N, cap), c-block at [c·N·cap]
// The rolling columns exist only for a law with rolling resistance, the tangential ones only with a
// tangential spring. Each force evaluation reads the rows of the previous one and writes a new set
// (two buffers, swapped after the evaluation): a contact found again takes its stretch, a new one starts
// at zero, one no longer in contact is not written and so is forgotten. Because the key is the partner's
// id, the store survives any search (cell size, rebuilds) unchanged.
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "demmat/contact_memory.hpp"
#include "demmat/state.hpp"

namespace demmat {

template <class T>
class StretchColumns {
public:
    using Index = std::int32_t;

    void reset(std::size_t n, Index cap, bool tangential, bool rolling)
    {
        n_ = n;
        cap_ = cap;
        tangential_ = tangential;
        rolling_ = rolling;
        for (Rows* r : {&cur_, &next_}) {
            r->count.assign(n, 0);
            r->key.assign(n * std::size_t(cap), 0);
            r->t.assign(tangential ? 3 * n * std::size_t(cap) : 0, T(0));
            r->r.assign(rolling ? 3 * n * std::size_t(cap) : 0, T(0));
        }
    }

    // Reads row i of the previous evaluation by ascending key: take(key) for keys in ascending order.
    class Reader {
    public:
        Reader(const StretchColumns& s, std::size_t i) : s_(s), i_(i) {}
        Stretch<T> take(Index key)
        {
            const Rows& r = s_.cur_;
            const std::size_t row = i_ * std::size_t(s_.cap_);
            while (k_ < r.count[i_] && r.key[row + std::size_t(k_)] < key) ++k_;
            if (k_ == r.count[i_] || r.key[row + std::size_t(k_)] != key) return {};
            return s_.get(r, row + std::size_t(k_));
        }

    private:
        const StretchColumns& s_;
        std::size_t i_;
        Index k_ = 0;
    };
    Reader reader(std::size_t i) const { return Reader(*this, i); }

    // Row i of this evaluation: begin_row(i), then put() in ascending key order (at most cap entries: a
    // row never holds more contacts than its candidates, which the search caps at the same capacity).
    void begin_row(std::size_t i) { next_.count[i] = 0; }
    void put(std::size_t i, Index key, const Stretch<T>& s)
    {
        Index& c = next_.count[i];
        set(next_, i * std::size_t(cap_) + std::size_t(c), key, s);
        ++c;
    }
    void finish_evaluation() { std::swap(cur_, next_); }

    // The live contacts as a state holds them (ids, never slots), `wall` marking the wall store.
    void save(std::vector<ContactStretch>& out, bool wall) const
    {
        for (std::size_t i = 0; i < n_; ++i)
            for (Index k = 0; k < cur_.count[i]; ++k) {
                const std::size_t e = i * std::size_t(cap_) + std::size_t(k);
                const Stretch<T> s = get(cur_, e);
                out.push_back({std::int64_t(i), std::int64_t(cur_.key[e]), wall, cast<double>(s.t), cast<double>(s.r)});
            }
    }
    // From a state: its contacts of this store's kind (in canonical order, so each row is ascending).
    // Returns false when a row would exceed the capacity.
    bool load(const std::vector<ContactStretch>& in, bool wall)
    {
        for (std::size_t i = 0; i < n_; ++i) cur_.count[i] = 0;
        for (const ContactStretch& c : in) {
            if (c.wall != wall) continue;
            const auto i = std::size_t(c.i);
            if (cur_.count[i] == cap_) return false;
            set(cur_, i * std::size_t(cap_) + std::size_t(cur_.count[i]++), Index(c.partner), {cast<T>(c.tangential), cast<T>(c.rolling)});
        }
        return true;
    }

    std::size_t memory_bytes() const
    {
        return 2 * (cur_.count.size() + cur_.key.size()) * sizeof(Index) + 2 * (cur_.t.size() + cur_.r.size()) * sizeof(T);
    }

private:
    struct Rows {
        std::vector<Index> count, key;
        std::vector<T> t, r;
    };
    Stretch<T> get(const Rows& r, std::size_t e) const
    {
        const std::size_t b = n_ * std::size_t(cap_);
        Stretch<T> s;
        if (tangential_) s.t = {r.t[e], r.t[b + e], r.t[2 * b + e]};
        if (rolling_) s.r = {r.r[e], r.r[b + e], r.r[2 * b + e]};
        return s;
    }
    void set(Rows& r, std::size_t e, Index key, const Stretch<T>& s) const
    {
        const std::size_t b = n_ * std::size_t(cap_);
        r.key[e] = key;
        if (tangential_) {
            r.t[e] = s.t.x;
            r.t[b + e] = s.t.y;
            r.t[2 * b + e] = s.t.z;
        }
        if (rolling_) {
            r.r[e] = s.r.x;
            r.r[b + e] = s.r.y;
            r.r[2 * b + e] = s.r.z;
        }
    }

    std::size_t n_ = 0;
    Index cap_ = 0;
    bool tangential_ = false, rolling_ = false;
    Rows cur_, next_;
};

} // namespace demmat
