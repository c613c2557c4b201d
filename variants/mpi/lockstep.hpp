#pragma once
// The mpi variant beside a reference variant (arrays) run on rank 0 from the same state: the two
// snapshots compared bit for bit after init and after every step, as compare_variants does for variants
// in one process (checker.hpp). Used by demmat_mpi compare and the mpi tests. Collective.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "mpi_variant.hpp"
#include "demmat/checker.hpp"
#include "demmat/driver.hpp"

namespace demmat::mpi {

struct LockstepResult {
    std::optional<Difference> difference;  // rank 0: the first difference, if any
    std::int64_t steps = 0;                // steps compared
};

// `mpi` is initialised here (by its Driver) from `problem`; `make_reference` is called on rank 0 only.
// Stops at the first difference. `last`, if given, receives the mpi variant's last snapshot (rank 0).
LockstepResult compare_lockstep(const Problem& problem, MpiVariant& mpi, const std::function<std::unique_ptr<Variant>()>& make_reference,
                                const std::string& reference_name, std::int64_t steps, Snapshot* last = nullptr);

} // namespace demmat::mpi
