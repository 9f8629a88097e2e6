// Error against time while rendering (--error-csv): a CSV row after every iteration with the
// render seconds so far (start-up, output and this bookkeeping excluded), the spp, the relMSE
// estimated from the film's two half buffers and that estimate's standard error, and, given a
// reference image, the metrics of `spillway compare` against it. Where no estimate exists yet (a
// half buffer without samples: the first iteration of one sample), its two cells are empty.
#pragma once

#include "host/image/compare.h"
#include "host/image/film.h"

#include "host/image/output_file.h"

#include <optional>
#include <string>

namespace spw {

class ErrorCsv {
  public:
    // Throws std::runtime_error naming the path when it cannot be written. The rows go to an
    // anonymous file as they come; the CSV appears under its name at commit(), not before.
    // `resumedIterations`: a render resumed after that many iterations keeps the rows of those
    // iterations that the file already holds (the run that wrote the checkpoint wrote them), so
    // the CSV covers the whole render; throws std::invalid_argument where the file holds other
    // columns.
    ErrorCsv(const std::string& path, std::optional<ImageRGB> reference,
             std::optional<int> resumedIterations = std::nullopt);
    void addRow(int iteration, int spp, double seconds, const Film& film);
    void flush() { out_.flush(); }
    void commit() { out_.commit(); }

  private:
    OutputFile out_;
    std::optional<ImageRGB> reference_;
};

} // namespace spw
