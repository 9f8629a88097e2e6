#include "host/app/error_csv.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spw {

ErrorCsv::ErrorCsv(const std::string& path, std::optional<ImageRGB> reference,
                   std::optional<int> resumedIterations)
    : out_(path), reference_(std::move(reference)) {
    std::string header = "iteration,spp,seconds,relmse_estimate,relmse_estimate_stderr";
    if (reference_) header += ",mse,rmse,relmse,mae,psnr,maxabs";
    header += ",subject_relmse_estimate,subject_fraction"; // what the stop judges
    out_.write(header + "\n");
    std::error_code ec;
    if (!resumedIterations || !std::filesystem::is_regular_file(path, ec)) return;
    std::ifstream in(path);
    std::string line;
    if (!std::getline(in, line)) return;
    if (line != header)
        throw std::invalid_argument("--error-csv '" + path +
                                    "' holds other columns than this render writes (with or "
                                    "without --reference); name another file");
    while (std::getline(in, line)) {
        std::istringstream row(line);
        int iteration = 0;
        if (row >> iteration && iteration <= *resumedIterations) out_.write(line + "\n");
    }
}

void ErrorCsv::addRow(int iteration, int spp, double seconds, const Film& film) {
    std::ostringstream row;
    row.precision(9);
    const Film::ErrorEstimate error = film.halfBufferError();
    row << iteration << "," << spp << "," << seconds << ",";
    if (error.relMse)
        row << *error.relMse << "," << error.standardError;
    else
        row << ","; // no estimate yet: both cells empty

    if (reference_) {
        ImageMetrics m = compareImages({film.width(), film.height(), film.image()}, *reference_);
        row << "," << m.mse << "," << m.rmse << "," << m.relMse << "," << m.mae << ","
            << (std::isinf(m.psnr) ? std::string("inf") : std::to_string(m.psnr)) << ","
            << m.maxAbs;
    }
    row << ",";
    if (const std::optional<double> subject =
            error.subjectRelMse ? error.subjectRelMse : error.relMse)
        row << *subject << "," << error.subjectFraction;
    else
        row << ",";
    row << "\n";
    out_.write(row.str());
}

} // namespace spw
