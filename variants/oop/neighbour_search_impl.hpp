#pragma once
// The members of the object-oriented processor's contact searches (neighbour_search.hpp).
#include <cmath>
#include <iterator>

#include "demmat/linked_cells.hpp"
#include "neighbour_search.hpp"

namespace demmat::oop {

template <class M>
std::int64_t AllPairsSearch<M>::update(std::vector<SphericalParticle<M>>& particles)
{
    std::int64_t pairs = 0;
    for (auto p = particles.begin(); p != particles.end(); ++p) {
        p->clear_neighbours();
        for (auto q = std::next(p); q != particles.end(); ++q)  // particles are stored in id order
            if (p->near(*q)) p->add_neighbour(&*q);
        pairs += std::int64_t(p->neighbours().size());
    }
    return pairs;
}

template <class M>
typename CellSearch<M>::CellKey CellSearch<M>::key_of(const SphericalParticle& p) const
{
    const Vec3d& x = p.position();
    const auto id = std::size_t(p.id());
    return {cell_coordinate(x.x / edge_, id), cell_coordinate(x.y / edge_, id), cell_coordinate(x.z / edge_, id)};
}

template <class M>
typename CellSearch<M>::Cell& CellSearch<M>::cell_at(const CellKey& key)
{
    auto [it, created] = cells_.try_emplace(key);
    Cell& cell = it->second;
    if (created)
        for (std::int64_t dz = -1; dz <= 1; ++dz)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dx = -1; dx <= 1; ++dx) {
                    if (dx == 0 && dy == 0 && dz == 0) continue;
                    const auto other = cells_.find({key.x + dx, key.y + dy, key.z + dz});
                    if (other == cells_.end()) continue;
                    cell.adjacent.push_back(&other->second);
                    other->second.adjacent.push_back(&cell);
                }
    return cell;
}

template <class M>
void CellSearch<M>::drop_empty_cells()
{
    std::erase_if(cells_, [](const auto& entry) { return entry.second.members.empty(); });
    for (auto& [key, cell] : cells_) {
        cell.adjacent.clear();
        for (std::int64_t dz = -1; dz <= 1; ++dz)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dx = -1; dx <= 1; ++dx) {
                    if (dx == 0 && dy == 0 && dz == 0) continue;
                    const auto other = cells_.find({key.x + dx, key.y + dy, key.z + dz});
                    if (other != cells_.end()) cell.adjacent.push_back(&other->second);
                }
    }
}

template <class M>
std::int64_t CellSearch<M>::update(std::vector<SphericalParticle>& particles)
{
    // Bin the particles (each cell's list ascends by id).
    for (auto& [key, cell] : cells_) cell.members.clear();
    std::size_t occupied = 0;
    for (SphericalParticle& p : particles) {
        Cell& cell = cell_at(key_of(p));
        occupied += cell.members.empty();
        cell.members.push_back(&p);
        p.clear_neighbours();
    }
    if (cells_.size() > 4 * occupied + 64) drop_empty_cells();

    // The candidates of a particle: the particles with a higher id in its cell and the 26 around it.
    for (auto& [key, cell] : cells_)
        for (SphericalParticle* p : cell.members) {
            for (SphericalParticle* q : cell.members)
                if (q->id() > p->id() && p->near(*q)) p->add_neighbour(q);
            for (const Cell* other : cell.adjacent)
                for (SphericalParticle* q : other->members)
                    if (q->id() > p->id() && p->near(*q)) p->add_neighbour(q);
        }

    std::int64_t pairs = 0;
    for (SphericalParticle& p : particles) {
        p.sort_neighbours();  // the canonical order needs partners ascending by id
        pairs += std::int64_t(p.neighbours().size());
    }
    return pairs;
}

template <class M>
std::size_t CellSearch<M>::memory_bytes() const
{
    // libstdc++ node: next pointer, key and cell (the hash is recomputed, not cached), plus buckets.
    std::size_t bytes = cells_.bucket_count() * sizeof(void*) + cells_.size() * (sizeof(void*) + sizeof(CellKey) + sizeof(Cell));
    for (const auto& [key, cell] : cells_)
        bytes += cell.members.capacity() * sizeof(SphericalParticle*) + cell.adjacent.capacity() * sizeof(Cell*);
    return bytes;
}

} // namespace demmat::oop
