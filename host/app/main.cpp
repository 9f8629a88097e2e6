// The spillway command line: one command per file beside this one (render, compare, merge,
// devices). Exit status: 0 success, 1 runtime failure (disk, device), 2 bad input (usage or
// scene error).
#include "host/app/compare_command.h"
#include "host/app/devices_command.h"
#include "host/app/merge_command.h"
#include "host/app/render_command.h"
#include "host/app/usage.h"
#include "host/app/usage_error.h"
#include "host/backend/render_config.h"
#include "host/render/ranks.h"
#include "host/scene/scene.h"

#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#ifndef SPILLWAY_VERSION
#define SPILLWAY_VERSION "0.0.0"
#endif

namespace {

// A distributed render's rank, for the error messages main() prints ("" for one process).
std::string gRankLabel;

int distributedRender(const std::vector<std::string>& args) {
    // Started by mpirun as several ranks: one distributed render (host/render/ranks.h).
    std::unique_ptr<spw::Ranks> ranks = spw::joinMpiWorld();
    if (ranks)
        gRankLabel =
            "rank " + std::to_string(ranks->rank()) + " of " + std::to_string(ranks->size()) + ": ";
    try {
        return spw::renderCommand(args, ranks.get());
    } catch (...) {
        if (ranks) ranks->failed(); // the other ranks stop at their next agreement
        throw;
    }
}

int runCommand(const std::vector<std::string>& args) {
    if (args.empty()) {
        std::fputs(spw::usageText().c_str(), stderr);
        return 2;
    }
    const std::vector<std::string> rest(args.begin() + 1, args.end());
    if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
        std::fputs(spw::usageText().c_str(), stdout);
        return 0;
    }
    if (args[0] == "--version") {
        std::printf("spillway %s\n", SPILLWAY_VERSION);
        return 0;
    }
    if (args[0] == "render") return distributedRender(rest);
    if (args[0] == "compare") return spw::compareCommand(rest);
    if (args[0] == "devices") return spw::devicesCommand(rest);
    if (args[0] == "merge") return spw::mergeCommand(rest);
    throw spw::UsageError("unknown command '" + args[0] + "' (try spillway --help)");
}

} // namespace

int main(int argc, char** argv) {
    // A file-size limit must surface as a write error (EFBIG) with a message, not kill us.
    std::signal(SIGXFSZ, SIG_IGN);
    try {
        return runCommand(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const spw::UsageError& e) {
        std::fprintf(stderr, "spillway: %s%s\n", gRankLabel.c_str(), e.what());
        return 2;
    } catch (const spw::SceneError& e) {
        std::fprintf(stderr, "%s%s\n", gRankLabel.c_str(), e.what());
        return 2;
    } catch (const spw::RenderRefused& e) {
        std::fprintf(stderr, "spillway: %s%s\n", gRankLabel.c_str(), e.what());
        return 2;
    } catch (const std::bad_alloc&) { // one that no part of the render said more of
        std::fprintf(stderr,
                     "spillway: %serror: out of memory: the render needs more than this process "
                     "may take (a ulimit, a container's limit or the machine's memory)\n",
                     gRankLabel.c_str());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "spillway: %serror: %s\n", gRankLabel.c_str(), e.what());
        return 1;
    }
}
