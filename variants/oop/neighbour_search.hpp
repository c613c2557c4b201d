#pragma once
// Contact searches of the object-oriented processor: each rebuilds every particle's list of pointers
// to candidate partners (higher ids, ascending by id). The strategy is chosen once, at init. Templates on
// the model M, as the particles are (bodies.hpp); the members are defined in neighbour_search_impl.hpp,
// instantiated for the paper's model in neighbour_search.cpp (a translation unit of its own, as before the
// laws of physics.md §9 existed) and for the laws' models in oop_laws.cpp.
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "bodies.hpp"

namespace demmat::oop {

template <class M>
class NeighbourSearch {
public:
    virtual ~NeighbourSearch() = default;
    // Rebuilds the neighbour list of every particle; returns the number of candidate pairs kept.
    virtual std::int64_t update(std::vector<SphericalParticle<M>>& particles) = 0;
    virtual std::size_t memory_bytes() const = 0;
};

// Every pair (the paper's "no cells"), O(N²).
template <class M>
class AllPairsSearch final : public NeighbourSearch<M> {
public:
    std::int64_t update(std::vector<SphericalParticle<M>>& particles) override;
    std::size_t memory_bytes() const override { return 0; }
};

// Cubic cells of a given edge, kept in a hash map from cell coordinates to cell objects, so memory
// follows the particles, not the extent of the domain. A cell knows the existing cells around it (linked
// when it is created), so a step looks up one cell per particle, not 27; a cell's lists keep their
// capacity from step to step, and cells left empty are dropped when they outnumber the occupied ones.
template <class M>
class CellSearch final : public NeighbourSearch<M> {
    using SphericalParticle = oop::SphericalParticle<M>;

public:
    explicit CellSearch(double edge) : edge_(edge) {}

    std::int64_t update(std::vector<SphericalParticle>& particles) override;
    std::size_t memory_bytes() const override;

private:
    struct CellKey {
        std::int64_t x, y, z;
        friend bool operator==(const CellKey&, const CellKey&) = default;
    };
    struct CellKeyHash {
        std::size_t operator()(const CellKey& k) const noexcept
        {
            const std::uint64_t h = std::uint64_t(k.x) * 73856093ull ^ std::uint64_t(k.y) * 19349663ull ^
                                    std::uint64_t(k.z) * 83492791ull;
            return std::size_t(h * 0x9e3779b97f4a7c15ull >> 16);
        }
    };
    struct Cell {
        std::vector<SphericalParticle*> members;  // ascending by id
        std::vector<Cell*> adjacent;              // the existing cells among the 26 around this one
    };

    CellKey key_of(const SphericalParticle& p) const;
    Cell& cell_at(const CellKey& key);  // finds the cell, or creates it and links it to its neighbours
    void drop_empty_cells();

    double edge_;
    std::unordered_map<CellKey, Cell, CellKeyHash> cells_;  // nodes: a Cell never moves in memory
};

extern template class AllPairsSearch<FullModel>;
extern template class CellSearch<FullModel>;

} // namespace demmat::oop
