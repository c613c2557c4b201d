#include "demmat/io.hpp"

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>

#include <ext/stdio_filebuf.h>  // an ostream over the descriptor opened with O_EXCL

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include "demmat/error.hpp"

namespace demmat {

namespace {

// The temporary file being written, for the signal handler: a fixed buffer, because unlink() is all a
// handler may safely do with it.
char g_partial[4096];
constexpr std::size_t kMaxNameBytes = 255;  // NAME_MAX of Linux's file systems
volatile std::sig_atomic_t g_writing = 0;
constexpr int kCleanedSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

extern "C" void remove_partial_and_die(int sig)
{
    if (g_writing) ::unlink(g_partial);
    ::signal(sig, SIG_DFL);
    ::raise(sig);  // die of the signal as if no handler were installed (the parent sees the signal)
}

// fsync of a folder through a read-only descriptor: the rename itself must reach the disk.
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

// A temporary file beside `file` that did not exist before (O_EXCL, never through a symbolic link): FILE.tmpPID,
// or FILE.tmpPID-K if that name is taken, with FILE shortened so that the name fits the 255 bytes a file
// name may have (a legal 255-byte output name must not fail after the run).
int open_fresh_temporary(const std::filesystem::path& file, std::filesystem::path& tmp)
{
    const std::string name = file.filename().string();
    for (int k = 0; k < 1000; ++k) {
        const std::string suffix = k == 0 ? fmt::format(".tmp{}", ::getpid()) : fmt::format(".tmp{}-{}", ::getpid(), k);
        tmp = file.parent_path() / (name.substr(0, std::min(name.size(), kMaxNameBytes - suffix.size())) + suffix);
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0) return fd;
        if (errno != EEXIST) throw Error(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
    }
    throw Error(fmt::format("{}: cannot write: no free temporary name beside it", file.string()));
}

const char* kind_of(mode_t mode)
{
    return S_ISDIR(mode) ? "a directory" : S_ISCHR(mode) ? "a character device" : S_ISBLK(mode) ? "a block device"
         : S_ISFIFO(mode) ? "a pipe (FIFO)" : S_ISSOCK(mode) ? "a socket" : "not a regular file";
}

} // namespace

void refuse_special_file(const std::filesystem::path& file, const std::string& option)
{
    // lstat: a symbolic link is replaced by the rename, never written through, so only the name itself counts.
    struct stat st {};
    if (::lstat(file.c_str(), &st) != 0 || S_ISREG(st.st_mode) || S_ISLNK(st.st_mode)) return;
    throw Error(fmt::format("{}{}: is {}, not a regular file; an output is written whole to a temporary file and renamed into "
                            "place, which would replace it (write to a file, or '-' for standard output where the option takes it)",
                            option.empty() ? "" : option + " ", file.string(), kind_of(st.st_mode)));
}

void remove_partial_files_on_signal()
{
    struct sigaction sa {};
    sa.sa_handler = remove_partial_and_die;
    sigemptyset(&sa.sa_mask);
    for (int sig : kCleanedSignals) ::sigaction(sig, &sa, nullptr);
}

void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write)
{
    namespace fs = std::filesystem;
    if (file.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(file.parent_path(), ec);
    }
    fs::path tmp;
    int fd = -1;
    {
        // The signals that remove the partial file wait until its name is recorded for the handler.
        sigset_t block, old;
        sigemptyset(&block);
        for (int sig : kCleanedSignals) sigaddset(&block, sig);
        ::sigprocmask(SIG_BLOCK, &block, &old);
        try {
            fd = open_fresh_temporary(file, tmp);
        } catch (...) {
            ::sigprocmask(SIG_SETMASK, &old, nullptr);
            throw;
        }
        const std::string tmp_name = tmp.string();
        if (tmp_name.size() < sizeof g_partial) {
            std::memcpy(g_partial, tmp_name.c_str(), tmp_name.size() + 1);
            g_writing = 1;
        }
        ::sigprocmask(SIG_SETMASK, &old, nullptr);
    }
    try {
        {
            // The descriptor opened with O_EXCL is the one written: no name is opened twice.
            __gnu_cxx::stdio_filebuf<char> buf(fd, std::ios::out | std::ios::binary, 1 << 16);
            std::ostream out(&buf);
            write(out);
            out.flush();
            if (!out) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
            // The data must be on disk before the rename makes it the file, or a crash of the machine
            // could leave an empty file under the new name.
            if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS)  // EINVAL/EROFS: the file system does not sync
                throw Error(fmt::format("{}: write failed: {}", file.string(), std::strerror(errno)));
            if (!buf.close()) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
        }
        refuse_special_file(file, "");  // checked before the run too; again here, just before the rename
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

std::string read_input_file(const std::filesystem::path& file, const std::string& what, std::uintmax_t max_bytes)
{
    const std::string label = file.string();
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(fmt::format("{}: cannot open {}: {}", label, what, std::strerror(errno)));
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw Error(fmt::format("{}: cannot open {}: {}", label, what, std::strerror(errno)));
    if (!S_ISREG(st.st_mode)) {
        throw Error(fmt::format("{}: cannot read it as a {}: it is {}, not a regular file", label, what, kind_of(st.st_mode)));
    }
    if (std::uintmax_t(st.st_size) > max_bytes)
        throw Error(fmt::format("{}: the {} is {} bytes, more than the {} bytes a {} may have", label, what,
                                std::uintmax_t(st.st_size), max_bytes, what));
    // Read up to the size announced, and one byte past the cap at most (a file that grows while read).
    std::string bytes;
    bytes.reserve(std::size_t(st.st_size));
    char buf[1 << 16];
    for (;;) {
        const ssize_t got = ::read(fd, buf, sizeof buf);
        if (got < 0) {
            if (errno == EINTR) continue;
            throw Error(fmt::format("{}: cannot read {}: {}", label, what, std::strerror(errno)));
        }
        if (got == 0) break;
        bytes.append(buf, std::size_t(got));
        if (bytes.size() > max_bytes)
            throw Error(fmt::format("{}: the {} grew past the {} bytes a {} may have while it was read", label, what, max_bytes, what));
    }
    return bytes;
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b)
{
    namespace fs = std::filesystem;
    std::error_code ea, eb;
    if (fs::exists(a, ea) && fs::exists(b, eb)) {
        std::error_code ec;
        const bool same = fs::equivalent(a, b, ec);
        if (!ec) return same;
    }
    std::error_code ca, cb;
    const fs::path pa = fs::weakly_canonical(fs::absolute(a), ca), pb = fs::weakly_canonical(fs::absolute(b), cb);
    return !ca && !cb && pa == pb;
}

namespace {
// The nearest folder above `p` that exists (p's own parent, else "."'s ancestors): it must be a directory
// this process may write into.
void check_writable_ancestor(const std::filesystem::path& p, const std::string& option, const std::filesystem::path& shown)
{
    namespace fs = std::filesystem;
    fs::path dir = fs::absolute(p).parent_path();
    std::error_code ec;
    while (!dir.empty() && !fs::exists(dir, ec) && dir != dir.root_path()) dir = dir.parent_path();
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("{} {}: {} is not a directory", option, shown.string(), dir.string()));
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw Error(fmt::format("{} {}: cannot write into {}: {}", option, shown.string(), dir.string(), std::strerror(errno)));
}
} // namespace

