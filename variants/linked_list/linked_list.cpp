// The linked-list contact store: the design the DEMMAT paper rejected ("the linked list method based
// on pointers and target variables", because a list rebuilt every step allocates and frees a node for
// every contact every step). The particles' state is held exactly as in the arrays variant (flat
// arrays, column by column); only the contact store differs, so a comparison with arrays isolates it.
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

// ---- per-component helpers on the (N, 3) column layout (as in the arrays variant) -------------------

template <class T>
void gear_predictor(std::size_t n3, T* x, T* v, T* a, T* b3, T* b4, const T* b5, const GearCoefficients<T>& k)
{
    for (std::size_t e = 0; e < n3; ++e) gear_predict(x[e], v[e], a[e], b3[e], b4[e], b5[e], k);
}

template <class T>
void gear_corrector(std::size_t n3, T* x, T* v, T* a, T* b3, T* b4, T* b5, const T* a_new, const GearCoefficients<T>& k)
{
    for (std::size_t e = 0; e < n3; ++e) {
        const T da = a_new[e] - a[e];
        gear_correct(x[e], v[e], a[e], b3[e], b4[e], b5[e], da, k);
    }
}

template <class T>
Vec3<T> get(const T* a, std::size_t n, std::size_t i) { return {a[i], a[n + i], a[2 * n + i]}; }
template <class T>
void add(T* a, std::size_t n, std::size_t i, const Vec3<T>& v)
{
    a[i] += v.x;
    a[n + i] += v.y;
    a[2 * n + i] += v.z;
}

// ---- the processor ---------------------------------------------------------------------------------

// Rebuild: empty every list (release all nodes) at the start of each search, so the merge acquires a
// fresh node for every candidate; otherwise the lists persist from step to step.
template <class T, class M, class Nodes, bool Rebuild = false>
class LinkedListVariant final : public Variant {
public:
    LinkedListVariant() = default;
    LinkedListVariant(const LinkedListVariant&) = delete;
    LinkedListVariant& operator=(const LinkedListVariant&) = delete;
    ~LinkedListVariant() override { free_lists(); }

    void init(const Setup& setup) override
    {
        free_lists();
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        n_ = s.size();
        step_ = s.step;
        gear_ = GearCoefficients<T>::make(scene.dt);
        params_ = setup.contact.template as<T>();
        g_ = cast<T>(scene.gravity);
        walls_ = s.walls;
        dt_ = scene.dt;
        cell_ = T(setup.cell_size);
        for (auto* arr : {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_, &f_, &t_, &acc_, &alc_})
            arr->assign(3 * n_, T(0));
        auto load = [this](std::vector<T>& dst, const std::vector<Vec3d>& src) {
            for (std::size_t i = 0; i < n_; ++i)
                for (int c = 0; c < 3; ++c) dst[c * n_ + i] = T(component(src[i], c));
        };
        load(x_, s.trans.x); load(v_, s.trans.v); load(a_, s.trans.a);
        load(b3_, s.trans.b3); load(b4_, s.trans.b4); load(b5_, s.trans.b5);
        load(th_, s.rot.x); load(w_, s.rot.v); load(al_, s.rot.a);
        load(r3_, s.rot.b3); load(r4_, s.rot.b4); load(r5_, s.rot.b5);
        r_.resize(n_); m_.resize(n_); I_.resize(n_);
        for (std::size_t i = 0; i < n_; ++i) {
            r_[i] = T(s.radius[i]);
            m_[i] = T(setup.mass[i]);
            I_[i] = T(setup.inertia[i]);
        }
        nw_ = walls_.size();
        wp_.assign(3 * nw_, T(0)); wn_.assign(3 * nw_, T(0)); wv_.assign(3 * nw_, T(0));
        for (std::size_t w = 0; w < nw_; ++w)
            for (int c = 0; c < 3; ++c) {
                wn_[3 * w + c] = T(component(walls_[w].normal, c));
                wv_[3 * w + c] = T(component(walls_[w].velocity, c));
            }
        place_walls(step_);

        pp_head_.assign(n_, nullptr);
        pw_head_.assign(n_, nullptr);
        pp_live_ = pw_live_ = 0;
        // A dense bed keeps about three partners j > i per particle and a fraction of a wall contact;
        // the pool starts there and doubles if a scene needs more. (A no-op for the heap policy.)
        nodes_.reserve(4 * n_ + 64);
        scratch_.clear();
        scratch_.reserve(64);
        cells_.reserve(n_);
        pp_ = pw_ = candidates_ = 0;
    }

