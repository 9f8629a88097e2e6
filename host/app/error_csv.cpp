#include "host/app/error_csv.h"

#include <cmath>
#include <sstream>

namespace spw {

ErrorCsv::ErrorCsv(const std::string& path, std::optional<ImageRGB> reference)
    : out_(path), reference_(std::move(reference)) {
    std::string header = "iteration,spp,seconds,relmse_estimate,relmse_estimate_stderr";
    if (reference_) header += ",mse,rmse,relmse,mae,psnr,maxabs";
    out_.write(header + "\n");
}

void ErrorCsv::addRow(int iteration, int spp, double seconds, const Film& film) {
    std::ostringstream row;
    row.precision(9);
    const Film::ErrorEstimate error = film.halfBufferError();
    row << iteration << "," << spp << "," << seconds << "," << error.relMse.value_or(0.0) << ","
        << error.standardError;
    if (reference_) {
        ImageMetrics m = compareImages({film.width(), film.height(), film.image()}, *reference_);
        row << "," << m.mse << "," << m.rmse << "," << m.relMse << "," << m.mae << ","
            << (std::isinf(m.psnr) ? std::string("inf") : std::to_string(m.psnr)) << ","
            << m.maxAbs;
    }
    row << "\n";
    out_.write(row.str());
}

} // namespace spw
