// share_problem (mpi_variant.hpp): rank 0 reads the scene and its state; the other ranks get what the
// Driver and the variant need besides the particles, which the variant's init scatters.
#include <cstring>

#include "mpi_variant.hpp"
#include "demmat/error.hpp"
#include "demmat/scene_toml.hpp"

namespace demmat::mpi {

namespace {

// The walls as doubles (point, normal, velocity, ref_step's bits) and their names, one per line.
void pack_walls(const std::vector<Wall>& walls, std::vector<double>& nums, std::string& names)
{
    for (const Wall& w : walls) {
        for (const Vec3d* v : {&w.point, &w.normal, &w.velocity})
            for (int c = 0; c < 3; ++c) nums.push_back(component(*v, c));
        nums.push_back(id_to_double(w.ref_step));
        names += w.name + "\n";
    }
}

std::vector<Wall> unpack_walls(const std::vector<double>& nums, const std::string& names)
{
    std::vector<Wall> walls(nums.size() / 10);
    std::size_t at = 0;
    for (std::size_t k = 0; k < walls.size(); ++k) {
        Wall& w = walls[k];
        const double* p = &nums[10 * k];
        w.point = {p[0], p[1], p[2]};
        w.normal = {p[3], p[4], p[5]};
        w.velocity = {p[6], p[7], p[8]};
        w.ref_step = double_to_id(p[9]);
        const std::size_t end = names.find('\n', at);
        w.name = names.substr(at, end - at);
        at = end + 1;
    }
    return walls;
}

template <class T>
bool same_bits(const T& a, const T& b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }

} // namespace

std::unique_ptr<Problem> share_problem(const Comm& comm, const std::function<std::unique_ptr<Problem>()>& load)
{
    std::unique_ptr<Problem> mine;
    std::string failure, text, names;
    std::vector<double> head, walls;  // head: step, dt, fingerprint's bits
    if (comm.root()) {
        try {
            mine = load();
            Scene lite = mine->scene();  // the particles travel with the variant's init, not in the text
            lite.particles.clear();
            lite.grid.reset();
            lite.state_file = "(held by rank 0)";
            text = scene_to_toml(lite);
            const Scene back = parse_scene(text, "the scene sent to the ranks");
            // The text holds every double in its shortest round-trip form; check that the constants the
            // ranks derive from it are the very bits rank 0 derived.
            if (!same_bits(back.contact_params(), mine->scene().contact_params()) || !same_bits(back.dt, mine->scene().dt) ||
                !same_bits(back.gravity, mine->scene().gravity) || !same_bits(memory_params(back), memory_params(mine->scene())))
                throw Error("internal: the scene's text does not carry its constants exactly");
            const State& st = mine->state();
            head = {id_to_double(st.step), st.dt, id_to_double(std::int64_t(st.fingerprint))};
            pack_walls(st.walls, walls, names);
        } catch (const std::exception& e) {  // any failure: the other ranks must not wait for the scene
            failure = e.what();
            if (failure.empty()) failure = "the scene could not be loaded";
        }
    }
    comm.broadcast(failure);
    if (!failure.empty()) throw AllRanksError(failure);
    comm.broadcast(text);
    comm.broadcast(names);
    comm.broadcast(head);
    comm.broadcast(walls);
    if (comm.root()) return mine;
    Scene scene = parse_scene(text, "the scene sent by rank 0");
    State st;
    st.step = double_to_id(head[0]);
    st.dt = head[1];
    st.fingerprint = std::uint64_t(double_to_id(head[2]));
    st.walls = unpack_walls(walls, names);
    return std::make_unique<Problem>(std::move(scene), std::move(st));
}

} // namespace demmat::mpi
