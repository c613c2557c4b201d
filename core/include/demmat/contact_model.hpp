#pragma once
// Which contact law a scene asks for: the paper's (physics.md §2) unless its [contact] table names
// another (§9, docs/scene-format.md). This is the scene's choice as written; the per-run constants the
// law needs (α, 8·G*, …) are derived from it once, by memory_params (contact_memory.hpp).
#include <string>
#include <vector>

namespace demmat {

enum class NormalDamping { viscous, tsuji, restitution };
enum class TangentialModel { viscous, linear_history, mindlin };
enum class RollingModel { none, sds };
// How a spring's stretch advances (physics.md §9): LAMMPS's first-order ξ ← ξ + u·Δt, or the trapezoidal
// update with the contact's onset placed inside its first step.
enum class StretchUpdate { first_order, trapezoidal };

struct ContactModel {
    NormalDamping damping = NormalDamping::viscous;  // viscous: the paper's γ_n·m*
    double restitution = 0.0;                        // e in (0, 1], for tsuji and restitution
    TangentialModel tangential = TangentialModel::viscous;
    double kt = 0.0;                                 // N/m, linear_history
    double tangential_damping_ratio = 0.0;           // x_γt: η_t = x_γt·η_n (history models)
    RollingModel rolling = RollingModel::none;
    double kr = 0.0;                                 // N/m, sds
    double rolling_damping = 0.0;                    // γ_r, N·s/m, sds
    double rolling_friction = 0.0;                   // μ_r, sds
    StretchUpdate stretch_update = StretchUpdate::first_order;  // history and rolling springs

    bool has_spring() const { return tangential != TangentialModel::viscous || rolling != RollingModel::none; }

    bool is_paper() const
    {
        return damping == NormalDamping::viscous && tangential == TangentialModel::viscous && rolling == RollingModel::none;
    }
    // "damping tsuji (e = 0.6), tangential linear_history (kt = 1000 N/m, x_γt = 0.5), rolling none"
    std::string describe() const;
    // The [contact] table as scene_to_toml writes it; empty for the paper's law (old scenes read as before).
    std::string toml() const;
    // Values that enter Scene::fingerprint; none for the paper's law, so its fingerprints stay as they were.
    std::vector<double> fingerprint_values() const;
};

const char* name(NormalDamping d);
const char* name(TangentialModel t);
const char* name(RollingModel r);
const char* name(StretchUpdate u);

} // namespace demmat
