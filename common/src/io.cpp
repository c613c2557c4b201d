#include "demmat/io.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/format.h>
#include <unistd.h>

#include "demmat/error.hpp"

namespace demmat {

void write_atomically(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write)
{
    namespace fs = std::filesystem;
    if (file.has_parent_path()) {
        std::error_code ec;
        fs::create_directories(file.parent_path(), ec);
    }
    const fs::path tmp = file.string() + fmt::format(".tmp{}", ::getpid());
    try {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
        write(out);
        out.flush();
        if (!out) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
        out.close();
        if (!out) throw Error(fmt::format("{}: write failed (disk full?)", file.string()));
        std::error_code ec;
        fs::rename(tmp, file, ec);
        if (ec) throw Error(fmt::format("{}: cannot move the finished file into place: {}", file.string(), ec.message()));
    } catch (...) {
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