    void predict(std::int64_t step) override
    {
        step_ = step;
        gear_predictor(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), gear_);
        if constexpr (M::rotation)
            gear_predictor(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), gear_);
        place_walls(step);
    }

    void search() override
    {
        if constexpr (Rebuild) free_lists();
        if (cell_ > T(0)) search_cells();
        else search_all_pairs();
        search_walls();
    }

    void forces() override
    {
        std::fill(f_.begin(), f_.end(), T(0));
        std::fill(t_.begin(), t_.end(), T(0));
        pp_ = 0;
        pw_ = 0;
        candidates_ = std::int64_t(pp_live_);
        const std::size_t n = n_;
        const T* x = x_.data();
        const T* v = v_.data();
        const T* w = w_.data();
        // Particles in id order, each list in partner order: the canonical order of physics.md §6.
        for (std::size_t i = 0; i < n; ++i) {
            for (const Node* node = pp_head_[i]; node != nullptr; node = node->next) {
                const auto j = std::size_t(node->partner);
                ContactForce<T> c;
                if (!particle_contact<M>(get(x, n, i), get(x, n, j), get(v, n, i), get(v, n, j), get(w, n, i), get(w, n, j),
                                         r_[i], r_[j], m_[i], m_[j], params_, c))
                    continue;
                ++pp_;
                add(f_.data(), n, i, c.f_i);
                add(f_.data(), n, j, -c.f_i);
                if constexpr (M::rotation) {
                    add(t_.data(), n, i, c.t_i);
                    add(t_.data(), n, j, c.t_j);
                }
            }
        }
        for (std::size_t i = 0; i < n; ++i) {
            for (const Node* node = pw_head_[i]; node != nullptr; node = node->next) {
                const auto k = std::size_t(node->partner);
                ContactForce<T> c;
                if (!wall_contact<M>(get(x, n, i), get(v, n, i), get(w, n, i), r_[i], m_[i],
                                     Vec3<T>{wp_[3 * k], wp_[3 * k + 1], wp_[3 * k + 2]},
                                     Vec3<T>{wn_[3 * k], wn_[3 * k + 1], wn_[3 * k + 2]},
                                     Vec3<T>{wv_[3 * k], wv_[3 * k + 1], wv_[3 * k + 2]}, params_, c))
                    continue;
                ++pw_;
                add(f_.data(), n, i, c.f_i);
                if constexpr (M::rotation) add(t_.data(), n, i, c.t_i);
            }
        }
        const T g[3] = {g_.x, g_.y, g_.z};
        for (int c = 0; c < 3; ++c)
            for (std::size_t i = 0; i < n; ++i) {
                acc_[c * n + i] = acceleration(f_[c * n + i], m_[i], g[c]);
                if constexpr (M::rotation) alc_[c * n + i] = t_[c * n + i] / I_[i];
            }
    }

    void correct() override
    {
        gear_corrector(3 * n_, x_.data(), v_.data(), a_.data(), b3_.data(), b4_.data(), b5_.data(), acc_.data(), gear_);
        if constexpr (M::rotation)
            gear_corrector(3 * n_, th_.data(), w_.data(), al_.data(), r3_.data(), r4_.data(), r5_.data(), alc_.data(), gear_);
    }

    void snapshot(Snapshot& out) const override
    {
        out.resize(n_);
        out.step = step_;
        for (std::size_t i = 0; i < n_; ++i) {
            out.position[i] = cast<double>(get(x_.data(), n_, i));
            out.velocity[i] = cast<double>(get(v_.data(), n_, i));
            out.angular_velocity[i] = cast<double>(get(w_.data(), n_, i));
            out.force[i] = cast<double>(get(f_.data(), n_, i));
            out.torque[i] = cast<double>(get(t_.data(), n_, i));
        }
    }

    void save(State& out) const override
    {
        out.resize(n_);
        out.step = step_;
        out.walls = walls_;
        const std::vector<T>* src[12] = {&x_, &v_, &a_, &b3_, &b4_, &b5_, &th_, &w_, &al_, &r3_, &r4_, &r5_};
        std::vector<Vec3d>* dst[12] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                       &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int k = 0; k < 12; ++k)
            for (std::size_t i = 0; i < n_; ++i) (*dst[k])[i] = cast<double>(get(src[k]->data(), n_, i));
        for (std::size_t i = 0; i < n_; ++i) out.radius[i] = double(r_[i]);
    }

    ContactCounts counts() const override { return {pp_, pw_, candidates_}; }

    std::size_t memory_bytes() const override
    {
        return 19 * 3 * n_ * sizeof(T) + (pp_head_.size() + pw_head_.size()) * sizeof(Node*) + nodes_.bytes(pp_live_ + pw_live_) +
               scratch_.capacity() * sizeof(Index) + cells_.memory_bytes();
    }

