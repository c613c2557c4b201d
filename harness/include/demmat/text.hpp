#pragma once
// Comma-separated lists from the command line (--variants a,b; --families=phases,stream).
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

namespace demmat {

// The items of "a,b,c" in order; empty items (",," or a trailing comma) are dropped.
inline std::vector<std::string> split_list(std::string_view text, char separator = ',')
{
    std::vector<std::string> items;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(separator, start), text.size());
        if (end > start) items.emplace_back(text.substr(start, end - start));
        start = end + 1;
    }
    return items;
}

} // namespace demmat
