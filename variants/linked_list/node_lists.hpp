#pragma once
// The linked-list variants' contact nodes, where their nodes come from, and how a particle's sorted list
// is made equal to its sorted candidate set each step (linked_list.cpp holds the processor).
//
// A node is {next, partner}; under a contact law with memory (physics.md §9) it also holds the contact's
// stretches and whether the contact was live (h > 0) at the last force evaluation, so the memory lives
// where the contact does. A list that persists keeps a persisting pair's node, and with it the stretch;
// the list rebuilt every step takes each new node's stretch from the old list's node of the same pair.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "demmat/contact_memory.hpp"

namespace demmat::linked_list {

using Index = std::int32_t;

template <class T, bool Memory>
struct Node {
    Node* next;
    Index partner;  // particle id j > i, or wall index
};
template <class T>
struct Node<T, true> {
    Node* next;
    Index partner;
    bool live;           // in contact at the last force evaluation: what save() writes
    Stretch<T> stretch;  // zero for a new contact, and again whenever the contact opens (h <= 0)
};

// ---- node allocation policies ----------------------------------------------------------------------

// Every node from the general-purpose heap, every dropped node returned to it at once.
template <class N>
class HeapNodes {
public:
    using Node = N;
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
template <class N>
class PoolNodes {
public:
    using Node = N;
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

// A node for a new contact: its partner and, under a law with memory, no stretch yet.
template <class Node>
void start_contact(Node* n, Index partner)
{
    n->partner = partner;
    if constexpr (requires { n->stretch; }) {
        n->live = false;
        n->stretch = {};
    }
}

// Makes a sorted list equal to a sorted candidate set given one candidate at a time in ascending order:
// nodes with a smaller partner than the next candidate are dropped, a node equal to it is kept (with its
// stretch), and a missing one is linked in at that position; finish() drops what is left after the last
// candidate.
template <class Nodes>
class ListMerge {
    using Node = typename Nodes::Node;

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
        start_contact(fresh, c);
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

// The list rebuilt every step under a law with memory: every candidate gets a fresh node, which takes
// the stretch of the old list's node of the same pair, looked up by partner as the old list is walked
// beside the candidates (both ascending) and freed node by node. The paper's law has no memory to carry
// and frees every list at once before the search (linked_list.cpp), as it always did.
template <class Nodes>
class RebuildMerge {
    using Node = typename Nodes::Node;

public:
    RebuildMerge(Node*& head, Nodes& nodes, std::size_t& live) : old_(head), link_(&head), nodes_(nodes), live_(live)
    {
        head = nullptr;
    }

    void keep(Index c)
    {
        drop_old_below(c);
        Node* fresh = nodes_.acquire();
        start_contact(fresh, c);
        if (old_ != nullptr && old_->partner == c) {  // the same pair: its memory moves to the new node
            fresh->live = old_->live;
            fresh->stretch = old_->stretch;
            drop_old_below(c + 1);
        }
        fresh->next = nullptr;
        *link_ = fresh;
        link_ = &fresh->next;
        ++live_;
    }

    void finish() { drop_old_below(std::int64_t(std::numeric_limits<Index>::max()) + 1); }

private:
    void drop_old_below(std::int64_t c)
    {
        while (old_ != nullptr && old_->partner < c) {
            Node* next = old_->next;
            nodes_.release(old_);
            --live_;
            old_ = next;
        }
    }

    Node* old_;
    Node** link_;
    Nodes& nodes_;
    std::size_t& live_;
};

} // namespace demmat::linked_list
