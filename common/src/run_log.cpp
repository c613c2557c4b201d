#include "demmat/run_log.hpp"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <fmt/format.h>
#include <unistd.h>

#include "demmat/driver.hpp"
#include "demmat/error.hpp"
#include "demmat/reference.hpp"
#include "demmat/stability.hpp"

namespace demmat {

LogRow measure_log_row(const Snapshot& s, const Setup& setup)
{
    const State& st = *setup.state;
    const double dt = setup.gear.dt;
    LogRow r;
    r.step = s.step;
    r.time = double(s.step) * dt;  // as Driver::time(): from the integer step, never accumulated
    const KineticEnergy ke = kinetic_energy_parts(s, setup);
    r.kinetic_translational = ke.translational;
    r.kinetic_rotational = ke.rotational;
    for (std::size_t i = 0; i < s.position.size(); ++i)
        r.gravitational -= setup.mass[i] * dot(setup.scene->gravity, s.position[i]);
    r.wall_force.assign(st.walls.size(), Vec3d{});
    // A state that has blown up between two health checks has no contact set (a cell list cannot place
    // a non-finite or runaway position): its row says so with NaN, and the driver's check stops the run.
    const double far = 1e15 * setup.radius_max;
    for (const Vec3d& x : s.position)
        if (!(std::abs(x.x) < far && std::abs(x.y) < far && std::abs(x.z) < far)) {
            r.elastic = r.largest_overlap_ratio = std::nan("");
            for (Vec3d& f : r.wall_force) f = {r.elastic, r.elastic, r.elastic};
            return r;
        }
    r.elastic = elastic_energy(s.position, st.radius, st.walls, s.step, dt, setup.contact);

    // Contacts through the law itself (h > 0 exactly as the variants decide it). The paper's full model:
    // a scene's own model of that law differs only by terms that are zero for it, so the forces are the
    // same (a law of physics.md §9 needs the variant's stretches: demmat run refuses --log for it).
    for (const auto& [i, j] : contact_pairs(s.position, st.radius, false)) {
        ContactForce<double> c;
        if (!particle_contact<FullModel>(s.position[i], s.position[j], s.velocity[i], s.velocity[j], s.angular_velocity[i],
                                         s.angular_velocity[j], st.radius[i], st.radius[j], setup.mass[i], setup.mass[j],
                                         setup.contact, c))
            continue;
        ++r.contacts_particle;
        r.largest_overlap_ratio = std::max(r.largest_overlap_ratio, c.overlap / std::min(st.radius[i], st.radius[j]));
    }
    for (std::size_t w = 0; w < st.walls.size(); ++w) {
        const Wall& wall = st.walls[w];
        const Vec3d p = wall.point_at(s.step, dt);
        for (std::size_t i = 0; i < s.position.size(); ++i) {
            ContactForce<double> c;
            if (!wall_contact<FullModel>(s.position[i], s.velocity[i], s.angular_velocity[i], st.radius[i], setup.mass[i], p,
                                         wall.normal, wall.velocity, setup.contact, c))
                continue;
            ++r.contacts_wall;
            r.largest_overlap_ratio = std::max(r.largest_overlap_ratio, c.overlap / st.radius[i]);
            r.wall_force[w] += -c.f_i;  // the reaction: the particle pushes the wall with −f_i
        }
    }
    return r;
}

std::string log_header(std::size_t walls)
{
    std::string h = "step,time,kinetic_translational,kinetic_rotational,gravitational,elastic,total,contacts_particle,"
                    "contacts_wall,largest_overlap_ratio";
    for (std::size_t w = 0; w < walls; ++w) h += fmt::format(",wall{0}_fx,wall{0}_fy,wall{0}_fz", w);
    return h;
}

std::string log_line(const LogRow& r)
{
    std::string line = fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{},{},{:.17g}", r.step, r.time,
                                   r.kinetic_translational, r.kinetic_rotational, r.gravitational, r.elastic, r.total(),
                                   r.contacts_particle, r.contacts_wall, r.largest_overlap_ratio);
    for (const Vec3d& f : r.wall_force) line += fmt::format(",{:.17g},{:.17g},{:.17g}", f.x, f.y, f.z);
    return line;
}

void check_log_path(const std::filesystem::path& log, const std::vector<std::filesystem::path>& inputs)
{
    namespace fs = std::filesystem;
    if (log.empty()) throw Error("--log: an empty file name");
    if (log == kStandardOutput) return;
    std::error_code ec;
    if (fs::is_directory(log, ec))
        throw Error(fmt::format("--log {}: is a folder; give a file name for the run log", log.string()));
    const fs::path folder = log.has_parent_path() ? log.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, ec))
        throw Error(fmt::format("--log {}: the folder {} does not exist", log.string(), folder.string()));
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw Error(fmt::format("--log {}: cannot write in the folder {}: {}", log.string(), folder.string(), std::strerror(errno)));
    if (!fs::exists(log, ec)) return;
    for (const fs::path& in : inputs)
        if (!in.empty() && fs::equivalent(log, in, ec))
            throw Error(fmt::format("--log {}: is an input of the run ({}); it would be overwritten", log.string(), in.string()));
    if (::access(log.c_str(), W_OK) != 0)
        throw Error(fmt::format("--log {}: cannot write: {}", log.string(), std::strerror(errno)));
}

void check_log_every(std::int64_t every)
{
    if (every < 1) throw Error(fmt::format("--log-every {}: must be at least 1 step", every));
}

RunLog::RunLog(const std::filesystem::path& file, const Setup& setup, std::int64_t every)
    : file_(file), setup_(setup), every_(every)
{
    check_log_every(every_);
    if (file_ == kStandardOutput) {
        fd_ = STDOUT_FILENO;
        owned_ = false;
    } else {
        // Truncated only once this run holds the lock: a second run on the same log is refused, never
        // interleaved with the first (two writers would tear each other's rows).
        fd_ = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
        if (fd_ < 0) throw Error(fmt::format("{}: cannot write: {}", file_.string(), std::strerror(errno)));
        std::string refused;
        struct stat st {};
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0)
            refused = fmt::format("--log {}: another run is writing this log (it is locked); give each run its own log", file_.string());
        else if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode) && ::ftruncate(fd_, 0) != 0)
            refused = fmt::format("{}: cannot write: {}", file_.string(), std::strerror(errno));
        if (!refused.empty()) {
            ::close(fd_);  // a throwing constructor runs no destructor
            throw Error(refused);
        }
    }
    append(log_header(setup_.state->walls.size()));
}

RunLog::~RunLog()
{
    if (fd_ >= 0 && owned_) ::close(fd_);  // closing also releases the lock
}

void RunLog::write(const Snapshot& s) { append(log_line(measure_log_row(s, setup_))); }

void RunLog::append(const std::string& line)
{
    // One write call per row (a short write, e.g. a full disk, is an error): the row reaches the file at
    // once, whole, for a reader that plots it while the run goes on.
    const std::string text = line + "\n";
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error(fmt::format("{}: write failed: {}", file_.string(), n < 0 ? std::strerror(errno) : "disk full?"));
        done += std::size_t(n);
    }
}

} // namespace demmat
