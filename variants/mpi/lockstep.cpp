#include "lockstep.hpp"

#include <fmt/format.h>

namespace demmat::mpi {

LockstepResult compare_lockstep(const Problem& problem, MpiVariant& mpi, const std::function<std::unique_ptr<Variant>()>& make_reference,
                                const std::string& reference_name, std::int64_t steps, Snapshot* last)
{
    const Comm& comm = mpi.comm();
    Driver driver(mpi, problem.setup());
    std::unique_ptr<Variant> ref;
    std::unique_ptr<Driver> ref_driver;
    if (comm.root()) {
        ref = make_reference();
        ref_driver = std::make_unique<Driver>(*ref, problem.setup());
    }
    LockstepResult out;
    Snapshot a, b;
    auto same = [&] {
        mpi.snapshot(b);
        int diverged = 0;
        if (comm.root()) {
            ref->snapshot(a);
            if (auto d = first_difference(a, b)) {
                d->variant_a = reference_name;
                d->variant_b = fmt::format("mpi at {} processes", comm.size());
                out.difference = *d;
                diverged = 1;
            }
        }
        MPI_Bcast(&diverged, 1, MPI_INT, 0, comm.handle());  // every rank stops at the same step
        return diverged == 0;
    };
    bool ok = same();
    for (std::int64_t k = 1; k <= steps && ok; ++k) {
        driver.step();
        if (ref_driver) ref_driver->step();
        ok = same();
        out.steps = k;
    }
    if (last) *last = b;
    return out;
}

} // namespace demmat::mpi
