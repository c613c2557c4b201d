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
// torque), with walls also DIR/<stem>_walls_<step>.vtp (each wall's plane at that step clipped to the
// domain box, one polygon per wall, a quad for a face of the box), and rewrites DIR/<stem>.pvd listing
// every snapshot written so far with its time: the particles as part 0, the walls as part 1.
class VtkSeries {
public:
    VtkSeries(std::filesystem::path dir, std::string stem, Box domain = {}, std::vector<Wall> walls = {}, double dt = 0.0)
        : dir_(std::move(dir)), stem_(std::move(stem)), domain_(domain), walls_(std::move(walls)), dt_(dt) {}
    void write(const Snapshot& s, const std::vector<double>& radius, double time);
    const std::filesystem::path& dir() const { return dir_; }

private:
    struct Written {
        double time;
        std::string particles, walls;  // file names; walls empty without walls
    };
    void write_walls(const std::string& file, std::int64_t step) const;

    std::filesystem::path dir_;
    std::string stem_;
    Box domain_;
    std::vector<Wall> walls_;
    double dt_;
    std::vector<Written> written_;
};

// The step of a snapshot file name of the series `stem` (<stem>_<step>.vtp or <stem>_walls_<step>.vtp),
// or -1 when `name` is not one.
std::int64_t vtk_snapshot_step(const std::string& name, const std::string& stem);

// Refuses (Error, one line), before a run, every name the series `stem` in `dir` could write for a step in
// [first, last] (a blow-up writes the failing step, so every step of the run counts) that is one of
// `others` (the inputs, which must not be overwritten, and the other outputs), or that exists and is not
// a regular file or a symbolic link (a folder where a snapshot goes would fail only after the run).
void check_vtk_names(const std::filesystem::path& dir, const std::string& stem, std::int64_t first, std::int64_t last,
                     const std::vector<std::pair<std::filesystem::path, std::string>>& others);

// The polygon where the plane through `point` with normal `normal` cuts the box, its corners in order
// around the normal (3 to 6 corners; empty when the plane misses the box or only touches an edge).
std::vector<Vec3d> plane_in_box(const Vec3d& point, const Vec3d& normal, const Box& box);

// {commit, dirty, compiler, flags, build_type, cpu, host, date}
nlohmann::json provenance_json();

} // namespace demmat
