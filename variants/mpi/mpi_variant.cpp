// The mpi variant's entry: the plan rank 0 makes at init (the model, the bricks), sent to every rank, and
// the instantiation for that model (with_model, as the specialising variants pick theirs).
#include "mpi_variant.hpp"

#include <algorithm>

#include "rank_processor.hpp"
#include "demmat/features.hpp"

namespace demmat::mpi {

namespace {

// The largest distance at which two grains can touch is 2·R_max; the halo's relative margin covers the
// rounding of a coordinate's distance to a face (about 1e-16 relative), so no contact is missed.
constexpr double kHaloMargin = 1.000001;
// The neighbour list's skin in units of R_max, fast's default (variants/fast/fast.hpp).
constexpr double kSkin = 0.3;

std::vector<double> plan_to_doubles(const Plan& p)
{
    const ModelFeatures& f = p.features;
    const Bricks& b = p.bricks;
    std::vector<double> d = {double(f.rotation), double(f.friction), double(f.damping), double(f.walls), double(f.moving_walls),
                             double(f.polydisperse), p.radius_max, p.cell, p.halo, p.r0, p.m0, p.skin,
                             double(b.dims[0]), double(b.dims[1]), double(b.dims[2]), b.area[0], b.area[1], b.area[2]};
    for (const std::vector<double>& c : b.cuts) d.insert(d.end(), c.begin(), c.end());
    return d;
}

Plan plan_from_doubles(const std::vector<double>& d)
{
    Plan p;
    p.features = {d[0] != 0.0, d[1] != 0.0, d[2] != 0.0, d[3] != 0.0, d[4] != 0.0, d[5] != 0.0};
    p.radius_max = d[6];
    p.cell = d[7];
    p.halo = d[8];
    p.r0 = d[9];
    p.m0 = d[10];
    p.skin = d[11];
    auto at = d.begin() + 18;
    for (std::size_t a = 0; a < 3; ++a) {
        p.bricks.dims[a] = int(d[12 + a]);
        p.bricks.area[a] = d[15 + a];
        p.bricks.cuts[a].assign(at, at + p.bricks.dims[a] + 1);
        at += p.bricks.dims[a] + 1;
    }
    return p;
}

// Rank 0 plans from the whole state; every rank receives the plan, or the reason there is none (every
// rank then throws it, so that all exit with the one-line error).
Plan share_plan(const Comm& comm, const Setup& setup, const MpiOptions& options)
{
    std::string failure;
    std::vector<double> data;
    if (comm.root()) {
        const State& s = *setup.state;
        Plan p;
        p.features = model_for(setup);
        p.radius_max = setup.radius_max;
        p.skin = kSkin * setup.radius_max;
        p.halo = (2.0 * setup.radius_max + p.skin) * kHaloMargin;
        // Cells as wide as the longest listed pair, or the scene's if wider (they only add candidates): the
        // search never changes the contact set (physics.md §5), so neither does this choice.
        p.cell = std::max(setup.cell_size, 2.0 * setup.radius_max) + p.skin;
        if (s.size() > 0) {
            p.r0 = s.radius[0];
            p.m0 = setup.mass[0];
        }
        failure = plan_bricks(s.trans.x, comm.size(), p.halo, options.balance, options.grid, p.bricks);
        data = plan_to_doubles(p);
    }
    comm.broadcast(failure);
    if (!failure.empty()) throw AllRanksError(failure);
    comm.broadcast(data);
    return plan_from_doubles(data);
}

// The registered face of the variant: init makes the plan and picks the instantiation, every call is
// forwarded to it.
class MpiDispatch final : public MpiVariant {
public:
    MpiDispatch(MPI_Comm comm, const MpiOptions& options) : comm_(comm), options_(options) {}

    void init(const Setup& setup) override
    {
        const Plan plan = share_plan(comm_, setup, options_);
        ModelFeatures need = plan.features;  // the law's flags come from the scene, which every rank has
        const ModelFeatures law = law_features(setup.scene->contact_model);
        need.restitution_damping = law.restitution_damping;
        need.history = law.history;
        need.rolling = law.rolling;
        impl_ = need.beyond_paper() ? make_rank_processor_law(need, comm_, plan) : make_rank_processor_paper(need, comm_, plan);
        impl_->init(setup);
    }
    bool supports(const ContactModel&) const override { return true; }  // every law of physics.md §9
    void predict(std::int64_t step) override { impl_->predict(step); }
    void search() override { impl_->search(); }
    void forces() override { impl_->forces(); }
    void correct() override { impl_->correct(); }
    void snapshot(Snapshot& out) const override { impl_->snapshot(out); }
    void save(State& out) const override { impl_->save(out); }
    ContactCounts counts() const override { return impl_ ? impl_->counts() : ContactCounts{}; }
    std::size_t memory_bytes() const override { return impl_ ? impl_->memory_bytes() : 0; }
    void rejoin() const override { comm().barrier(); }  // after rank 0's health check
    ModelFeatures model() const override { return impl_ ? impl_->model() : ModelFeatures::full(); }
    const Comm& comm() const override { return impl_ ? impl_->comm() : comm_; }
    RankReport local_report() const override
    {
        if (impl_) return impl_->local_report();
        RankReport r;
        r.rank = comm_.rank();
        return r;
    }
    double communicate_seconds() const override { return impl_ ? impl_->communicate_seconds() : 0.0; }
    const Bricks& bricks() const override { return impl_->bricks(); }
    double halo() const override { return impl_->halo(); }

private:
    Comm comm_;
    MpiOptions options_;
    std::unique_ptr<MpiVariant> impl_;
};

} // namespace

std::vector<RankReport> MpiVariant::rank_reports() const
{
    const RankReport me = local_report();
    const std::vector<double> mine = {double(me.rank), double(me.owned), double(me.ghosts), double(me.owned_max), double(me.steps),
                                      double(me.migrants), double(me.rebuilds), double(me.traffic.messages), double(me.traffic.bytes),
                                      me.traffic.seconds};
    const std::vector<double> all = comm().gather(mine);
    std::vector<RankReport> out;
    for (std::size_t k = 0; k + 10 <= all.size(); k += 10)
        out.push_back({int(all[k]), std::int64_t(all[k + 1]), std::int64_t(all[k + 2]), std::int64_t(all[k + 3]), std::int64_t(all[k + 4]),
                       std::int64_t(all[k + 5]), std::int64_t(all[k + 6]), Traffic{std::int64_t(all[k + 7]), std::int64_t(all[k + 8]), all[k + 9]}});
    return out;
}

std::unique_ptr<MpiVariant> make_mpi_variant(MPI_Comm comm, const MpiOptions& options)
{
    auto v = std::make_unique<MpiDispatch>(comm, options);
    v->set_registered_name("mpi");
    return v;
}

} // namespace demmat::mpi
