// `spillway render SCENE [options]`: parse the options (render_options.h), load the scene with
// the overrides, render (render/render.h) with progress, preview, error CSV and checkpoints, and
// write every output whole or none. Exit status as main.cpp says.
#pragma once

#include "host/render/ranks.h"

#include <string>
#include <vector>

namespace spw {

// `ranks`: this process's place in a distributed render (mpirun), or nullptr. Every rank
// renders its share; rank 0 alone reads the reference, shows progress and writes every output.
int renderCommand(const std::vector<std::string>& args, Ranks* ranks);

} // namespace spw
