#pragma once
// Exchange with the production DEM codes LAMMPS and LIGGGHTS (docs/peers.md): a state as a LAMMPS data
// file (atom_style sphere; LIGGGHTS reads the same file as atom_style granular), the scene's physics as
// input-script fragments for each code, and a LAMMPS data file or text dump read back into a State, so
// that every code starts from the identical particles.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "demmat/scene.hpp"
#include "demmat/state.hpp"

namespace demmat {

struct PeerExport {
    std::string data;                                         // LAMMPS data file
    std::string lammps;                                       // LAMMPS input fragment (reads the data file)
    std::string liggghts;                                     // LIGGGHTS 3.8 input fragment (reads the data file)
    std::vector<std::pair<std::string, std::string>> meshes;  // LIGGGHTS STL files: (file name, content)
    std::string note;                                         // why there is no LIGGGHTS fragment, if there is none
    std::string warning;                                      // what the export could not carry (a state's stretches), if anything
};

struct PeerOptions {
    std::string data_name = "scene.data";  // the data file's name as the fragments refer to it
    std::string mesh_prefix = "scene";     // STL files are <prefix>_<wall>.stl
    double skin = 0.0;                     // neighbour skin (m); 0: half the smallest radius
};

// LAMMPS's fix wall/gran (and wall/gran/region) with hertz/material in the installed version (29 Sep 2021)
// turns its modulus argument E into the contact's effective modulus as E/(2(1-ν)), where the pair style
// uses 1/((1-ν_i²)/E_i + (1-ν_j²)/E_j); measured by a sphere resting on a wall (docs/peers.md). The argument
// that gives the suite's E* for a wall contact is therefore 2(1-ν)·E*.
double lammps_wall_modulus_argument(double e_star_wall, double poisson);

// The LIGGGHTS hertz/stiffness damping is γ·m*·sqrt(R*·δ); the coefficient that equals the suite's
// constant γ_n·m* at the reference overlap: the rest overlap of a grain of mean radius on a wall.
double liggghts_reference_sqrt_rdelta(const Scene& scene, const State& state);

PeerExport export_peers(const Scene& scene, const State& state, const PeerOptions& options);

// Adds to every velocity a random vector with components uniform in [-amplitude, amplitude] (splitmix64
// from seed, the same on every machine): the perturbed starts of an ensemble.
void perturb_velocities(State& state, double amplitude, std::uint64_t seed);

// Reads a LAMMPS data file (atom_style sphere, as written above) or a LAMMPS text dump (the last frame;
// columns named in ITEM: ATOMS, which must hold id, x, y, z and radius or diameter; velocities and omegas
// are zero when absent) into a State for `scene`: positions, velocities, angular velocities and radii in
// id order, the scene's walls at step 0, and t = 0 accelerations a = F/m + g, α = T/I by the reference
// code (b3 = b4 = b5 = 0), as for any new scene. Throws Error naming the file and line on bad input.
State import_peer_state(const std::filesystem::path& file, const Scene& scene);

// One frame of a LAMMPS-style text dump (id radius x y z vx vy vz omegax omegay omegaz) at `step`.
std::string lammps_dump_frame(std::int64_t step, const Scene& scene, const std::vector<double>& radius,
                              const std::vector<Vec3d>& x, const std::vector<Vec3d>& v, const std::vector<Vec3d>& w);

} // namespace demmat
