// Passes over the film's pixels on the render's threads (film.cpp, film_state.cpp,
// film_error.cpp).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace spw {

// fn(begin, end) over ranges of the pixels, on the render's threads: every pass over the whole
// film works pixel by pixel, so its result does not depend on how the range is cut.
template <typename Fn> void forPixels(size_t pixels, const Fn& fn) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 16384),
                      [&](const tbb::blocked_range<size_t>& r) { fn(r.begin(), r.end()); });
}

} // namespace spw
