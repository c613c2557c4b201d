// The Fortran 90 port of the arrays processor (the paper's DEMMAT_F90), demmat_f90.f90, driven through
// its bind(C) entry points by the shared PortVariant (engines/ports/include/demmat/port_variant.hpp).
#include <cstdint>
#include <memory>

#include "demmat/port_variant.hpp"
#include "demmat/registry.hpp"

extern "C" {
void* demmat_f90_create();
void demmat_f90_destroy(void* h);
void demmat_f90_init(void* h, int n, int nw, int cap, int wcap, double cell, const double* radius, const double* mass,
                     const double* inertia, const double* gear, const double* wn, const double* wv, const double* grav,
                     const double* coef, const double* contact);
void demmat_f90_set_walls(void* h, const double* wp);
void demmat_f90_predict(void* h, const double* wp);
void demmat_f90_search(void* h, int* status, std::int64_t* info, std::int64_t* particle);
void demmat_f90_forces(void* h);
void demmat_f90_correct(void* h);
void demmat_f90_get(void* h, int which, double* out);
void demmat_f90_counts(void* h, std::int64_t* out);
}

namespace demmat {

void register_variant_f90(Registry& r)
{
    static const PortApi<void*> api{
        demmat_f90_create,
        [](void* h) { return h != nullptr; },
        [] { return std::string("f90: the Fortran processor could not be allocated"); },
        demmat_f90_destroy, demmat_f90_init, demmat_f90_set_walls, demmat_f90_predict, demmat_f90_search,
        demmat_f90_forces, demmat_f90_correct, demmat_f90_get, demmat_f90_counts};
    r.add({"f90", "Fortran 90 port of the arrays processor (the paper's DEMMAT_F90), driven through bind(C)",
           [] { return std::make_unique<PortVariant<void*>>(api); }});
}

} // namespace demmat
