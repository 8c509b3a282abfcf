// Ranks over MPI (run/ranks_mpi.hpp). The only file that includes mpi.h; without HAET_MPI it compiles to the one
// process's scope.
#include "run/ranks_mpi.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#ifdef HAET_MPI
#include <mpi.h>
#endif

namespace haet {

#ifdef HAET_MPI
namespace {

/// Ranks over MPI_COMM_WORLD. Sums gather every rank's values and add them in rank order, so that every rank gets
/// the same bits whatever MPI_Allreduce's order would be.
class MpiRanks final : public Ranks {
public:
    explicit MpiRanks(bool* talking) : talking_(talking) {
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
    }
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    std::uint32_t orBits(std::uint32_t mine) override {
        *talking_ = true;
        unsigned out = 0, in = mine;
        MPI_Allreduce(&in, &out, 1, MPI_UNSIGNED, MPI_BOR, MPI_COMM_WORLD);
        return out;
    }
    void sum(std::vector<double>& v) override {
        *talking_ = true;
        const int n = static_cast<int>(v.size());
        std::vector<double> all(v.size() * static_cast<std::size_t>(size_));
        MPI_Allgather(v.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, MPI_COMM_WORLD);
        for (int k = 0; k < n; ++k) {
            double s = 0;
            for (int r = 0; r < size_; ++r) s += all[static_cast<std::size_t>(r) * v.size() + k];
            v[k] = s;
        }
    }
    void max(std::vector<double>& v) override {
        *talking_ = true;
        std::vector<double> out(v.size());
        MPI_Allreduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        v.swap(out);
    }
    std::vector<std::vector<char>> exchange(const std::vector<std::vector<char>>& send) override {
        *talking_ = true;
        const std::size_t nr = static_cast<std::size_t>(size_);
        std::vector<long long> sizes(nr, 0), got(nr, 0);
        for (std::size_t r = 0; r < nr; ++r)
            if (static_cast<int>(r) != rank_) sizes[r] = static_cast<long long>(send[r].size());
        MPI_Alltoall(sizes.data(), 1, MPI_LONG_LONG, got.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD);
        std::vector<std::size_t> bytes(nr);
        for (std::size_t r = 0; r < nr; ++r) bytes[r] = static_cast<std::size_t>(got[r]);
        return exchangeKnown(send, bytes);
    }
    std::vector<std::vector<char>> exchangeKnown(const std::vector<std::vector<char>>& send,
                                                 const std::vector<std::size_t>& recvBytes) override {
        *talking_ = true;
        const std::size_t nr = static_cast<std::size_t>(size_);
        std::vector<std::vector<char>> recv(nr);
        std::vector<MPI_Request> reqs;
        for (std::size_t r = 0; r < nr; ++r) {
            if (static_cast<int>(r) == rank_) continue;
            recv[r].resize(recvBytes[r]);
            if (recvBytes[r] > 0) {
                reqs.emplace_back();
                MPI_Irecv(recv[r].data(), static_cast<int>(recvBytes[r]), MPI_BYTE, static_cast<int>(r), 0,
                          MPI_COMM_WORLD, &reqs.back());
            }
        }
        for (std::size_t r = 0; r < nr; ++r) {
            if (static_cast<int>(r) == rank_ || send[r].empty()) continue;
            reqs.emplace_back();
            MPI_Isend(send[r].data(), static_cast<int>(send[r].size()), MPI_BYTE, static_cast<int>(r), 0,
                      MPI_COMM_WORLD, &reqs.back());
        }
        MPI_Waitall(static_cast<int>(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
        return recv;
    }

private:
    int rank_ = 0, size_ = 1;
    bool* talking_;
};

/// Whether mpirun (Open MPI, or a PMI launcher) started this process.
bool launchedByMpirun() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(v) != nullptr) return true;
    return false;
}

}  // namespace

struct MpiScope::Impl {
    bool initialised = false;
    bool talking = false;
    std::unique_ptr<MpiRanks> ranks;
};

MpiScope::MpiScope(int& argc, char**& argv) : impl_(std::make_unique<Impl>()) {
    if (!launchedByMpirun()) return;
    // One thread calls MPI; OpenMP threads inside a rank never do.
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    impl_->initialised = true;
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size > 1) impl_->ranks = std::make_unique<MpiRanks>(&impl_->talking);
}

MpiScope::~MpiScope() {
    if (impl_->initialised) MPI_Finalize();
}

Ranks* MpiScope::ranks() { return impl_->ranks.get(); }
int MpiScope::rank() const { return impl_->ranks ? impl_->ranks->rank() : 0; }
bool MpiScope::talking() const { return impl_->talking; }
void MpiScope::abort(int code) {
    if (impl_->initialised) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}
bool mpiBuilt() { return true; }

#else

struct MpiScope::Impl {};
MpiScope::MpiScope(int&, char**&) {
    // Started as one of several ranks by a build without MPI: each would run the whole scenario into the same
    // directory.
    const char* n = std::getenv("OMPI_COMM_WORLD_SIZE");
    if (n != nullptr && std::atoi(n) > 1) {
        std::fprintf(stderr, "error: this haet was built without MPI (CMake option HAET_MPI): run it without mpirun\n");
        std::exit(2);
    }
}
MpiScope::~MpiScope() = default;
Ranks* MpiScope::ranks() { return nullptr; }
int MpiScope::rank() const { return 0; }
bool MpiScope::talking() const { return false; }
void MpiScope::abort(int code) { std::exit(code); }
bool mpiBuilt() { return false; }

#endif

}  // namespace haet
