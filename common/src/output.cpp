#include "demmat/output.hpp"

#include <chrono>
#include <ctime>
#include <sstream>

#include <fmt/format.h>

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
    written_.emplace_back(time, file);
    write_atomically(dir_ / (stem_ + ".pvd"), [&](std::ostream& o) {
        o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
        for (const auto& [t, f] : written_)
            o << fmt::format("    <DataSet timestep=\"{:.9g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", t, f);
        o << "  </Collection>\n</VTKFile>\n";
    });
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
