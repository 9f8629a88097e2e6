// Distributed rendering: the processes of one render started by `mpirun -np N spillway render`.
//
// Every rank loads the scene and renders every iteration; within an iteration, each takes the
// camera samples of a share of the image's 8 x 8 tiles (Film::setShare: the k-th tile still
// sampling goes to rank k mod N). After the iteration the ranks add their film accumulators
// together with one integer all-reduce (MPI_SUM on 64-bit integers), so every rank holds the
// same film, bit for bit the film one process would have made: a path's random numbers depend
// only on (seed, pixel, sample, bounce, dimension), never on who traces it, and integer sums do
// not depend on their grouping. Everything the render decides from the film (adaptive tiles,
// --target-error, the end) is then the same on every rank without a message; what a rank sees
// alone (a failure, a signal, its clock) is agreed in a small all-reduce (agree()) before and
// after each iteration. Rank 0 writes the outputs and --stats.
//
// A failing rank says so at the next agreement, so that no rank waits forever: agree() throws
// RankFailure on the others, and every rank then leaves through its normal error path (its
// spill file is anonymous, so none is left on any exit).
//
// The MPI calls live in ranks.cpp alone, behind SPILLWAY_MPI; without it joinMpiWorld() finds no
// world and the render runs as one process.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace spw {

// Thrown on the other ranks when one rank failed (it prints its own message).
class RankFailure : public std::runtime_error {
  public:
    explicit RankFailure(int rank);
    int rank() const { return rank_; }

  private:
    int rank_;
};

class Ranks {
  public:
    virtual ~Ranks() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    // Collective: `values` becomes their sum over the ranks, element by element, exactly.
    virtual void sum(std::vector<std::int64_t>& values) const = 0;
    // Collective: `values` becomes their maximum over the ranks, element by element.
    virtual void max(std::vector<std::int64_t>& values) const = 0;
    // Collective: every rank's `text`, in rank order, on rank 0 (empty elsewhere).
    virtual std::vector<std::string> gather(const std::string& text) const = 0;
    // The host this rank runs on, and how many of the ranks run there.
    virtual std::string host() const = 0;
    virtual int ranksOnHost() const = 0;

    // What the ranks agree on around an iteration: each rank brings what it alone knows.
    struct Agreement {
        int failedRank = -1; // the lowest rank that failed, or -1
        bool stop = false;   // some rank was asked to stop (a signal, the preview window)
        bool timeUp = false; // some rank's render time reached the time limit
    };
    // Collective. A rank that failed brings failed = true, then rethrows its own error; when
    // another rank failed this throws RankFailure. Once a rank has taken part in a failed
    // agreement, or left the render's collectives (finish()), failed() does nothing.
    Agreement agree(bool failed, bool stop, bool timeUp);
    // A rank failed outside the render loop (scene, options, outputs): tells the others at their
    // next agreement, unless they already know or have finished.
    void failed();
    // Collective, before any other of the render: every rank brings the digests of what decides
    // its image (the same fields, in the same order, on every rank) and learns, for each rank,
    // the first field where it differs from rank 0 (-1: none).
    std::vector<int> firstDifferences(const std::vector<std::uint64_t>& fields);
    // The render's collectives are over (rank 0 is left to write its outputs).
    void finish() { finished_ = true; }

  private:
    bool finished_ = false;
};

// The MPI world when this process was started by mpirun (or another MPI launcher) with more than
// one rank, initialising MPI, which is finalised when the returned object goes; nullptr for a
// plain process (MPI is then never initialised) and in a build without MPI (where asking for more
// than one rank is an error: it throws std::runtime_error).
std::unique_ptr<Ranks> joinMpiWorld();

// Whether this build can render across MPI ranks.
bool mpiBuilt();

} // namespace spw
