// The contact searches of the object-oriented processor for the paper's model (the laws of physics.md §9
// instantiate theirs in oop_laws.cpp).
#include "neighbour_search_impl.hpp"

namespace demmat::oop {

template class AllPairsSearch<FullModel>;
template class CellSearch<FullModel>;

} // namespace demmat::oop
