#pragma once
// The plain-arrays processor, the paper's DEMMAT_F90 in C++: procedural free functions over flat
// arrays of shape (N, 3) stored column by column (x(i, c) at x[c·N + i], as Fortran stores them),
// capacities fixed up front and checked (the paper's "control of overestimation"). The particles'
// state and its phases are in demmat/column_state.hpp, the contacts' stretches of a §9 law in
// stretch_columns.hpp; this file holds the contact store, the search and the processor. Its
// instantiations are made in arrays.cpp (the paper's law) and arrays_laws.cpp (the laws of physics.md §9).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "stretch_columns.hpp"
#include "demmat/column_state.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"

namespace demmat::arrays {

using Index = std::int32_t;

// ---- contact search --------------------------------------------------------------------------------

// Neighbour list: for particle i, its candidate partners j > i in ascending order, at most `cap`.
struct NeighbourList {
    Index cap = 0;
    std::vector<Index> count;    // (N)
    std::vector<Index> partner;  // (N, cap), row i at [i·cap]
};

// Boundary list: for particle i, the walls it may touch, in wall order.
struct BoundaryList {
    Index cap = 0;
    std::vector<Index> count;  // (N)
    std::vector<Index> wall;   // (N, cap)
};

// Every pair (the paper's "no cells"), O(N²).
template <class T>
void search_all_pairs(std::size_t n, const T* x, const T* r, NeighbourList& nl)
{
    CandidateOverflow over;
    for (std::size_t i = 0; i < n; ++i) {
        Index c = 0;
        Index* row = &nl.partner[i * std::size_t(nl.cap)];
        const Vec3<T> xi = get(x, n, i);
        for (std::size_t j = i + 1; j < n; ++j) {
            if (!may_touch(xi, get(x, n, j), r[i], r[j])) continue;
            if (c < nl.cap) row[c] = Index(j);
            ++c;
        }
        over.note(c, i);
        nl.count[i] = std::min(c, nl.cap);
    }
    over.check(nl.cap);
}

// Linked cells (core/include/demmat/linked_cells.hpp); partners j > i stored in ascending order, as the canonical
// order needs. On overflow the search goes on counting so the message can give the value that fits.
template <class T>
void search_cells(std::size_t n, const T* x, const T* r, T edge, LinkedCells& cells, NeighbourList& nl)
{
    cells.build(n, x, x + n, x + 2 * n, edge);
    CandidateOverflow over;
    for (std::size_t i = 0; i < n; ++i) {
        Index c = 0;
        Index* row = &nl.partner[i * std::size_t(nl.cap)];
        const Vec3<T> xi = get(x, n, i);
        const T ri = r[i];
        cells.for_each_above(i, [&](std::size_t j) {
            if (!may_touch(xi, get(x, n, j), ri, r[j])) return;
            if (c < nl.cap) insert_ascending(row, c, Index(j));
            ++c;
        });
        over.note(c, i);
        nl.count[i] = std::min(c, nl.cap);
    }
    over.check(nl.cap);
}

template <class T, class M, class S>
void search_walls(const ColumnState<T, M, S>& s, BoundaryList& bl)
{
    const std::size_t n = s.size(), nw = s.wall_count();
    std::fill(bl.count.begin(), bl.count.end(), Index(0));
    for (std::size_t w = 0; w < nw; ++w) {
        const Vec3<T> p = s.wall_point(w), nv = s.wall_normal(w);
        for (std::size_t i = 0; i < n; ++i) {
            if (!may_touch_wall(get(s.x(), n, i), s.r()[i], p, nv)) continue;
            Index& c = bl.count[i];
            if (c == bl.cap)  // at most one entry per wall: the walls' count always fits
                throw CapacityError(fmt::format("capacity.wall_contacts_per_particle = {} exceeded: particle {} touches more "
                                                "walls; set it to {} (the number of walls)", bl.cap, i, nw));
            bl.wall[i * std::size_t(bl.cap) + std::size_t(c++)] = Index(w);
        }
    }
}

// ---- the processor ---------------------------------------------------------------------------------

// T: value type (double, float); M: model (model.hpp); S: integrator (integrators.hpp).
template <class T, class M, class S = Gear5Scheme>
class ArraysVariant final : public ColumnStateVariant<T, M, S> {
    using ColumnStateVariant<T, M, S>::state_, ColumnStateVariant<T, M, S>::pp_, ColumnStateVariant<T, M, S>::pw_,
        ColumnStateVariant<T, M, S>::candidates_;

public:
    void init(const Setup& setup) override
    {
        state_.load(setup);
        const Scene& scene = *setup.scene;
        const std::size_t n = state_.size();
        cell_ = T(setup.cell_size);
        nl_.cap = Index(scene.capacity.contacts_per_particle);
        nl_.count.assign(n, 0);
        nl_.partner.assign(n * std::size_t(nl_.cap), 0);
        if constexpr (M::walls) {  // a model without walls holds no boundary list
            bl_.cap = Index(scene.capacity.wall_contacts_per_particle);
            bl_.count.assign(n, 0);
            bl_.wall.assign(n * std::size_t(bl_.cap), 0);
        }
        cells_.reserve(n);
        if constexpr (M::memory) {  // the stretches of a §9 law, carried from the state (none at a fresh start)
            pp_mem_.reset(n, nl_.cap, M::history, M::rolling);
            pw_mem_.reset(n, bl_.cap, M::history, M::rolling);
            if (!pp_mem_.load(setup.state->stretches, false) || !pw_mem_.load(setup.state->stretches, true))
                throw CapacityError(fmt::format("the state holds more contacts per particle than capacity.contacts_per_particle = {} "
                                                "or wall_contacts_per_particle = {}", nl_.cap, bl_.cap));
        }
    }

