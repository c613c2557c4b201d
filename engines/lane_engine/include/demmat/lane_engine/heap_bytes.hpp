#pragma once
// The heap bytes a part of the fast variant holds: each part sums its own containers next to their
// declarations, and the variant's memory_bytes() sums the parts.
#include <cstddef>

namespace demmat::fast {

// Vectors, vectors of vectors or of parts with a bytes() of their own (their own and their elements'
// heap), and such parts themselves.
template <class C>
std::size_t heap_bytes(const C& c)
{
    if constexpr (requires { c.bytes(); }) {
        return c.bytes();
    } else if constexpr (requires { c.front().capacity(); }) {
        std::size_t b = c.capacity() * sizeof(c.front());
        for (const auto& inner : c) b += heap_bytes(inner);
        return b;
    } else if constexpr (requires { c.front().bytes(); }) {
        std::size_t b = c.capacity() * sizeof(c.front());
        for (const auto& inner : c) b += inner.bytes();
        return b;
    } else {
        return c.capacity() * sizeof(typename C::value_type);
    }
}
template <class... C>
std::size_t heap_bytes(const C&... c)
{
    return (heap_bytes(c) + ...);
}

} // namespace demmat::fast
