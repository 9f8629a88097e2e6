// `spillway compare`: the command around host/image/compare.h's metrics and heatmap.
//
// Exit status: 0 all bounds met, 1 a --threshold bound exceeded, 2 usage or input error
// (unreadable or non-image file, sizes differ, heatmap not writable).
#pragma once

#include <string>
#include <vector>

namespace spw {

// The usage text of the compare command.
const char* compareUsage();

// `spillway compare A B [--json] [--heatmap FILE.png] [--threshold METRIC=VALUE]...`, given
// the arguments after "compare". Prints a table (or JSON with --json) to stdout, failed bounds
// and errors to stderr; returns 0, 1 or 2 as described at the top of this file.
int compareCommand(const std::vector<std::string>& args);

} // namespace spw