    void search() override
    {
        const std::size_t n = state_.size();
        if (cell_ > T(0)) search_cells(n, state_.x(), state_.r(), cell_, cells_, nl_);
        else search_all_pairs(n, state_.x(), state_.r(), nl_);
        if constexpr (M::walls) search_walls(state_, bl_);
    }

    void forces() override
    {
        state_.zero_loads();
        pp_ = 0;
        pw_ = 0;
        candidates_ = 0;
        const std::size_t n = state_.size();
        for (std::size_t i = 0; i < n; ++i) {
            const Index* row = &nl_.partner[i * std::size_t(nl_.cap)];
            candidates_ += nl_.count[i];
            if constexpr (M::memory) {
                pp_ += remembered(pp_mem_, i, row, nl_.count[i], [&](std::size_t j, Stretch<T>& s) { return state_.pair(i, j, s); });
            } else {
                for (Index k = 0; k < nl_.count[i]; ++k)
                    if (state_.pair(i, std::size_t(row[k]))) ++pp_;
            }
        }
        if constexpr (M::walls)
            for (std::size_t i = 0; i < n; ++i) {
                const Index* row = &bl_.wall[i * std::size_t(bl_.cap)];
                if constexpr (M::memory) {
                    pw_ += remembered(pw_mem_, i, row, bl_.count[i], [&](std::size_t w, Stretch<T>& s) { return state_.wall(i, w, s); });
                } else {
                    for (Index k = 0; k < bl_.count[i]; ++k)
                        if (state_.wall(i, std::size_t(row[k]))) ++pw_;
                }
            }
        if constexpr (M::memory) {
            pp_mem_.finish_evaluation();
            pw_mem_.finish_evaluation();
        }
        state_.newton();
    }

    void save(State& out) const override
    {
        state_.save(out);
        out.stretches.clear();
        if constexpr (M::memory) {
            pp_mem_.save(out.stretches, false);
            pw_mem_.save(out.stretches, true);
            std::sort(out.stretches.begin(), out.stretches.end());  // the canonical order: by particle, pairs, then walls
        }
    }
    std::size_t memory_bytes() const override
    {
        return state_.memory_bytes() + (nl_.partner.size() + nl_.count.size() + bl_.wall.size() + bl_.count.size()) * sizeof(Index) +
               cells_.memory_bytes() + pp_mem_.memory_bytes() + pw_mem_.memory_bytes();
    }

private:
    // Row i's contacts under a §9 law with memory (keys: partner ids or wall indices, ascending): each
    // takes its stretch from the previous evaluation by key, and a contact that is live writes it back.
    template <class Contact>
    static std::int64_t remembered(StretchColumns<T>& mem, std::size_t i, const Index* row, Index count, Contact&& contact)
    {
        std::int64_t live = 0;
        auto old = mem.reader(i);
        mem.begin_row(i);
        for (Index k = 0; k < count; ++k) {
            Stretch<T> s = old.take(row[k]);
            if (!contact(std::size_t(row[k]), s)) continue;
            ++live;
            mem.put(i, row[k], s);
        }
        return live;
    }

    T cell_ = T(0);
    NeighbourList nl_;
    BoundaryList bl_;
    LinkedCells cells_;
    StretchColumns<T> pp_mem_, pw_mem_;  // a §9 law with memory: pairs (partners j > i) and wall contacts
};

// The instantiation for a scene with a §9 law (arrays_laws.cpp).
std::unique_ptr<Variant> pick_arrays_law(const Setup& setup);

} // namespace demmat::arrays
