#include "host/render/ranks.h"

#include <algorithm>
#include <cstdlib>

#ifdef SPILLWAY_MPI
// The C API only: Open MPI's and MPICH's headers otherwise pull in the deprecated C++ bindings.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace spw {

RankFailure::RankFailure(int rank)
    : std::runtime_error("rank " + std::to_string(rank) +
                         " failed (it says why); the other ranks stopped with it"),
      rank_(rank) {}

Ranks::Agreement Ranks::agree(bool failed, bool stop, bool timeUp) {
    // One all-reduce (max): a flag per rank for failures, so that everyone learns who failed.
    std::vector<std::int64_t> v(size_t(size()) + 2, 0);
    if (failed) v[size_t(rank())] = 1;
    v[size_t(size())] = stop;
    v[size_t(size()) + 1] = timeUp;
    if (!finished_) max(v);
    Agreement a;
    for (int r = 0; r < size(); ++r)
        if (v[size_t(r)] != 0) {
            a.failedRank = r;
            break;
        }
    a.stop = v[size_t(size())] != 0;
    a.timeUp = v[size_t(size()) + 1] != 0;
    if (a.failedRank >= 0) {
        finished_ = true; // every rank leaves the render now: no collective follows
        if (!failed) throw RankFailure(a.failedRank);
    }
    return a;
}

std::vector<int> Ranks::firstDifferences(const std::vector<std::uint64_t>& fields) {
    // Rank 0's digests to everyone: a maximum where the other ranks bring -1 (the digests are
    // cut to 62 bits, so they are never negative).
    std::vector<std::int64_t> zero(fields.size(), -1);
    if (rank() == 0)
        for (size_t i = 0; i < fields.size(); ++i)
            zero[i] = std::int64_t(fields[i] >> 2);
    max(zero);
    int mine = -1;
    for (size_t i = 0; i < fields.size() && mine < 0; ++i)
        if (std::int64_t(fields[i] >> 2) != zero[i]) mine = int(i);
    // Then each rank's first difference to everyone.
    std::vector<std::int64_t> all(size_t(size()), -1);
    all[size_t(rank())] = mine;
    max(all);
    return std::vector<int>(all.begin(), all.end());
}

void Ranks::failed() {
    if (!finished_) agree(true, false, false);
}

#ifdef SPILLWAY_MPI
namespace {

class MpiWorld final : public Ranks {
  public:
    MpiWorld() {
        int provided = 0;
        // The render's MPI calls come from one thread at a time (the preview runs the render on
        // its own thread, so not always the main one).
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
        if (provided < MPI_THREAD_SERIALIZED) {
            MPI_Finalize();
            throw std::runtime_error("MPI: the library cannot serve calls from more than one "
                                     "thread (MPI_THREAD_SERIALIZED)");
        }
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
        MPI_Comm local;
        MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
        MPI_Comm_size(local, &ranksOnHost_);
        MPI_Comm_free(&local);
    }
    ~MpiWorld() override { MPI_Finalize(); }

    int rank() const override { return rank_; }
    int size() const override { return size_; }
    int ranksOnHost() const override { return ranksOnHost_; }
    void sum(std::vector<std::int64_t>& values) const override { reduce(values, MPI_SUM); }
    void max(std::vector<std::int64_t>& values) const override { reduce(values, MPI_MAX); }

    std::vector<std::string> gather(const std::string& text) const override {
        int length = int(text.size());
        std::vector<int> lengths(size_t(size_), 0), offsets(size_t(size_), 0);
        MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
        std::string all;
        if (rank_ == 0) {
            for (int r = 1; r < size_; ++r)
                offsets[size_t(r)] = offsets[size_t(r) - 1] + lengths[size_t(r) - 1];
            all.resize(size_t(offsets.back() + lengths.back()));
        }
        MPI_Gatherv(text.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(),
                    MPI_CHAR, 0, MPI_COMM_WORLD);
        std::vector<std::string> out;
        if (rank_ == 0)
            for (int r = 0; r < size_; ++r)
                out.push_back(all.substr(size_t(offsets[size_t(r)]), size_t(lengths[size_t(r)])));
        return out;
    }

    std::string host() const override {
        char name[MPI_MAX_PROCESSOR_NAME];
        int length = 0;
        MPI_Get_processor_name(name, &length);
        return std::string(name, size_t(length));
    }

  private:
    void reduce(std::vector<std::int64_t>& values, MPI_Op op) const {
        // MPI counts are ints: reduce in slices (a 4K film is 8 x 12 M values).
        constexpr size_t kSlice = size_t(1) << 28;
        for (size_t at = 0; at < values.size(); at += kSlice) {
            const int n = int(std::min(kSlice, values.size() - at));
            MPI_Allreduce(MPI_IN_PLACE, values.data() + at, n, MPI_INT64_T, op, MPI_COMM_WORLD);
        }
    }

    int rank_ = 0, size_ = 1, ranksOnHost_ = 1;
};

} // namespace
#endif

namespace {
// The world size an MPI launcher gave this process: Open MPI's mpirun, or a PMI launcher (MPICH's
// Hydra, Slurm's srun); 1 for a plain process.
int launchedRanks() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
        if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
    return 1;
}
} // namespace

bool mpiBuilt() {
#ifdef SPILLWAY_MPI
    return true;
#else
    return false;
#endif
}

std::unique_ptr<Ranks> joinMpiWorld() {
    if (launchedRanks() <= 1) return nullptr;
#ifdef SPILLWAY_MPI
    return std::make_unique<MpiWorld>();
#else
    throw std::runtime_error("started as " + std::to_string(launchedRanks()) +
                             " MPI ranks, but this spillway was built without MPI (install "
                             "libopenmpi-dev and build again)");
#endif
}

} // namespace spw