void check_output_path(const std::filesystem::path& file, const std::string& option, const std::vector<NamedPath>& inputs)
{
    namespace fs = std::filesystem;
    if (file.empty()) throw Error(fmt::format("{}: an empty file name", option));
    std::error_code ec;
    if (fs::is_directory(file, ec)) throw Error(fmt::format("{} {}: is a directory, not a file", option, file.string()));
    if (file.filename().string().size() > kMaxNameBytes)
        throw Error(fmt::format("{} {}...: a file name of {} bytes, more than the {} a file name may have", option,
                                file.string().substr(0, 40), file.filename().string().size(), kMaxNameBytes));
    refuse_special_file(file, option);
    for (const auto& [input, what] : inputs)
        if (!input.empty() && same_file(file, input))
            throw Error(fmt::format("{} {}: is the input {} {}; refusing to overwrite it", option, file.string(), what, input.string()));
    check_writable_ancestor(file, option, file);
}

void check_output_folder(const std::filesystem::path& dir, const std::string& option)
{
    namespace fs = std::filesystem;
    if (dir.empty()) throw Error(fmt::format("{}: an empty folder name", option));
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw Error(fmt::format("{} {}: exists and is not a directory", option, dir.string()));
    check_writable_ancestor(dir / "x", option, dir);
}

std::string safe_file_stem(const std::string& text)
{
    std::string out;
    for (const unsigned char c : text) {
        if (out.size() == 200) break;
        const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
        out += keep && !(c == '.' && out.empty()) ? char(c) : '_';
    }
    return out.empty() ? "unnamed" : out;
}

} // namespace demmat
