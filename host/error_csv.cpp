#include "host/error_csv.h"

#include <cmath>
#include <stdexcept>

namespace spw {

ErrorCsv::ErrorCsv(const std::string& path, std::optional<ImageRGB> reference)
    : path_(path), out_(path), reference_(std::move(reference)) {
    if (!out_) throw std::runtime_error("cannot write error CSV '" + path + "'");
    out_ << "iteration,spp,seconds,relmse_estimate";
    if (reference_) out_ << ",mse,rmse,relmse,mae,psnr,maxabs";
    out_ << "\n";
    out_.precision(9);
}

void ErrorCsv::addRow(int iteration, int spp, double seconds, const Film& film) {
    out_ << iteration << "," << spp << "," << seconds << "," << film.halfBufferRelMse();
    if (reference_) {
        ImageMetrics m = compareImages({film.width(), film.height(), film.image()}, *reference_);
        out_ << "," << m.mse << "," << m.rmse << "," << m.relMse << "," << m.mae << ","
             << (std::isinf(m.psnr) ? std::string("inf") : std::to_string(m.psnr)) << "," << m.maxAbs;
    }
    out_ << "\n";
    out_.flush();
    if (!out_) throw std::runtime_error("cannot write error CSV '" + path_ + "'");
}

} // namespace spw
