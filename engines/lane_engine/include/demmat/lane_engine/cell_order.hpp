#pragma once
// The fast variant's cell order: at each rebuild the particles are sorted by the cell they are in, the
// box's shortest axis fastest, so that the particles a pair can join (the 27 cells around) lie as close
// in storage as the box allows (in a flat bed, a slice across its longest axis); then a particle's
// later neighbours are a scan of five key ranges, its own row of cells and the four after it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/linked_cells.hpp"
#include "heap_bytes.hpp"
#include "quads.hpp"

namespace demmat::fast {

class CellOrder {
public:
    struct Key {
        std::uint64_t cell;
        Index id, from;  // the particle's id, and the slot it held before the sort
    };

    // The cell order of the n particles at positions x (three component blocks) with ids id: key(s) is
    // what goes into slot s. Cells of edge `cell` over the bounding box, padded by one empty layer so
    // that a cell's neighbours stay inside. A compact box (the usual case) gets a table of cell starts
    // and a stable counting sort, O(N); a huge sparse box (the paper's literal 2 m box) a comparison sort
    // and binary searches. Throws InstabilityError for positions too far apart for any grid.
    void sort(const std::vector<double>& x, const std::vector<Index>& id, std::size_t n, double cell)
    {
        cell3_.resize(3 * n);
        key_.resize(n);
        double lo[3];
        std::int64_t dims[3];
        std::size_t ends[3][2];  // slots of the lowest and highest particle on each axis
        for (int c = 0; c < 3; ++c) {
            const double* xc = x.data() + std::size_t(c) * n;
            std::int64_t* qc = cell3_.data() + std::size_t(c) * n;
            ends[c][0] = std::size_t(std::min_element(xc, xc + n) - xc);
            ends[c][1] = ends[c][0];
            lo[c] = xc[ends[c][0]];
            std::int64_t hi = 0;
            for (std::size_t s = 0; s < n; ++s) {
                qc[s] = cell_coordinate((xc[s] - lo[c]) / cell, std::size_t(id[s])) + 1;
                if (qc[s] > hi) {
                    hi = qc[s];
                    ends[c][1] = s;
                }
            }
            dims[c] = hi + 2;
        }
        const double cells = double(dims[0]) * double(dims[1]) * double(dims[2]);
        if (cells > 0x1p62) {
            // Finite but runaway positions: name the end of the widest axis farther from the mean.
            const int c = int(std::max_element(dims, dims + 3) - dims);
            const double* xc = x.data() + std::size_t(c) * n;
            double mean = 0.0;
            for (std::size_t s = 0; s < n; ++s) mean += xc[s] / double(n);
            const std::size_t far = std::abs(xc[ends[c][1]] - mean) > std::abs(xc[ends[c][0]] - mean) ? ends[c][1] : ends[c][0];
            throw InstabilityError(fmt::format("particle {} has a runaway position (found by the fast variant's cell search)", id[far]), -1,
                                   std::int64_t(id[far]));
        }
        // The axes in the key by extent, the shortest fastest.
        int ax[3] = {0, 1, 2};
        std::sort(ax, ax + 3, [&](int p, int q) { return dims[p] < dims[q]; });
        dims_[0] = dims[ax[0]];
        dims_[1] = dims[ax[1]];
        const std::int64_t* q0 = cell3_.data() + std::size_t(ax[0]) * n;
        const std::int64_t* q1 = cell3_.data() + std::size_t(ax[1]) * n;
        const std::int64_t* q2 = cell3_.data() + std::size_t(ax[2]) * n;
        for (std::size_t s = 0; s < n; ++s)
            key_[s] = {std::uint64_t(q0[s] + dims_[0] * (q1[s] + dims_[1] * q2[s])), id[s], Index(s)};
        dense_ = cells <= double(8 * n + 4096);
        if (dense_) {
            const std::size_t nc = std::size_t(cells);
            cstart_.assign(nc + 1, 0);
            for (std::size_t s = 0; s < n; ++s) ++cstart_[key_[s].cell + 1];
            for (std::size_t c = 0; c < nc; ++c) cstart_[c + 1] += cstart_[c];
            keytmp_.resize(n);
            for (std::size_t s = 0; s < n; ++s) keytmp_[std::size_t(cstart_[key_[s].cell]++)] = key_[s];
            for (std::size_t c = nc; c > 0; --c) cstart_[c] = cstart_[c - 1];  // back to starts
            cstart_[0] = 0;
            key_.swap(keytmp_);
        } else {
            std::sort(key_.begin(), key_.end(), [](const Key& p, const Key& q) { return p.cell != q.cell ? p.cell < q.cell : p.id < q.id; });
        }
    }

    const Key& key(std::size_t s) const { return key_[s]; }

    // Calls f(from, to) for runs of slots [from, to), in ascending order, that together hold every slot
    // after s in the 27 cells around slot s's cell, once the particles are in the sorted order: a pair is
    // listed once, by the particle that comes first. The cells are visited as rows of three along the
    // fastest axis (a row's cells are consecutive keys, so one run); the rows below s's own (keys all
    // lower) hold no later slot, and in its own row the later slots start right after s, so only s's own
    // row and the four rows above it are scanned, half of the 27 cells.
    template <class F>
    void for_each_later(std::size_t s, F&& f) const
    {
        const std::uint64_t k = key_[s].cell;
        const auto dx = std::uint64_t(dims_[0]), dxy = dx * std::uint64_t(dims_[1]);
        auto below = [](const Key& e, std::uint64_t v) { return e.cell < v; };
        // [from, to): from a slot up to the end of cell hi.
        auto scan = [&](std::size_t from, std::uint64_t hi) {
            const std::size_t to = dense_ ? std::size_t(cstart_[hi + 1])
                                          : std::size_t(std::lower_bound(key_.begin() + std::ptrdiff_t(from), key_.end(), hi + 1, below) - key_.begin());
            f(from, to);
        };
        auto row = [&](std::uint64_t centre) {
            const std::size_t from = dense_ ? std::size_t(cstart_[centre - 1])
                                            : std::size_t(std::lower_bound(key_.begin(), key_.end(), centre - 1, below) - key_.begin());
            scan(from, centre + 1);
        };
        scan(s + 1, k + 1);  // s's own row: the rest of its cell, and the cell after it
        row(k + dx);         // the row above in the middle axis, then the three of the slowest axis's next layer
        for (std::uint64_t dy = 0; dy < 3; ++dy) row(k + dxy + dy * dx - dx);
    }

    std::size_t bytes() const { return heap_bytes(key_, keytmp_, cell3_, cstart_); }

private:
    std::vector<Key> key_, keytmp_;
    std::vector<std::int64_t> cell3_;  // (3N) cell coordinates at the last rebuild
    std::vector<Index> cstart_;        // first storage slot of each cell (dense grid), cells + 1
    bool dense_ = true;
    std::int64_t dims_[2] = {0, 0};
};

} // namespace demmat::fast
