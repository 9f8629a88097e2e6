// `spillway --help`: the commands, then every render option from the option table.
#pragma once

#include <string>

namespace spw {

std::string usageText();

} // namespace spw
