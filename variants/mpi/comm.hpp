#pragma once
// The MPI calls of the mpi variant, in one place: the exchange with two brick neighbours (counted:
// messages, bytes, seconds), and the gathers and broadcasts that rank 0 uses for observables and setup.
// Every buffer is doubles; an id travels as the bits of an int64 (id_to_double), exactly.
#include <bit>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <mpi.h>

namespace demmat::mpi {

inline double id_to_double(std::int64_t id) { return std::bit_cast<double>(id); }
inline std::int64_t double_to_id(double d) { return std::bit_cast<std::int64_t>(d); }

// What this rank has sent to its neighbours since init, and the time spent in those exchanges.
struct Traffic {
    std::int64_t messages = 0, bytes = 0;
    double seconds = 0.0;
};

class Comm {
public:
    explicit Comm(MPI_Comm comm = MPI_COMM_WORLD);
    int rank() const { return rank_; }
    int size() const { return size_; }
    MPI_Comm handle() const { return comm_; }
    bool root() const { return rank_ == 0; }

    // Sends `to_lower` to rank `lower` and `to_upper` to rank `upper` (−1: none) and returns what they
    // sent this rank, in one round of a message each way with each. `tag` keeps rounds apart.
    void exchange(int lower, int upper, const std::vector<double>& to_lower, const std::vector<double>& to_upper,
                  std::vector<double>& from_lower, std::vector<double>& from_upper, int tag);
    const Traffic& traffic() const { return traffic_; }

    // Rank 0 receives every rank's buffer, concatenated in rank order; the others get an empty vector.
    std::vector<double> gather(const std::vector<double>& mine) const;
    // Rank 0 sends parts[r] to rank r; returns this rank's part.
    std::vector<double> scatter(const std::vector<std::vector<double>>& parts) const;
    void broadcast(std::vector<double>& data) const;  // from rank 0; resized on the others
    void broadcast(std::string& text) const;
    std::int64_t sum(std::int64_t v) const;
    // True on every rank when `flag` is on some rank; timed into traffic().seconds (it is a step's exchange).
    bool any(bool flag);
    double max(double v) const;
    void barrier() const;  // not counted as traffic: it is not a step's exchange

private:
    MPI_Comm comm_;
    int rank_ = 0, size_ = 1;
    Traffic traffic_;
};

} // namespace demmat::mpi
