#include "host/pipeline/spill_file.h"

#include "host/image/scratch_file.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <iterator>
#include <stdexcept>
#include <unistd.h>
#include <utility>

namespace spw {

SpillFile::SpillFile(const std::string& dir) : dir_(dir), fd_(openScratchFile(dir, "spill")) {}

SpillFile::~SpillFile() {
    if (fd_ >= 0) ::close(fd_);
}

void SpillFile::write(std::uint64_t offset, const std::vector<std::uint8_t>& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw std::runtime_error("cannot write ray batch to the spill file in '" + dir_ +
                                     "': " + (n < 0 ? std::strerror(errno) : "no space left"));
        done += size_t(n);
    }
}

void SpillFile::read(std::uint64_t offset, std::vector<std::uint8_t>& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        ssize_t n = ::pread(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw std::runtime_error("cannot read ray batch back from the spill file in '" + dir_ +
                                     "': " + (n < 0 ? std::strerror(errno) : "file ended early"));
        done += size_t(n);
    }
}

std::uint64_t SpillFile::reserve(std::uint64_t size) {
    std::lock_guard<std::mutex> lock(mutex_);
    // First fit: batches are mostly of one size (2^e rays), so the first free range fits.
    for (auto it = free_.begin(); it != free_.end(); ++it)
        if (it->second >= size) {
            const std::uint64_t offset = it->first;
            it->first += size;
            it->second -= size;
            if (it->second == 0) free_.erase(it);
            return offset;
        }
    const std::uint64_t offset = end_;
    end_ += size;
    return offset;
}

void SpillFile::release(std::uint64_t offset, std::uint64_t size) {
    if (size == 0) return;
    std::lock_guard<std::mutex> lock(mutex_);
    // Kept sorted by offset, neighbours merged, so that freed batches make room for full ones.
    auto it =
        std::lower_bound(free_.begin(), free_.end(), std::make_pair(offset, std::uint64_t(0)));
    it = free_.insert(it, {offset, size});
    if (std::next(it) != free_.end() && it->first + it->second == std::next(it)->first) {
        it->second += std::next(it)->second;
        free_.erase(std::next(it));
    }
    if (it != free_.begin() && std::prev(it)->first + std::prev(it)->second == it->first) {
        std::prev(it)->second += it->second;
        free_.erase(it);
    }
}

} // namespace spw
