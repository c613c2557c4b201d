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
// Two compile-time policies of one template give the three registered variants and what each measures:
//   linked_list_rebuild  Rebuild = true, nodes from new/delete: every step every node of every list is
//                        deleted and a fresh one new'ed per candidate, the paper's rebuilt list, so it
//                        costs an allocation and a free per contact per step;
//   linked_list          persistent lists, nodes from new/delete: allocator calls only for the few
//                        contacts that appear or disappear each step;
//   linked_list_pool     persistent lists, nodes from blocks allocated up front (doubled when exhausted)
//                        and recycled through a free list: no allocator calls once warm, so what remains
//                        of the difference to arrays is pointer chasing.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "demmat/column_state.hpp"
#include "demmat/features.hpp"
#include "demmat/linked_cells.hpp"
#include "demmat/registry.hpp"

namespace demmat {
namespace {

using Index = std::int32_t;

// ---- node allocation policies ----------------------------------------------------------------------

struct Node {
    Node* next;
    Index partner;  // particle id j > i, or wall index
};

// Every node from the general-purpose heap, every dropped node returned to it at once.
class HeapNodes {
public:
    HeapNodes() = default;
    HeapNodes(const HeapNodes&) = delete;
    HeapNodes& operator=(const HeapNodes&) = delete;

    void reserve(std::size_t) {}
    Node* acquire() { return new Node; }
    void release(Node* n) { delete n; }
    // Bytes of node storage held for `live` nodes (the heap's own bookkeeping per block not counted).
    std::size_t bytes(std::size_t live) const { return live * sizeof(Node); }
};

// Nodes carved from large blocks; a released node goes on an intrusive free list (through its `next`)
// and is the next one handed out. Blocks are only freed when the pool is destroyed.
class PoolNodes {
public:
    PoolNodes() = default;
    PoolNodes(const PoolNodes&) = delete;
    PoolNodes& operator=(const PoolNodes&) = delete;

    void reserve(std::size_t count)
    {
        if (count > capacity_) grow(count - capacity_);
    }
    Node* acquire()
    {
        if (free_ == nullptr) grow(std::max<std::size_t>(capacity_, 1024));  // doubling
        Node* n = free_;
        free_ = n->next;
        return n;
    }
    void release(Node* n)
    {
        n->next = free_;
        free_ = n;
    }
    std::size_t bytes(std::size_t) const { return capacity_ * sizeof(Node) + blocks_.capacity() * sizeof(blocks_[0]); }

private:
    void grow(std::size_t count)
    {
        blocks_.push_back(std::unique_ptr<Node[]>(new Node[count]));
        Node* b = blocks_.back().get();
        for (std::size_t k = count; k-- > 0;) {  // threaded so that a fresh block is handed out in address order
            b[k].next = free_;
            free_ = &b[k];
        }
        capacity_ += count;
    }

    std::vector<std::unique_ptr<Node[]>> blocks_;
    Node* free_ = nullptr;
    std::size_t capacity_ = 0;
};

// Makes a sorted list equal to a sorted candidate set given one candidate at a time in ascending order:
// nodes with a smaller partner than the next candidate are dropped, a node equal to it is kept, and a
// missing one is linked in at that position; finish() drops what is left after the last candidate.
template <class Nodes>
class ListMerge {
public:
    ListMerge(Node*& head, Nodes& nodes, std::size_t& live) : link_(&head), nodes_(nodes), live_(live) {}

    void keep(Index c)
    {
        Node* cur = *link_;
        while (cur != nullptr && cur->partner < c) {  // pair left: free its node
            *link_ = cur->next;
            nodes_.release(cur);
            --live_;
            cur = *link_;
        }
        if (cur != nullptr && cur->partner == c) {  // pair persists: keep its node
            link_ = &cur->next;
            return;
        }
        Node* fresh = nodes_.acquire();  // new pair: a node in sorted position
        fresh->partner = c;
        fresh->next = cur;
        *link_ = fresh;
        link_ = &fresh->next;
        ++live_;
    }

    void finish()
    {
        while (Node* cur = *link_) {
            *link_ = cur->next;
            nodes_.release(cur);
            --live_;
        }
    }

private:
    Node** link_;
    Nodes& nodes_;
    std::size_t& live_;
};

// ---- the processor ---------------------------------------------------------------------------------

// Rebuild: empty every list (release all nodes) at the start of each search, so the merge acquires a
// fresh node for every candidate; otherwise the lists persist from step to step.
template <class T, class M, class Nodes, bool Rebuild = false>
class LinkedListVariant final : public ColumnStateVariant<T, M> {
    using ColumnStateVariant<T, M>::state_, ColumnStateVariant<T, M>::pp_, ColumnStateVariant<T, M>::pw_,
        ColumnStateVariant<T, M>::candidates_;

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
    }

    void search() override
    {
        if constexpr (Rebuild) free_lists();
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
        for (std::size_t i = 0; i < n; ++i)
            for (const Node* node = pp_head_[i]; node != nullptr; node = node->next)
                if (state_.pair(i, std::size_t(node->partner))) ++pp_;
        if constexpr (M::walls)
            for (std::size_t i = 0; i < n; ++i)
                for (const Node* node = pw_head_[i]; node != nullptr; node = node->next)
                    if (state_.wall(i, std::size_t(node->partner))) ++pw_;
        state_.newton();
    }

    std::size_t memory_bytes() const override
    {
        return state_.memory_bytes() + (pp_head_.size() + pw_head_.size()) * sizeof(Node*) + nodes_.bytes(pp_live_ + pw_live_) +
               scratch_.capacity() * sizeof(Index) + cells_.memory_bytes();
    }

private:
    // Merges particle i's sorted candidates (in scratch_) into its list.
    void update_pairs(std::size_t i)
    {
        ListMerge<Nodes> merge(pp_head_[i], nodes_, pp_live_);
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
            ListMerge<Nodes> merge(pp_head_[i], nodes_, pp_live_);
            const Vec3<T> xi = get(x, n, i);
            for (std::size_t j = i + 1; j < n; ++j)
                if (may_touch(xi, get(x, n, j), r[i], r[j])) merge.keep(Index(j));
            merge.finish();
        }
    }

    // Linked cells (common/linked_cells.hpp); a particle's candidates j > i gathered ascending in a
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
            ListMerge<Nodes> merge(pw_head_[i], nodes_, pw_live_);
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

// The instantiation a run gets, picked in init() as in arrays (the same ColumnState, the same models), so
// that a comparison with arrays keeps isolating the contact store.
template <class Nodes, bool Rebuild = false>
std::unique_ptr<Variant> make_dispatching()
{
    return std::make_unique<DispatchingVariant>([](const Setup& setup) {
        return with_model(model_for(setup), []<class M>() -> std::unique_ptr<Variant> {
            return std::make_unique<LinkedListVariant<double, M, Nodes, Rebuild>>();
        });
    });
}

} // namespace

void register_variant_linked_list(Registry& r)
{
    r.add({"linked_list", "arrays state; persistent per-particle linked lists of contacts, nodes from new/delete",
           [] { return make_dispatching<HeapNodes>(); }});
    r.add({"linked_list_pool", "arrays state; persistent per-particle linked lists of contacts, nodes from a recycled pool",
           [] { return make_dispatching<PoolNodes>(); }});
    r.add({"linked_list_rebuild", "arrays state; per-particle linked lists rebuilt every step, a new/delete per contact",
           [] { return make_dispatching<HeapNodes, true>(); }});
}

} // namespace demmat