private:
    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < nw_; ++w) {
            const Vec3d p = walls_[w].point_at(step, dt_);
            for (int c = 0; c < 3; ++c) wp_[3 * w + c] = T(component(p, c));
        }
    }

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
        const std::size_t n = n_;
        const T* x = x_.data();
        for (std::size_t i = 0; i < n; ++i) {
            ListMerge<Nodes> merge(pp_head_[i], nodes_, pp_live_);
            const Vec3<T> xi = get(x, n, i);
            for (std::size_t j = i + 1; j < n; ++j)
                if (may_touch(xi, get(x, n, j), r_[i], r_[j])) merge.keep(Index(j));
            merge.finish();
        }
    }

    // Linked cells (common/linked_cells.hpp); a particle's candidates j > i gathered ascending in a
    // scratch row, then merged into its list.
    void search_cells()
    {
        const std::size_t n = n_;
        const T* x = x_.data();
        cells_.build(n, x, x + n, x + 2 * n, cell_);
        for (std::size_t i = 0; i < n; ++i) {
            scratch_.clear();
            const Vec3<T> xi = get(x, n, i);
            cells_.for_each_above(i, [&](std::size_t j) {
                if (!may_touch(xi, get(x, n, j), r_[i], r_[j])) return;
                scratch_.push_back(Index(j));
                insert_ascending(scratch_.data(), std::int64_t(scratch_.size()) - 1, Index(j));
            });
            update_pairs(i);
        }
    }

    // Per particle, the walls in wall order: they come out ascending and merge straight into the list.
    void search_walls()
    {
        const std::size_t n = n_;
        const T* x = x_.data();
        for (std::size_t i = 0; i < n; ++i) {
            ListMerge<Nodes> merge(pw_head_[i], nodes_, pw_live_);
            const Vec3<T> xi = get(x, n, i);
            for (std::size_t w = 0; w < nw_; ++w) {
                const Vec3<T> p{wp_[3 * w], wp_[3 * w + 1], wp_[3 * w + 2]}, nv{wn_[3 * w], wn_[3 * w + 1], wn_[3 * w + 2]};
                if (may_touch_wall(xi, r_[i], p, nv)) merge.keep(Index(w));
            }
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

    std::size_t n_ = 0, nw_ = 0;
    std::int64_t step_ = 0;
    double dt_ = 0.0;
    T cell_ = T(0);
    GearCoefficients<T> gear_;
    ContactParams<T> params_;
    Vec3<T> g_;
    std::vector<Wall> walls_;
    std::vector<T> x_, v_, a_, b3_, b4_, b5_, th_, w_, al_, r3_, r4_, r5_;  // (N, 3) each
    std::vector<T> f_, t_, acc_, alc_;                                      // (N, 3) each
    std::vector<T> r_, m_, I_;                                              // (N)
    std::vector<T> wp_, wn_, wv_;                                           // (3, walls)
    // Declared before the list heads, so it outlives them on destruction (the destructor empties the
    // lists first in any case).
    Nodes nodes_;
    std::vector<Node*> pp_head_;  // (N) particle i's partners j > i, ascending
    std::vector<Node*> pw_head_;  // (N) particle i's walls, ascending
    std::size_t pp_live_ = 0, pw_live_ = 0;
    std::vector<Index> scratch_;  // one particle's candidates during the search
    LinkedCells cells_;
    std::int64_t pp_ = 0, pw_ = 0, candidates_ = 0;
};

} // namespace

void register_variant_linked_list(Registry& r)
{
    r.add({"linked_list", "arrays state; persistent per-particle linked lists of contacts, nodes from new/delete",
           [] { return std::make_unique<LinkedListVariant<double, FullModel, HeapNodes>>(); }});
    r.add({"linked_list_pool", "arrays state; persistent per-particle linked lists of contacts, nodes from a recycled pool",
           [] { return std::make_unique<LinkedListVariant<double, FullModel, PoolNodes>>(); }});
    r.add({"linked_list_rebuild", "arrays state; per-particle linked lists rebuilt every step, a new/delete per contact",
           [] { return std::make_unique<LinkedListVariant<double, FullModel, HeapNodes, true>>(); }});
}

} // namespace demmat
