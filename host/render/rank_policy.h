// How the processes of a render agree and add up their work: a policy the render session calls
// at fixed points of its loop. One process (SingleProcess) agrees with itself and has nothing to
// add, so the render loop reads the same with or without MPI; a distributed render (RankSync,
// over host/render/ranks.h) agrees before and after each iteration, adds the film's sums exactly,
// and gathers every rank's stats on rank 0.
#pragma once

#include "host/backend/stats.h"
#include "host/image/film.h"
#include "host/render/ranks.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace spw {

// What decides a render's image, field by field: a name for the user and a digest.
using RenderIdentity = std::vector<std::pair<std::string, std::uint64_t>>;

class RankPolicy {
  public:
    virtual ~RankPolicy() = default;
    // Before anything else: whether every process renders the same thing. Throws RenderRefused
    // on every process, naming the first rank and field that differ from rank 0's (`identity`
    // is only called where there is more than one process).
    virtual void agreeIdentity(const std::function<RenderIdentity()>& identity) = 0;
    // Whether this process writes the outputs and checkpoints (rank 0, or the only process).
    virtual bool writes() const = 0;
    // Gives the film this process's share of every iteration's camera samples.
    virtual void share(Film& film) const = 0;
    // Before an iteration: what some process alone knows (a stop asked for, its clock past the
    // time limit), agreed so that every rank renders the same iterations.
    virtual Ranks::Agreement agreeBefore(bool stop, bool timeUp, StageTimes& stages) = 0;
    // After an iteration: whether every process completed its share.
    virtual bool agreeWhole(bool whole, StageTimes& stages) = 0;
    // Every process's share of the iteration added into every film, exactly.
    virtual void reduce(Film& film, StageTimes& stages) = 0;
    // The end of the render's collectives: on the writing process, `stats` then holds every
    // process's (`ranks`) and their totals.
    virtual void finish(RenderStats& stats, double wallSeconds) = 0;
};

// One process: every agreement is its own, nothing to reduce.
class SingleProcess final : public RankPolicy {
  public:
    bool writes() const override { return true; }
    void agreeIdentity(const std::function<RenderIdentity()>&) override {}
    void share(Film&) const override {}
    Ranks::Agreement agreeBefore(bool stop, bool timeUp, StageTimes&) override {
        Ranks::Agreement a;
        a.stop = stop;
        a.timeUp = timeUp;
        return a;
    }
    bool agreeWhole(bool whole, StageTimes&) override { return whole; }
    void reduce(Film&, StageTimes&) override {}
    void finish(RenderStats&, double) override {}
};

// The ranks of an MPI world (host/render/ranks.h says how a distributed render works).
class RankSync final : public RankPolicy {
  public:
    explicit RankSync(Ranks& ranks) : ranks_(ranks) {}
    bool writes() const override { return ranks_.rank() == 0; }
    void agreeIdentity(const std::function<RenderIdentity()>& identity) override;
    void share(Film& film) const override { film.setShare(ranks_.rank(), ranks_.size()); }
    Ranks::Agreement agreeBefore(bool stop, bool timeUp, StageTimes& stages) override;
    bool agreeWhole(bool whole, StageTimes& stages) override;
    void reduce(Film& film, StageTimes& stages) override;
    void finish(RenderStats& stats, double wallSeconds) override;

  private:
    Ranks& ranks_;
};

// The policy for `ranks` (nullptr: one process).
std::unique_ptr<RankPolicy> rankPolicy(Ranks* ranks);

} // namespace spw
