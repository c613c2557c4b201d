// The linked-list contact store: the design the DEMMAT paper rejected ("the linked list method based
// on pointers and target variables", because a list rebuilt every step allocates and frees a node for
// every contact every step). The particles' state is the arrays variant's own (ColumnState, flat arrays
// column by column, demmat/column_state.hpp); only the contact store differs, so a comparison with arrays isolates it.
//
// Particle i owns a singly linked list of nodes {partner j > i, next}, kept sorted by partner id, and a
// second list of its wall contacts, sorted by wall index. Each step the search finds the current
// candidate set of every particle and merges it into the lists: nodes of pairs that left are unlinked
// and released, nodes of new pairs are acquired and linked in sorted position, and pairs that persist
// keep their node (where contact history would live). Walking particles in id order and each list in
// order is the canonical summation order of physics.md §6, so every mode gives the same sorted lists
// and a trajectory bit-identical to arrays.
//
// Under a contact law with memory (physics.md §9) a node also holds its contact's stretches
// (node_lists.hpp): a persistent list carries them in the node of a persisting pair, and the list rebuilt
// every step looks each pair's old node up by partner as it builds the new one.
//
// Two compile-time policies of one template give the three registered variants and what each measures:
//   linked_list_rebuild  Rebuild = true, nodes from new/delete: every step every node of every list is
//                        deleted and a fresh one new'ed per candidate, the paper's rebuilt list, so it
//                        costs an allocation and a free per contact per step;
//   linked_list          persistent lists, nodes from new/delete: allocator calls only for the few
//                        contacts that appear or disappear each step;
//   linked_list_pool     persistent lists, nodes from blocks allocated up front (doubled when exhausted)
//                        and recycled through a free list: no allocator calls once warm, so what remains
//                        of the difference to arrays is pointer chasing.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "demmat/column_state.hpp"
#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"
#include "node_lists.hpp"

namespace demmat {
namespace linked_list {
namespace {

// ---- the processor ---------------------------------------------------------------------------------

// Pool: where nodes come from (HeapNodes, PoolNodes). Rebuild: empty every list at each search, so a
// fresh node is acquired for every candidate; otherwise the lists persist from step to step.
template <class T, class M, template <class> class Pool, bool Rebuild = false>
class LinkedListVariant final : public ColumnStateVariant<T, M> {
    using ColumnStateVariant<T, M>::state_, ColumnStateVariant<T, M>::pp_, ColumnStateVariant<T, M>::pw_,
        ColumnStateVariant<T, M>::candidates_;
    using Node = linked_list::Node<T, M::memory>;
    using Nodes = Pool<Node>;
    // The paper's law frees every list at once before the search; a law with memory rebuilds each list
    // beside the old one, to carry the stretches over (node_lists.hpp).
    using Merge = std::conditional_t<Rebuild && M::memory, RebuildMerge<Nodes>, ListMerge<Nodes>>;

public:
    LinkedListVariant() = default;
    LinkedListVariant(const LinkedListVariant&) = delete;
    LinkedListVariant& operator=(const LinkedListVariant&) = delete;
    ~LinkedListVariant() override { free_lists(); }

    void init(const Setup& setup) override
    {
        free_lists();
        state_.load(setup);
        const std::size_t n = state_.size();
        cell_ = T(setup.cell_size);
        pp_head_.assign(n, nullptr);
        pw_head_.assign(n, nullptr);
        pp_live_ = pw_live_ = 0;
        // A dense bed keeps about three partners j > i per particle and a fraction of a wall contact;
        // the pool starts there and doubles if a scene needs more. (A no-op for the heap policy.)
        nodes_.reserve(4 * n + 64);
        scratch_.clear();
        scratch_.reserve(64);
        cells_.reserve(n);
        pp_ = pw_ = candidates_ = 0;
        if constexpr (M::memory) load_stretches(setup.state->stretches);
    }

