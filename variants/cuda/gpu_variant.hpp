#pragma once
// The GPU-style processor over a backend: particles in backend memory in cell order, the four phases as
// launches of the kernels in kernels.hpp. Backend B supplies memory (alloc, upload, download), launch,
// a sort of (key, slot) pairs, and sync; the device backend (cuda.cu) runs on a GPU, the host backend
// (host_backend.hpp) runs the same kernel bodies on the CPU in shuffled block order. Host and backend
// memory meet only in init, snapshot, save and counts, and in one status read per search (32 bytes:
// capacity overflows and runaway positions, which stop the run as in the arrays variant).
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "demmat/features.hpp"
#include "demmat/state.hpp"
#include "demmat/variant.hpp"
#include "kernels.hpp"

namespace demmat::gpu {

// Throws the run-stopping error a non-zero status word reports (status.cpp, host code).
void throw_status(const unsigned long long (&status)[kStatusWords], std::uint32_t cap_above, std::uint32_t row_cap,
                  std::uint32_t cap_walls, std::size_t walls);
// Refuses a scene the variant cannot hold (more than kMaxWalls walls, 2^32 − 1 particles).
void check_size(std::size_t particles, std::size_t walls);
// The error for a state whose contacts overflow a row of stretches (`cap` entries) at `particle`.
[[noreturn]] void throw_state_overflow(std::uint32_t cap, bool wall, std::int64_t particle);

template <class B, class M>
class GpuVariant final : public Variant {
public:
    explicit GpuVariant(B backend) : be_(std::move(backend)) {}

    void init(const Setup& setup) override
    {
        const State& s = *setup.state;
        const Scene& scene = *setup.scene;
        check_size(s.size(), s.walls.size());
        be_.release();
        const std::uint32_t n = std::uint32_t(s.size());
        walls_ = s.walls;
        dt_ = scene.dt;
        step_ = s.step;
        v_ = View{};
        v_.n = n;
        std::uint64_t buckets = 2;
        while (buckets < 2ull * n) buckets *= 2;
        v_.bucket_mask = buckets - 1;
        bucket_bits_ = 0;
        while ((std::uint64_t(1) << bucket_bits_) < buckets) ++bucket_bits_;
        v_.cell = setup.cell_size;
        v_.cap_above = std::uint32_t(scene.capacity.contacts_per_particle);
        v_.cap_walls = std::uint32_t(scene.capacity.wall_contacts_per_particle);
        v_.row_cap = 2 * v_.cap_above;  // partners on both sides
        v_.params = setup.contact;
        v_.memory = setup.memory;
        v_.gravity = scene.gravity;
        v_.gear = setup.gear;
        if constexpr (!M::polydisperse)  // one radius and mass: the contacts' coefficients once per run
            if (n > 0) {
                v_.mono_pp = pair_coefficients(s.radius[0], s.radius[0], setup.mass[0], setup.mass[0], v_.params);
                v_.mono_pw = wall_coefficients(s.radius[0], setup.mass[0], v_.params);
            }
        v_.walls.count = int(walls_.size());
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            v_.walls.normal[w] = walls_[w].normal;
            v_.walls.velocity[w] = walls_[w].velocity;
        }
        place_walls(step_);

        const std::size_t n3 = 3 * std::size_t(n);
        for (Particles* b : {&v_.p, &v_.q}) {
            for (auto& g : b->gear) g = be_.template alloc<double>(n3);
            b->radius = be_.template alloc<double>(n);
            b->mass = be_.template alloc<double>(n);
            b->inertia = be_.template alloc<double>(n);
            b->id = be_.template alloc<std::uint32_t>(n);
            b->cell = be_.template alloc<std::uint64_t>(n);
        }
        for (double** a : {&v_.force, &v_.torque, &v_.acc, &v_.alpha}) *a = be_.template alloc<double>(n3);
        v_.row = be_.template alloc<std::uint64_t>(std::size_t(n) * v_.row_cap);
        for (std::uint32_t** a : {&v_.row_count, &v_.wall_mask, &v_.candidates, &v_.contacts, &v_.wall_contacts, &v_.key_slot, &v_.sorted_slot})
            *a = be_.template alloc<std::uint32_t>(n);
        for (std::uint64_t** a : {&v_.key, &v_.sorted_key, &v_.cell_tmp}) *a = be_.template alloc<std::uint64_t>(n);
        for (std::uint32_t** a : {&v_.bucket_begin, &v_.bucket_end}) *a = be_.template alloc<std::uint32_t>(buckets);
        v_.status = be_.template alloc<unsigned long long>(kStatusWords);
        if constexpr (M::memory) {  // two sets of rows each for pairs (both sides) and walls, zero: no contact yet
            for (StretchRows* r : {&v_.pairs_then, &v_.pairs_now}) alloc_rows(*r, v_.row_cap);
            for (StretchRows* r : {&v_.walls_then, &v_.walls_now}) alloc_rows(*r, v_.cap_walls);
        }

