#pragma once
// Results a run writes: VTK snapshots with a .pvd series (ParaView), and the provenance block every
// JSON result carries. All files are written atomically (io.hpp).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "demmat/variant.hpp"

namespace demmat {

// Writes DIR/<stem>_<step>.vtp (XML PolyData: points, radius, id, velocity, angular velocity, force,
// torque) and rewrites DIR/<stem>.pvd listing every snapshot written so far with its time.
class VtkSeries {
public:
    VtkSeries(std::filesystem::path dir, std::string stem) : dir_(std::move(dir)), stem_(std::move(stem)) {}
    void write(const Snapshot& s, const std::vector<double>& radius, double time);
    const std::filesystem::path& dir() const { return dir_; }

private:
    std::filesystem::path dir_;
    std::string stem_;
    std::vector<std::pair<double, std::string>> written_;
};

// {commit, dirty, compiler, flags, build_type, cpu, host, date}
nlohmann::json provenance_json();

} // namespace demmat
