#include "comm.hpp"

#include <numeric>

namespace demmat::mpi {

Comm::Comm(MPI_Comm comm) : comm_(comm)
{
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
}

void Comm::exchange(int lower_rank, int upper_rank, const std::vector<double>& to_lower, const std::vector<double>& to_upper,
                    std::vector<double>& from_lower, std::vector<double>& from_upper, int tag)
{
    const auto t0 = std::chrono::steady_clock::now();
    const int lower = lower_rank >= 0 ? lower_rank : MPI_PROC_NULL;
    const int upper = upper_rank >= 0 ? upper_rank : MPI_PROC_NULL;
    MPI_Request req[2];
    // The sizes travel with the messages (MPI_Probe): one message per neighbour and direction.
    MPI_Isend(to_lower.data(), int(to_lower.size()), MPI_DOUBLE, lower, tag, comm_, &req[0]);
    MPI_Isend(to_upper.data(), int(to_upper.size()), MPI_DOUBLE, upper, tag, comm_, &req[1]);
    auto receive = [&](int from, std::vector<double>& out) {
        out.clear();
        if (from == MPI_PROC_NULL) return;
        MPI_Status st;
        MPI_Probe(from, tag, comm_, &st);
        int count = 0;
        MPI_Get_count(&st, MPI_DOUBLE, &count);
        out.resize(std::size_t(count));
        MPI_Recv(out.data(), count, MPI_DOUBLE, from, tag, comm_, MPI_STATUS_IGNORE);
    };
    receive(lower, from_lower);
    receive(upper, from_upper);
    MPI_Waitall(2, req, MPI_STATUSES_IGNORE);
    for (auto [to, buf] : {std::pair{lower, &to_lower}, {upper, &to_upper}})
        if (to != MPI_PROC_NULL) {
            ++traffic_.messages;
            traffic_.bytes += std::int64_t(buf->size() * sizeof(double));
        }
    traffic_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<double> Comm::gather(const std::vector<double>& mine) const
{
    int n = int(mine.size());
    std::vector<int> counts(root() ? std::size_t(size_) : 0), offsets;
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
    std::vector<double> all;
    if (root()) {
        offsets.resize(counts.size());
        std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
        all.resize(std::size_t(offsets.back() + counts.back()));
    }
    MPI_Gatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm_);
    return all;
}

std::vector<double> Comm::scatter(const std::vector<std::vector<double>>& parts) const
{
    std::vector<int> counts, offsets;
    std::vector<double> all;
    if (root()) {
        for (const auto& p : parts) counts.push_back(int(p.size()));
        offsets.resize(counts.size());
        std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
        for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
    }
    int n = 0;
    MPI_Scatter(counts.data(), 1, MPI_INT, &n, 1, MPI_INT, 0, comm_);
    std::vector<double> mine(static_cast<std::size_t>(n));
    MPI_Scatterv(all.data(), counts.data(), offsets.data(), MPI_DOUBLE, mine.data(), n, MPI_DOUBLE, 0, comm_);
    return mine;
}

void Comm::broadcast(std::vector<double>& data) const
{
    long long n = (long long)data.size();
    MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm_);
    data.resize(std::size_t(n));
    MPI_Bcast(data.data(), int(n), MPI_DOUBLE, 0, comm_);
}

void Comm::broadcast(std::string& text) const
{
    long long n = (long long)text.size();
    MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm_);
    text.resize(std::size_t(n));
    MPI_Bcast(text.data(), int(n), MPI_CHAR, 0, comm_);
}

std::int64_t Comm::sum(std::int64_t v) const
{
    long long in = v, out = 0;
    MPI_Allreduce(&in, &out, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    return out;
}

bool Comm::any(bool flag)
{
    const auto t0 = std::chrono::steady_clock::now();
    int in = flag ? 1 : 0, out = 0;
    MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_MAX, comm_);
    traffic_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out != 0;
}

double Comm::max(double v) const
{
    double out = 0.0;
    MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX, comm_);
    return out;
}

void Comm::barrier() const { MPI_Barrier(comm_); }

} // namespace demmat::mpi