        // Slot = id to start with (the first search sorts).
        std::array<std::vector<double>, kGearArrays> cols;
        std::array<std::vector<double>*, kGearArrays> dst;
        for (int k = 0; k < kGearArrays; ++k) dst[k] = &cols[k];
        load_gear_columns<double>(s, dst);
        for (int k = 0; k < kGearArrays; ++k) be_.upload(v_.p.gear[k], cols[k].data(), n3);
        std::vector<std::uint32_t> ids(n);
        for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
        be_.upload(v_.p.radius, s.radius.data(), n);
        be_.upload(v_.p.mass, setup.mass.data(), n);
        be_.upload(v_.p.inertia, setup.inertia.data(), n);
        be_.upload(v_.p.id, ids.data(), n);
        if constexpr (M::memory) load_stretches(s.stretches);
        be_.sync();
    }

    // Each phase ends with the backend synchronised, so that the driver's clock times the phase's work.
    void predict(std::int64_t step) override
    {
        step_ = step;
        if constexpr (M::moving_walls) place_walls(step);  // fixed walls stay where init put them
        be_.launch(3ull * v_.n, Predict<M>{v_});
        be_.sync();
    }

    void search() override
    {
        const std::uint32_t n = v_.n;
        if (n > 0) {
            be_.launch(n, MakeKeys{v_});
            be_.sort(v_.key, v_.sorted_key, v_.key_slot, v_.sorted_slot, n, 32 + (v_.cell > 0.0 ? bucket_bits_ : 0));
            be_.launch(n, Gather{v_});
            std::swap(v_.p, v_.q);
            be_.launch(v_.bucket_mask + 1, ClearBuckets{v_});
            be_.launch(n, FindBuckets{v_});
            be_.launch(n, Search<M>{v_});
        }
        unsigned long long status[kStatusWords];
        be_.download(status, v_.status, kStatusWords);  // synchronises
        throw_status(status, v_.cap_above, v_.row_cap, v_.cap_walls, walls_.size());
    }

    void forces() override
    {
        be_.launch(v_.n, Forces<M>{v_});
        if constexpr (M::memory) {  // this evaluation's rows are the next one's "then"
            std::swap(v_.pairs_then, v_.pairs_now);
            std::swap(v_.walls_then, v_.walls_now);
        }
        be_.sync();
    }

    void correct() override
    {
        be_.launch(3ull * v_.n, Correct<M>{v_});
        be_.sync();
    }

    void snapshot(Snapshot& out) const override
    {
        const std::size_t n = v_.n;
        out.resize(n);
        out.step = step_;
        const std::vector<std::uint32_t> id = fetch(v_.p.id, n);
        const double* src[5] = {v_.p.gear[0], v_.p.gear[1], v_.p.gear[7], v_.force, v_.torque};
        std::vector<Vec3d>* dst[5] = {&out.position, &out.velocity, &out.angular_velocity, &out.force, &out.torque};
        for (int k = 0; k < 5; ++k) {
            const std::vector<double> a = fetch(src[k], 3 * n);
            for (std::size_t s = 0; s < n; ++s) (*dst[k])[id[s]] = {a[s], a[n + s], a[2 * n + s]};
        }
    }

    void save(State& out) const override
    {
        const std::size_t n = v_.n;
        out.resize(n);
        out.step = step_;
        out.walls = walls_;
        const std::vector<std::uint32_t> id = fetch(v_.p.id, n);
        std::vector<Vec3d>* dst[kGearArrays] = {&out.trans.x, &out.trans.v, &out.trans.a, &out.trans.b3, &out.trans.b4, &out.trans.b5,
                                                &out.rot.x,   &out.rot.v,   &out.rot.a,   &out.rot.b3,   &out.rot.b4,   &out.rot.b5};
        for (int k = 0; k < kGearArrays; ++k) {
            const std::vector<double> a = fetch(v_.p.gear[k], 3 * n);
            for (std::size_t s = 0; s < n; ++s) (*dst[k])[id[s]] = {a[s], a[n + s], a[2 * n + s]};
        }
        const std::vector<double> r = fetch(v_.p.radius, n);
        for (std::size_t s = 0; s < n; ++s) out.radius[id[s]] = r[s];
        out.stretches.clear();
        if constexpr (M::memory) {
            save_stretches(v_.pairs_then, id, false, out.stretches);
            save_stretches(v_.walls_then, id, true, out.stretches);
            std::sort(out.stretches.begin(), out.stretches.end());  // the canonical order: by particle, pairs, then walls
        }
    }

    ContactCounts counts() const override
    {
        ContactCounts c;
        for (std::uint32_t k : fetch(v_.candidates, v_.n)) c.candidates += k;
        for (std::uint32_t k : fetch(v_.contacts, v_.n)) c.particle_particle += k;
        if constexpr (M::walls)
            for (std::uint32_t k : fetch(v_.wall_contacts, v_.n)) c.particle_wall += k;
        return c;
    }

