#include "demmat/output.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>

#include <fmt/format.h>

#include "demmat/error.hpp"
#include "demmat/io.hpp"
#include "demmat/provenance.hpp"

namespace demmat {

namespace {
void vector_array(std::ostream& o, const char* name, const std::vector<Vec3d>& a)
{
    o << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const auto& v : a) o << fmt::format("          {:.9g} {:.9g} {:.9g}\n", v.x, v.y, v.z);
    o << "        </DataArray>\n";
}
} // namespace

void VtkSeries::write(const Snapshot& s, const std::vector<double>& radius, double time)
{
    const std::string file = fmt::format("{}_{:09d}.vtp", stem_, s.step);
    const std::size_t n = s.position.size();
    write_atomically(dir_ / file, [&](std::ostream& o) {
        o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n";
        o << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\">\n", n, n);
        o << "      <Points>\n";
        vector_array(o, "position", s.position);
        o << "      </Points>\n      <Verts>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
        for (std::size_t i = 0; i < n; ++i) o << "          " << i << "\n";
        o << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
        for (std::size_t i = 0; i < n; ++i) o << "          " << i + 1 << "\n";
        o << "        </DataArray>\n      </Verts>\n";
        o << "      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
        o << "        <DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
        for (double r : radius) o << fmt::format("          {:.9g}\n", r);
        o << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"id\" format=\"ascii\">\n";
        for (std::size_t i = 0; i < n; ++i) o << "          " << i << "\n";
        o << "        </DataArray>\n";
        vector_array(o, "velocity", s.velocity);
        vector_array(o, "angular_velocity", s.angular_velocity);
        vector_array(o, "force", s.force);
        vector_array(o, "torque", s.torque);
        o << "      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
    });
    std::string walls;
    if (!walls_.empty()) {
        walls = fmt::format("{}_walls_{:09d}.vtp", stem_, s.step);
        write_walls(walls, s.step);
    }
    written_.push_back({time, file, walls});
    // Last, so that the series never names a file that is not yet whole.
    write_atomically(dir_ / (stem_ + ".pvd"), [&](std::ostream& o) {
        o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
        for (const Written& w : written_) {
            o << fmt::format("    <DataSet timestep=\"{:.9g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", w.time, w.particles);
            if (!w.walls.empty())
                o << fmt::format("    <DataSet timestep=\"{:.9g}\" group=\"\" part=\"1\" file=\"{}\"/>\n", w.time, w.walls);
        }
        o << "  </Collection>\n</VTKFile>\n";
    });
}

void VtkSeries::write_walls(const std::string& file, std::int64_t step) const
{
    // One polygon per wall that cuts the domain box, at the wall's position for this step (a moving
    // wall's point_at, the position the variants use); the cell data name the wall by its index.
    std::vector<Vec3d> points, normal, velocity;
    std::vector<std::size_t> offsets, id;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        const Wall& wall = walls_[w];
        const std::vector<Vec3d> poly = plane_in_box(wall.point_at(step, dt_), wall.normal, domain_);
        if (poly.empty()) continue;
        points.insert(points.end(), poly.begin(), poly.end());
        offsets.push_back(points.size());
        id.push_back(w);
        normal.push_back(wall.normal);
        velocity.push_back(wall.velocity);
    }
    write_atomically(dir_ / file, [&](std::ostream& o) {
        o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n";
        o << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfPolys=\"{}\">\n", points.size(), offsets.size());
        o << "      <Points>\n";
        vector_array(o, "position", points);
        o << "      </Points>\n      <Polys>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
        for (std::size_t i = 0; i < points.size(); ++i) o << "          " << i << "\n";
        o << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
        for (std::size_t k : offsets) o << "          " << k << "\n";
        o << "        </DataArray>\n      </Polys>\n";
        o << "      <CellData Scalars=\"wall\" Vectors=\"velocity\">\n";
        o << "        <DataArray type=\"Int64\" Name=\"wall\" format=\"ascii\">\n";
        for (std::size_t w : id) o << "          " << w << "\n";
        o << "        </DataArray>\n";
        vector_array(o, "normal", normal);
        vector_array(o, "velocity", velocity);
        o << "      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
    });
}