    void search() override
    {
        if constexpr (Rebuild && !M::memory) free_lists();
        if (cell_ > T(0)) search_cells();
        else search_all_pairs();
        if constexpr (M::walls) search_walls();
    }

    void forces() override
    {
        state_.zero_loads();
        pp_ = 0;
        pw_ = 0;
        candidates_ = std::int64_t(pp_live_);
        const std::size_t n = state_.size();
        // Particles in id order, each list in partner order: the canonical order of physics.md §6.
        if constexpr (M::memory) {
            for (std::size_t i = 0; i < n; ++i)
                for (Node* node = pp_head_[i]; node != nullptr; node = node->next)
                    pp_ += remember(node, state_.pair(i, std::size_t(node->partner), node->stretch));
            if constexpr (M::walls)
                for (std::size_t i = 0; i < n; ++i)
                    for (Node* node = pw_head_[i]; node != nullptr; node = node->next)
                        pw_ += remember(node, state_.wall(i, std::size_t(node->partner), node->stretch));
        } else {
            for (std::size_t i = 0; i < n; ++i)
                for (const Node* node = pp_head_[i]; node != nullptr; node = node->next)
                    if (state_.pair(i, std::size_t(node->partner))) ++pp_;
            if constexpr (M::walls)
                for (std::size_t i = 0; i < n; ++i)
                    for (const Node* node = pw_head_[i]; node != nullptr; node = node->next)
                        if (state_.wall(i, std::size_t(node->partner))) ++pw_;
        }
        state_.newton();
    }

    // The state, and under a law with memory every live contact's stretches: particle by particle, its
    // pair list then its wall list, both ascending, which is the canonical order.
    void save(State& out) const override
    {
        state_.save(out);
        out.stretches.clear();
        if constexpr (M::memory)
            for (std::size_t i = 0; i < state_.size(); ++i)
                for (bool wall : {false, true})
                    for (const Node* node = (wall ? pw_head_ : pp_head_)[i]; node != nullptr; node = node->next)
                        if (node->live)
                            out.stretches.push_back({std::int64_t(i), std::int64_t(node->partner), wall,
                                                     cast<double>(node->stretch.t), cast<double>(node->stretch.r)});
    }

    std::size_t memory_bytes() const override
    {
        return state_.memory_bytes() + (pp_head_.size() + pw_head_.size()) * sizeof(Node*) + nodes_.bytes(pp_live_ + pw_live_) +
               scratch_.capacity() * sizeof(Index) + cells_.memory_bytes();
    }

private:
    // A contact evaluated under a law with memory: a live one has advanced its stretch in place; one that
    // has opened forgets it (a contact that closes again starts at zero, physics.md §9).
    static bool remember(Node* node, bool live)
    {
        node->live = live;
        if (!live) node->stretch = {};
        return live;
    }

    // The live contacts of a saved state (canonical order: each particle's partners, then walls,
    // ascending), appended to the lists they belong to; the first search keeps those still candidates.
    void load_stretches(const std::vector<ContactStretch>& in)
    {
        for (const ContactStretch& c : in) {
            Node** link = &(c.wall ? pw_head_ : pp_head_)[std::size_t(c.i)];
            while (*link != nullptr) link = &(*link)->next;
            Node* node = nodes_.acquire();
            start_contact(node, Index(c.partner));
            node->live = true;
            node->stretch = {cast<T>(c.tangential), cast<T>(c.rolling)};
            node->next = nullptr;
            *link = node;
            ++(c.wall ? pw_live_ : pp_live_);
        }
    }

    // Merges particle i's sorted candidates (in scratch_) into its list.
    void update_pairs(std::size_t i)
    {
        Merge merge(pp_head_[i], nodes_, pp_live_);
        for (const Index j : scratch_) merge.keep(j);
        merge.finish();
    }

