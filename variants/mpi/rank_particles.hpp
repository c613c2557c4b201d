#pragma once
// One rank's particles: the ones it owns (with their whole Gear history) followed by the ghosts, copies
// of its neighbours' particles near the brick faces (what the law reads: position, velocity, angular
// velocity, radius, mass). Local index l < owned() is an owned particle, owned() <= l < size() a ghost.
// Ids are kept beside every particle: the canonical order is by id, never by local index.
#include <cstdint>
#include <vector>

#include "comm.hpp"
#include "demmat/vec3.hpp"

namespace demmat::mpi {

// A migrant (an owned particle handed to a neighbour, or scattered at init): id, radius, mass, inertia,
// and the twelve Gear vectors (translation x, v, a, b3, b4, b5, then rotation).
inline constexpr std::size_t kMigrantDoubles = 4 + 36;
// A ghost: id, radius, mass, position, velocity, angular velocity.
inline constexpr std::size_t kGhostDoubles = 3 + 9;

struct RankParticles {
    // owned and ghosts
    std::vector<std::int64_t> id;
    std::vector<Vec3d> x, v, w;
    std::vector<double> r, m;
    // owned only
    std::vector<double> inertia;
    std::vector<Vec3d> a, b3, b4, b5, th, al, q3, q4, q5;  // q3–q5: the rotational b3–b5
    std::vector<Vec3d> f, t, acc, alc;                     // loads and the corrected accelerations
    std::size_t n_owned = 0;

    std::size_t owned() const { return n_owned; }
    std::size_t size() const { return id.size(); }

    void drop_ghosts() { resize_shared(n_owned); }

    void pack_migrant(std::size_t l, std::vector<double>& out) const
    {
        out.push_back(id_to_double(id[l]));
        out.push_back(r[l]);
        out.push_back(m[l]);
        out.push_back(inertia[l]);
        for (const std::vector<Vec3d>* g : gear())
            for (int c = 0; c < 3; ++c) out.push_back(component((*g)[l], c));
    }

    // Appends the migrants in `in` as owned particles (ghosts must have been dropped).
    void add_migrants(const std::vector<double>& in)
    {
        for (std::size_t k = 0; k + kMigrantDoubles <= in.size(); k += kMigrantDoubles) add_migrant(&in[k]);
    }
    void add_migrant(const double* p)
    {
        {
            const std::size_t l = n_owned;
            resize_owned(l + 1);
            id[l] = double_to_id(p[0]);
            r[l] = p[1];
            m[l] = p[2];
            inertia[l] = p[3];
            p += 4;
            for (std::vector<Vec3d>* g : gear()) {
                (*g)[l] = {p[0], p[1], p[2]};
                p += 3;
            }
        }
    }

    // Removes owned particle l, moving the last owned one into its place (ghosts must have been dropped).
    void remove_owned(std::size_t l)
    {
        const std::size_t last = n_owned - 1;
        if (l != last) {
            id[l] = id[last];
            r[l] = r[last];
            m[l] = m[last];
            inertia[l] = inertia[last];
            for (std::vector<Vec3d>* g : gear()) (*g)[l] = (*g)[last];
        }
        resize_owned(last);
    }

    // Puts the owned particles in a new order: slot s takes the particle from slot from[s] (ghosts must
    // have been dropped). The rank sorts them into cell order at each rebuild, so that a particle's
    // partners, their records and their slots lie near it in memory.
    void permute_owned(const std::vector<std::size_t>& from)
    {
        auto apply = [&](auto& v) {
            auto old = v;  // a copy per array: a rebuild is rare beside the steps between
            for (std::size_t s = 0; s < n_owned; ++s) v[s] = old[from[s]];
        };
        apply(id);
        apply(r);
        apply(m);
        apply(inertia);
        for (std::vector<Vec3d>* g : gear()) apply(*g);
        for (auto* g : {&f, &t, &acc, &alc}) apply(*g);
    }

    void pack_ghost(std::size_t l, std::vector<double>& out) const
    {
        out.push_back(id_to_double(id[l]));
        out.push_back(r[l]);
        out.push_back(m[l]);
        for (const Vec3d* q : {&x[l], &v[l], &w[l]})
            for (int c = 0; c < 3; ++c) out.push_back(component(*q, c));
    }

    void add_ghosts(const std::vector<double>& in)
    {
        for (std::size_t k = 0; k + kGhostDoubles <= in.size(); k += kGhostDoubles) {
            const double* p = &in[k];
            id.push_back(double_to_id(p[0]));
            r.push_back(p[1]);
            m.push_back(p[2]);
            x.push_back({p[3], p[4], p[5]});
            v.push_back({p[6], p[7], p[8]});
            w.push_back({p[9], p[10], p[11]});
        }
    }

    std::size_t memory_bytes() const
    {
        std::size_t b = id.capacity() * sizeof(std::int64_t) + (r.capacity() + m.capacity() + inertia.capacity()) * sizeof(double);
        for (const auto* g : {&x, &v, &w, &a, &b3, &b4, &b5, &th, &al, &q3, &q4, &q5, &f, &t, &acc, &alc})
            b += g->capacity() * sizeof(Vec3d);
        return b;
    }

private:
    // The twelve Gear vectors in the order of a migrant record; x, v (shared with ghosts) and w among them.
    std::vector<std::vector<Vec3d>*> gear() { return {&x, &v, &a, &b3, &b4, &b5, &th, &w, &al, &q3, &q4, &q5}; }
    std::vector<const std::vector<Vec3d>*> gear() const { return {&x, &v, &a, &b3, &b4, &b5, &th, &w, &al, &q3, &q4, &q5}; }

    void resize_shared(std::size_t n)
    {
        id.resize(n);
        x.resize(n);
        v.resize(n);
        w.resize(n);
        r.resize(n);
        m.resize(n);
    }
    void resize_owned(std::size_t n)
    {
        resize_shared(n);
        inertia.resize(n);
        for (auto* g : {&a, &b3, &b4, &b5, &th, &al, &q3, &q4, &q5, &f, &t, &acc, &alc}) g->resize(n);
        n_owned = n;
    }
};

} // namespace demmat::mpi
