#pragma once
// Output files are written whole or not at all: to a temporary file beside the target, flushed, then
// synced to disk, then renamed into place, so an interrupted run leaves the previous file or the complete
// new one.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace demmat {

// The temporary file has a fresh name (FILE.tmpPID, created with O_EXCL, never through a symbolic link),
// and an existing FILE that is not a regular file (a device, a pipe, a folder) is refused, never replaced.
void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write);
void write_atomically(const std::filesystem::path& file, const std::string& content);

// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGQUIT that remove the temporary file being written
// (if any) and then die of the signal as usual, so Ctrl-C leaves no partial file behind. (SIGKILL cannot
// be caught: it may leave a stray FILE.tmpPID beside an intact FILE.) Called once by the demmat program.
void remove_partial_files_on_signal();

// The bytes of an input file, refused with one line naming the file unless it is a regular file (not a
// directory, device or pipe: /dev/zero would be read until memory runs out) of at most max_bytes.
// `what` names the kind in messages ("scene file", "state file").
std::string read_input_file(const std::filesystem::path& file, const std::string& what, std::uintmax_t max_bytes);

// An input a command reads, as an output must not overwrite it: (path, what it is, e.g. "scene file").
using NamedPath = std::pair<std::filesystem::path, std::string>;

// Refuses (Error, one line naming `option`) a path that exists and is neither a regular file nor a
// symbolic link (which the rename replaces, never writes through): a device, a pipe, a socket, a folder.
void refuse_special_file(const std::filesystem::path& file, const std::string& option);

// Checks an output path before any work, so that a bad path fails in a second, not after the run:
// not an existing directory, device, pipe or socket, a name of at most 255 bytes, not one of `inputs` (the same file by inode, or by canonical path when it
// does not exist yet), and the nearest existing folder above it is a directory this process may write
// into (write_atomically creates the missing folders below it). `option` names it in the message.
void check_output_path(const std::filesystem::path& file, const std::string& option, const std::vector<NamedPath>& inputs);
// The same for a folder that will receive files (--vtk DIR): an existing one must be a directory.
void check_output_folder(const std::filesystem::path& dir, const std::string& option);
// Whether two paths name the same file (same inode when both exist, else the same canonical path).
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// A file-name stem made from text a scene supplies (its name, a wall's name): letters, digits, '-',
// '_' and '.' are kept, every other byte (a '/' above all) becomes '_', a leading '.' too (no "..",
// no hidden files), at most 200 bytes; "unnamed" when nothing is left. Output files named from scene
// text therefore always land in the folder chosen for them.
std::string safe_file_stem(const std::string& text);

} // namespace demmat
