#pragma once
// Output files are written whole or not at all: to a temporary file beside the target, flushed, then
// synced to disk, then renamed into place, so an interrupted run leaves the previous file or the complete
// new one.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace demmat {

void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write);
void write_atomically(const std::filesystem::path& file, const std::string& content);

// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGQUIT that remove the temporary file being written
// (if any) and then die of the signal as usual, so Ctrl-C leaves no partial file behind. (SIGKILL cannot
// be caught: it may leave a stray FILE.tmpPID beside an intact FILE.) Called once by the demmat program.
void remove_partial_files_on_signal();

} // namespace demmat
