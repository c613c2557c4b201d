#pragma once
// Output files are written whole or not at all: to a temporary file beside the target, flushed, then
// renamed into place, so an interrupted run leaves the previous file or the complete new one.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace demmat {

void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write);
void write_atomically(const std::filesystem::path& file, const std::string& content);

} // namespace demmat