    // Every pair (the paper's "no cells"), O(N²); candidates come out ascending.
    void search_all_pairs()
    {
        const std::size_t n = state_.size();
        const T* x = state_.x();
        const T* r = state_.r();
        for (std::size_t i = 0; i < n; ++i) {
            Merge merge(pp_head_[i], nodes_, pp_live_);
            const Vec3<T> xi = get(x, n, i);
            for (std::size_t j = i + 1; j < n; ++j)
                if (may_touch(xi, get(x, n, j), r[i], r[j])) merge.keep(Index(j));
            merge.finish();
        }
    }

    // Linked cells (core/include/demmat/linked_cells.hpp); a particle's candidates j > i gathered ascending in a
    // scratch row, then merged into its list.
    void search_cells()
    {
        const std::size_t n = state_.size();
        const T* x = state_.x();
        const T* r = state_.r();
        cells_.build(n, x, x + n, x + 2 * n, cell_);
        for (std::size_t i = 0; i < n; ++i) {
            scratch_.clear();
            const Vec3<T> xi = get(x, n, i);
            cells_.for_each_above(i, [&](std::size_t j) {
                if (!may_touch(xi, get(x, n, j), r[i], r[j])) return;
                scratch_.push_back(Index(j));
                insert_ascending(scratch_.data(), std::int64_t(scratch_.size()) - 1, Index(j));
            });
            update_pairs(i);
        }
    }

    // Per particle, the walls in wall order: they come out ascending and merge straight into the list.
    void search_walls()
    {
        const std::size_t n = state_.size(), nw = state_.wall_count();
        const T* x = state_.x();
        const T* r = state_.r();
        for (std::size_t i = 0; i < n; ++i) {
            Merge merge(pw_head_[i], nodes_, pw_live_);
            const Vec3<T> xi = get(x, n, i);
            for (std::size_t w = 0; w < nw; ++w)
                if (may_touch_wall(xi, r[i], state_.wall_point(w), state_.wall_normal(w))) merge.keep(Index(w));
            merge.finish();
        }
    }

    void free_lists()
    {
        for (std::vector<Node*>* heads : {&pp_head_, &pw_head_})
            for (Node*& head : *heads) {
                while (Node* cur = head) {
                    head = cur->next;
                    nodes_.release(cur);
                }
            }
        pp_live_ = pw_live_ = 0;
    }

    T cell_ = T(0);
    // Declared before the list heads, so it outlives them on destruction (the destructor empties the
    // lists first in any case).
    Nodes nodes_;
    std::vector<Node*> pp_head_;  // (N) particle i's partners j > i, ascending
    std::vector<Node*> pw_head_;  // (N) particle i's walls, ascending
    std::size_t pp_live_ = 0, pw_live_ = 0;
    std::vector<Index> scratch_;  // one particle's candidates during the search
    LinkedCells cells_;
};

// The instantiation a run gets, picked in init() as in arrays (the same ColumnState, the same models, the
// paper's law exactly with_model's), so that a comparison with arrays keeps isolating the contact store.
template <template <class> class Pool, bool Rebuild = false>
std::unique_ptr<Variant> make_dispatching()
{
    return std::make_unique<DispatchingVariant>(
        [](const Setup& setup) {
            return with_law_model(model_for(setup), []<class M>() -> std::unique_ptr<Variant> {
                return std::make_unique<LinkedListVariant<double, M, Pool, Rebuild>>();
            });
        },
        /*all_integrators=*/false, /*all_laws=*/true);
}

} // namespace
} // namespace linked_list

void register_variant_linked_list(Registry& r)
{
    using linked_list::HeapNodes, linked_list::PoolNodes, linked_list::make_dispatching;
    r.add({"linked_list", "arrays state; persistent per-particle linked lists of contacts, nodes from new/delete",
           [] { return make_dispatching<HeapNodes>(); }});
    r.add({"linked_list_pool", "arrays state; persistent per-particle linked lists of contacts, nodes from a recycled pool",
           [] { return make_dispatching<PoolNodes>(); }});
    r.add({"linked_list_rebuild", "arrays state; per-particle linked lists rebuilt every step, a new/delete per contact",
           [] { return make_dispatching<HeapNodes, true>(); }});
}

} // namespace demmat
