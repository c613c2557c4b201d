// The fast variant's registration and its dispatch: init() picks the instantiation of Fast<M>
// (fast_variant.hpp) for what the scene needs (fast_models.hpp) and forwards every phase to it.
#include <memory>
#include <utility>

#include "demmat/error.hpp"
#include "demmat/features.hpp"
#include "demmat/registry.hpp"
#include "fast.hpp"
#include "fast_models.hpp"

namespace demmat {
namespace {

using namespace demmat::fast;

class FastDispatch final : public FastVariant {
public:
    explicit FastDispatch(const FastOptions& o) : opt_(o) {}

    // Every law of physics.md §9 in the canonical order (gear5 in double); fast_unordered the paper's only.
    bool supports(const ContactModel& law) const override { return opt_.canonical || law.is_paper(); }

    void init(const Setup& setup) override
    {
        const ModelFeatures need = model_for(setup);
        if (need.beyond_paper() && !opt_.canonical) throw Error("fast_unordered runs the paper's contact law only");
        if (need.beyond_paper()) impl_ = make_fast_law(need, opt_);
        else if (need.polydisperse) impl_ = make_fast_paper_poly(paper_level(need), opt_);
        else impl_ = make_fast_paper_mono(paper_level(need), opt_);
        impl_->init(setup);
    }
    void predict(std::int64_t step) override { impl_->predict(step); }
    void search() override { impl_->search(); }
    void forces() override { impl_->forces(); }
    void correct() override { impl_->correct(); }
    void snapshot(Snapshot& out) const override { impl_->snapshot(out); }
    void save(State& out) const override { impl_->save(out); }
    ContactCounts counts() const override { return impl_ ? impl_->counts() : ContactCounts{}; }
    std::size_t memory_bytes() const override { return impl_ ? impl_->memory_bytes() : 0; }
    ModelFeatures model() const override { return impl_ ? impl_->model() : ModelFeatures::full(); }
    int threads_used() const override { return impl_ ? impl_->threads_used() : 1; }
    std::int64_t rebuilds() const override { return impl_ ? impl_->rebuilds() : 0; }

private:
    FastOptions opt_;
    std::unique_ptr<FastVariant> impl_;
};

} // namespace

std::unique_ptr<FastVariant> make_fast_variant(const FastOptions& options) { return std::make_unique<FastDispatch>(options); }

void register_variant_fast(Registry& r)
{
    r.add({"fast", "data-oriented SoA in cell order, skin neighbour list, OpenMP; canonical order, bit-identical to arrays",
           [] { return make_fast_variant(FastOptions{}); }, true, true});
    VariantInfo u{"fast_unordered", "fast without the canonical order: plain accumulation (not bit-identical to arrays)",
                  [] {
                      FastOptions unordered;  // the default skin, so that only the order differs
                      unordered.canonical = false;
                      return make_fast_variant(unordered);
                  }};
    u.bitwise = false;
    u.threaded = true;
    r.add(std::move(u));
}

} // namespace demmat
