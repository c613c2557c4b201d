// The per-run constants of the §9 contact laws (contact_memory.hpp), and the solve that gives the
// `restitution` damping its α.
#include "demmat/contact_memory.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "demmat/scene.hpp"

namespace demmat {

double tsuji_alpha(double e)
{
    const double e2 = e * e, e3 = e2 * e, e4 = e3 * e, e5 = e4 * e, e6 = e5 * e;
    return 1.2728 - 4.2783 * e + 11.087 * e2 - 22.348 * e3 + 27.467 * e4 - 18.022 * e5 + 4.8218 * e6;
}

// A head-on impact under F_n = K·h^(3/2) + α·sqrt(m*·K·sqrt(h))·dh/dt, clipped at F_n >= 0, in the units
// h₀ = (m*·v²/K)^(2/5) and t₀ = h₀/v (v the impact speed): every constant drops out but α, and
//     h'' = −max(0, h^(3/2) + α·h^(1/4)·h'),   h(0) = 0, h'(0) = 1,
// so the rebound −h' at the end does not depend on v, m*, R* or E*. Integrated with classical RK4 at
// the fixed step kStep until h < 0 on the way out. Near the end the damping term, ∝ h^(1/4), outweighs the
// elastic one, ∝ h^(3/2), so the clipped force is zero and the speed no longer changes: −h' at the
// first step past h = 0 is the rebound. A contact still closed at t = 200 (an overdamped creep, whose
// speed tends to zero) rebounds at 0 (head_on_rebound). Halving kStep changes the rebound by less than
// 2·10⁻⁷ for α up to 2 (e down to about 0.15), and the rebound agrees with an independent integration
// of the law in SI units to 2·10⁻⁶ (tests/test_memory.cpp, RestitutionSolveMatchesAnIndependentIntegration).
namespace {
constexpr double kStep = 1e-4;
} // namespace

double dimensionless_rebound(double alpha)
{
    return head_on_rebound(
        [alpha](double h, double v) {
            const double hp = std::max(h, 0.0);
            const double f = hp * std::sqrt(hp) + alpha * std::sqrt(std::sqrt(hp)) * v;
            return f > 0.0 ? -f : 0.0;
        },
        kStep);
}

// The rebound falls monotonically from 1 at α = 0, so α is bracketed (doubling from 1) and bisected until
// the bracket is narrower than 1e-10·α: the α returned gives e to within the integration's error.
double restitution_alpha(double e)
{
    if (e >= 1.0) return 0.0;
    thread_local double last_e = -1.0, last_alpha = 0.0;  // Setup::make and the t = 0 forces ask for the same e
    if (e == last_e) return last_alpha;
    last_alpha = damping_for_rebound(dimensionless_rebound, e);
    last_e = e;
    return last_alpha;
}

std::string describe_law(const ContactModel& law, const MemoryParams<double>& q)
{
    if (law.damping == NormalDamping::viscous) return law.describe();
    return fmt::format("{}; η_n = α·sqrt(m*·k_n) with α = {:.10g}{}", law.describe(), q.alpha,
                       law.damping == NormalDamping::restitution ? " (solved for the restitution)" : " (Tsuji's fit)");
}

MemoryParams<double> memory_params(const Scene& scene)
{
    const ContactModel& m = scene.contact_model;
    MemoryParams<double> q;
    if (m.is_paper()) return q;
    if (m.damping == NormalDamping::tsuji) q.alpha = tsuji_alpha(m.restitution);
    if (m.damping == NormalDamping::restitution) q.alpha = restitution_alpha(m.restitution);
    // Mindlin's 1/G* = 2(2−ν_i)(1+ν_i)/E_i + 2(2−ν_j)(1+ν_j)/E_j, from E and ν only (not the scene's `shear`).
    // A rigid wall adds nothing to 1/G* (physics.md §9).
    auto shear_term = [](const Material& x) { return x.rigid ? 0.0 : 2.0 * (2.0 - x.poisson) * (1.0 + x.poisson) / x.young; };
    q.shear8_pp = 8.0 / (shear_term(scene.material) + shear_term(scene.material));
    q.shear8_pw = 8.0 / (shear_term(scene.material) + shear_term(scene.wall_mat()));
    q.mindlin = m.tangential == TangentialModel::mindlin;
    q.trapezoidal = m.stretch_update == StretchUpdate::trapezoidal;
    q.kt = m.kt;
    q.ratio_t = m.tangential_damping_ratio;
    q.kr = m.kr;
    q.gamma_r = m.rolling_damping;
    q.mu_r = m.rolling_friction;
    q.dt = scene.dt;
    return q;
}

} // namespace demmat
