// The Object Pascal port of the arrays processor (the paper's DEMMAT_PAS), demmat_pas.pas, built by fpc
// into libdemmat_pas.so and driven through its cdecl exports by the shared PortVariant
// (engines/ports/include/demmat/port_variant.hpp). The Pascal state lives in global dynamic arrays, one record
// per instance slot (a small fixed table, demmat_pas_max_instances()); a handle is a slot index, and
// creating one more instance than there are slots throws demmat::Error.
#include <cstdint>
#include <memory>

#include <fmt/format.h>

#include "demmat/port_variant.hpp"
#include "demmat/registry.hpp"

extern "C" {
int demmat_pas_create();
void demmat_pas_destroy(int h);
int demmat_pas_max_instances();
void demmat_pas_init(int h, int n, int nw, int cap, int wcap, double cell, const double* radius, const double* mass,
                     const double* inertia, const double* gear, const double* wn, const double* wv, const double* grav,
                     const double* coef, const double* contact);
void demmat_pas_set_walls(int h, const double* wp);
void demmat_pas_predict(int h, const double* wp);
void demmat_pas_search(int h, int* status, std::int64_t* info, std::int64_t* particle);
void demmat_pas_forces(int h);
void demmat_pas_correct(int h);
void demmat_pas_get(int h, int which, double* out);
void demmat_pas_counts(int h, std::int64_t* out);
}

namespace demmat {

void register_variant_pascal(Registry& r)
{
    static const PortApi<int> api{
        demmat_pas_create,
        [](int h) { return h >= 0; },
        [] {
            return fmt::format("pascal: at most {} live instances (the Pascal state is a global table of {} slots); destroy one "
                               "before creating another", demmat_pas_max_instances(), demmat_pas_max_instances());
        },
        demmat_pas_destroy, demmat_pas_init, demmat_pas_set_walls, demmat_pas_predict, demmat_pas_search,
        demmat_pas_forces, demmat_pas_correct, demmat_pas_get, demmat_pas_counts};
    r.add({"pascal", "Object Pascal port (the paper's DEMMAT_PAS), global dynamic arrays, Free Pascal, driven through cdecl exports",
           [] { return std::make_unique<PortVariant<int>>(api); }});
}

} // namespace demmat
