#include "demmat/io.hpp"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include "demmat/error.hpp"

namespace demmat {

namespace {

// The temporary file being written, for the signal handler: a fixed buffer, because unlink() is all a
// handler may safely do with it.
char g_partial[4096];
volatile std::sig_atomic_t g_writing = 0;

extern "C" void remove_partial_and_die(int sig)
{
    if (g_writing) ::unlink(g_partial);
    ::signal(sig, SIG_DFL);
    ::raise(sig);  // die of the signal as if no handler were installed (the parent sees the signal)
}

// fsync through a read-only descriptor (std::ofstream exposes none): the data must be on disk before
// the rename makes it the file, or a crash of the machine could leave an empty file under the new name.
void sync_path(const std::filesystem::path& p, int flags)
{
    const int fd = ::open(p.c_str(), O_RDONLY | flags);
    if (fd < 0) return;  // nothing to sync (e.g. a directory that cannot be opened): not an error
    const int rc = ::fsync(fd);
    const int err = errno;
    ::close(fd);
    if (rc != 0 && err != EINVAL && err != EROFS)  // EINVAL/EROFS: the file system does not sync (pipes, some FUSE)
        throw Error(fmt::format("{}: write failed: {}", p.string(), std::strerror(err)));
}

} // namespace

void remove_partial_files_on_signal()
{
    struct sigaction sa {};
    sa.sa_handler = remove_partial_and_die;
    sigemptyset(&sa.sa_mask);
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) ::sigaction(sig, &sa, nullptr);
}

void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write)
{
    namespace fs = std::filesystem;
    if (file.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(file.parent_path(), ec);
    }
    const fs::path tmp = file.string() + fmt::format(".tmp{}", ::getpid());
    const std::string tmp_name = tmp.string();
    if (tmp_name.size() < sizeof g_partial) {
        g_writing = 0;
        std::memcpy(g_partial, tmp_name.c_str(), tmp_name.size() + 1);
        g_writing = 1;
    }
    try {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
        write(out);
        out.flush();
        if (!out) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
        out.close();
        if (!out) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
        sync_path(tmp, 0);
        std::error_code ec;
        fs::rename(tmp, file, ec);
        if (ec) throw Error(fmt::format("{}: cannot move the finished file into place: {}", file.string(), ec.message()));
        g_writing = 0;
        sync_path(file.has_parent_path() ? file.parent_path() : fs::path("."), O_DIRECTORY);  // the rename itself
    } catch (...) {
        g_writing = 0;
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
}

void write_atomically(const std::filesystem::path& file, const std::string& content)
{
    write_atomically(file, [&](std::ostream& out) { out << content; });
}

} // namespace demmat
