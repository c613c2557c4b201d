#pragma once
// The mpi variant: the processor spread over the ranks of an MPI communicator by spatial domain
// decomposition (bricks.hpp), bit-identical to arrays for any number of ranks (docs/variants/mpi.md).
// One instance per rank, each driven by its own Driver in lockstep. It is not in the registry (a
// program that runs it must be started by mpirun): demmat_mpi and the mpi tests make it here.
//
// Collective calls: init and the four phases (they exchange migrants and ghosts with the brick
// neighbours), and snapshot, save, counts and rank_reports, which every rank must call together;
// snapshot and save fill their output on rank 0 only (the others get no particles).
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "comm.hpp"
#include <array>

#include "bricks.hpp"
#include "demmat/error.hpp"
#include "demmat/problem.hpp"
#include "demmat/variant.hpp"

namespace demmat::mpi {

struct MpiOptions {
    Balance balance = Balance::count;
    std::array<int, 3> grid = {0, 0, 0};  // bricks along x, y, z; zeros: the grid whose cuts have the least area
};

// One rank's share: particles owned now, ghosts received at the last step, and its traffic so far.
struct RankReport {
    int rank = 0;
    std::int64_t owned = 0, ghosts = 0, owned_max = 0;  // owned_max: the most it owned after any step
    std::int64_t steps = 0;                              // steps taken since init
    std::int64_t migrants = 0;                           // particles it handed to a neighbour since init
    std::int64_t rebuilds = 0;                           // neighbour-list rebuilds since init (every rank alike)
    Traffic traffic;                                     // sent to neighbours since init (migrants and ghosts)
};

// An error every rank throws at once (bad input found by rank 0 and sent to all, a process count the
// scene cannot be split into): the program prints it once and every rank exits normally, non-zero.
class AllRanksError : public Error {
public:
    using Error::Error;
};

class MpiVariant : public Variant {
public:
    virtual const Comm& comm() const = 0;
    // This rank's report (not collective).
    virtual RankReport local_report() const = 0;
    // Rank 0 gets every rank's report, in rank order; the others an empty vector. Collective.
    std::vector<RankReport> rank_reports() const;
    // This rank's seconds spent exchanging with its neighbours (inside the search phase) since init.
    virtual double communicate_seconds() const = 0;
    virtual const Bricks& bricks() const = 0;
    virtual double halo() const = 0;  // m: ghosts are the particles within this distance of a shared face
};

std::unique_ptr<MpiVariant> make_mpi_variant(MPI_Comm comm, const MpiOptions& options = {});

// The problem on every rank, from rank 0's: rank 0 calls `load` (reading the scene and its state);
// every other rank gets the scene (sent as its TOML text, without the particles) and a state with no
// particles that holds the step, the fingerprint and the walls. If `load` throws on rank 0, every rank
// throws its message as an AllRanksError, so that all exit together. Collective.
std::unique_ptr<Problem> share_problem(const Comm& comm, const std::function<std::unique_ptr<Problem>()>& load);

} // namespace demmat::mpi