std::int64_t vtk_snapshot_step(const std::string& name, const std::string& stem)
{
    const std::string ext = ".vtp";
    if (name.size() <= stem.size() + 1 + ext.size() || name.compare(0, stem.size() + 1, stem + "_") != 0 ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
        return -1;
    std::string digits = name.substr(stem.size() + 1, name.size() - stem.size() - 1 - ext.size());
    if (digits.rfind("walls_", 0) == 0) digits.erase(0, 6);
    std::int64_t step = -1;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), step);
    // At least 9 digits, as write() pads them; a 10-digit step has no padding.
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.size() < 9 || digits[0] == '-') return -1;
    return fmt::format("{:09d}", step) == digits ? step : -1;
}

void check_vtk_names(const std::filesystem::path& dir, const std::string& stem, std::int64_t first, std::int64_t last,
                     const std::vector<std::pair<std::filesystem::path, std::string>>& others)
{
    namespace fs = std::filesystem;
    auto in_run = [&](const fs::path& p) {
        const std::int64_t k = vtk_snapshot_step(p.filename().string(), stem);
        return k >= first && k <= last ? k : -1;
    };
    for (const auto& [path, what] : others) {
        if (path.empty()) continue;
        const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
        const std::int64_t k = in_run(path);
        if (k >= 0 && same_file(folder, dir))
            throw Error(fmt::format("--vtk {}: the snapshot of step {} would be {} {}; refusing to overwrite it", dir.string(), k, what,
                                    path.string()));
    }
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::int64_t k = in_run(it->path());
        if (k < 0) continue;
        std::error_code sc;
        const fs::file_status st = it->symlink_status(sc);
        if (!sc && st.type() != fs::file_type::regular && st.type() != fs::file_type::symlink)
            throw Error(fmt::format("--vtk {}: {}, where the snapshot of step {} goes, is not a regular file", dir.string(),
                                    it->path().filename().string(), k));
    }
}

std::vector<Vec3d> plane_in_box(const Vec3d& point, const Vec3d& normal, const Box& box)
{
    // The box's corners on the plane (to a tolerance relative to the box's size, so a wall on a face of
    // the box gives that face) and the points where its edges cross the plane strictly between corners.
    Vec3d corner[8];
    double side[8];
    const Vec3d diag = box.max - box.min;
    const double eps = 1e-12 * std::sqrt(dot(diag, diag));
    for (int k = 0; k < 8; ++k) {
        corner[k] = {(k & 1) ? box.max.x : box.min.x, (k & 2) ? box.max.y : box.min.y, (k & 4) ? box.max.z : box.min.z};
        side[k] = dot(corner[k] - point, normal);
        if (std::abs(side[k]) <= eps) side[k] = 0.0;
    }
    std::vector<Vec3d> out;
    for (int k = 0; k < 8; ++k)
        if (side[k] == 0.0) out.push_back(corner[k]);
    for (int a = 0; a < 8; ++a)
        for (int bit = 1; bit < 8; bit <<= 1) {
            const int b = a | bit;  // each edge once, from the corner without the bit
            if (b == a || side[a] == 0.0 || side[b] == 0.0 || (side[a] < 0.0) == (side[b] < 0.0)) continue;
            out.push_back(corner[a] + (side[a] / (side[a] - side[b])) * (corner[b] - corner[a]));
        }
    if (out.size() < 3) return {};
    // Ordered by angle around the normal (u, v, normal right-handed): the polygon faces into the domain.
    Vec3d centre{};
    for (const Vec3d& p : out) centre += p;
    centre = centre / double(out.size());
    const double ax = std::abs(normal.x), ay = std::abs(normal.y), az = std::abs(normal.z);
    const Vec3d least = ax <= ay && ax <= az ? Vec3d{1, 0, 0} : (ay <= az ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1});
    const Vec3d u = cross(normal, least);
    const Vec3d v = cross(normal, u);
    auto angle = [&](const Vec3d& p) { return std::atan2(dot(p - centre, v), dot(p - centre, u)); };
    std::sort(out.begin(), out.end(), [&](const Vec3d& p, const Vec3d& q) { return angle(p) < angle(q); });
    return out;
}

nlohmann::json provenance_json()
{
    const Provenance& p = build_provenance();
    const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    return {{"commit", p.commit}, {"dirty", p.dirty},        {"compiler", p.compiler}, {"flags", p.flags},
            {"build_type", p.build_type}, {"cpu", cpu_model()}, {"host", host_name()}, {"date", date}};
}

} // namespace demmat