    std::size_t memory_bytes() const override { return be_.bytes(); }
    ModelFeatures model() const override { return ModelFeatures::of<M>(); }

private:
    template <class T>
    std::vector<T> fetch(const T* src, std::size_t count) const
    {
        std::vector<T> out(count);
        if (count > 0) be_.download(out.data(), src, count);
        return out;
    }

    void alloc_rows(StretchRows& r, std::uint32_t cap)
    {
        r.cap = cap;
        r.count = be_.template alloc<std::uint32_t>(v_.n);
        r.key = be_.template alloc<std::uint32_t>(std::size_t(v_.n) * cap);
        r.spring = be_.template alloc<double>(3 * std::size_t(kSprings<M>) * v_.n * cap);
    }

    // A state's stretches into the "then" rows, slot = id as init leaves it: each pair in both of its
    // particles' rows, each wall contact in its particle's, keys ascending (the canonical order gives it).
    void load_stretches(std::vector<ContactStretch> in)
    {
        if (in.empty()) return;  // the rows are zero: no contact yet
        std::sort(in.begin(), in.end());
        const std::size_t n = v_.n;
        struct Host {
            std::vector<std::uint32_t> count, key;
            std::vector<double> spring;
        } pairs, walls;
        for (Host* h : {&pairs, &walls}) h->count.assign(n, 0);
        pairs.key.assign(n * v_.row_cap, 0);
        walls.key.assign(n * v_.cap_walls, 0);
        pairs.spring.assign(3 * kSprings<M> * n * v_.row_cap, 0.0);
        walls.spring.assign(3 * kSprings<M> * n * v_.cap_walls, 0.0);
        auto add = [&](Host& h, std::uint32_t cap, bool wall, std::uint32_t s, std::uint32_t key, const ContactStretch& c) {
            if (h.count[s] == cap) throw_state_overflow(cap, wall, s);
            const std::size_t k = h.count[s]++;
            h.key[k * n + s] = key;
            Stretch<double> st{c.tangential, c.rolling};
            std::size_t comp = 0;
            for_each_spring<M>(st, [&](const Vec3<double>& x) {
                for (double value : {x.x, x.y, x.z}) h.spring[(comp++ * cap + k) * n + s] = value;
            });
        };
        for (const ContactStretch& c : in) {  // pairs below a particle come before its own (i ascending)
            const auto i = std::uint32_t(c.i), j = std::uint32_t(c.partner);
            if (c.wall) {
                add(walls, v_.cap_walls, true, i, j, c);
            } else {
                add(pairs, v_.row_cap, false, i, j, c);
                add(pairs, v_.row_cap, false, j, i, c);
            }
        }
        for (auto [h, r] : {std::pair{&pairs, &v_.pairs_then}, std::pair{&walls, &v_.walls_then}}) {
            be_.upload(r->count, h->count.data(), h->count.size());
            be_.upload(r->key, h->key.data(), h->key.size());
            be_.upload(r->spring, h->spring.data(), h->spring.size());
        }
    }

    // The live contacts of the last evaluation as a state holds them: each pair once, from its lower id's row.
    void save_stretches(const StretchRows& r, const std::vector<std::uint32_t>& id, bool wall, std::vector<ContactStretch>& out) const
    {
        const std::size_t n = v_.n;
        const std::vector<std::uint32_t> count = fetch(r.count, n), key = fetch(r.key, n * r.cap);
        const std::vector<double> spring = fetch(r.spring, 3 * kSprings<M> * n * r.cap);
        for (std::size_t s = 0; s < n; ++s)
            for (std::size_t k = 0; k < count[s]; ++k) {
                const std::uint32_t partner = key[k * n + s];
                if (!wall && partner < id[s]) continue;  // the pair's other copy, in its lower particle's row
                Stretch<double> st{};
                std::size_t comp = 0;
                for_each_spring<M>(st, [&](Vec3<double>& x) {
                    for (double* value : {&x.x, &x.y, &x.z}) *value = spring[(comp++ * r.cap + k) * n + s];
                });
                out.push_back({std::int64_t(id[s]), std::int64_t(partner), wall, st.t, st.r});
            }
    }

    // The walls' positions of this step, computed on the host as the arrays variant does and passed to
    // the kernels by value (View::walls).
    void place_walls(std::int64_t step)
    {
        for (std::size_t w = 0; w < walls_.size(); ++w) v_.walls.point[w] = walls_[w].point_at(step, dt_);
    }

    B be_;
    View v_;
    int bucket_bits_ = 0;
    std::vector<Wall> walls_;
    double dt_ = 0.0;
    std::int64_t step_ = 0;
};

// A DispatchingVariant whose init() picks GpuVariant<B, M> for the smallest model the scene needs, with its
// contact law (every law of physics.md §9).
template <class B>
std::unique_ptr<Variant> make_dispatching(std::function<B()> backend)
{
    return std::make_unique<DispatchingVariant>([backend](const Setup& setup) {
        return with_law_model(model_for(setup), [&]<class M>() -> std::unique_ptr<Variant> {
            return std::make_unique<GpuVariant<B, M>>(backend());
        });
    }, false, true);
}

} // namespace demmat::gpu
