// A command-line mistake: the commands print it with a pointer to --help and exit 2.
#pragma once

#include <stdexcept>

namespace spw {

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

} // namespace spw
