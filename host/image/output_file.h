// Every file Spillway writes (the image, --stats, --error-csv, compare's heatmap) appears whole
// or not at all. The bytes go to an anonymous file (O_TMPFILE) in the destination's folder; only
// after every write, and the flush to disk, succeeded is it given a temporary name (linkat) and
// renamed over the destination, with SIGINT and SIGTERM held back for those two calls. A process
// that fails or is killed before commit() leaves no file, and an existing file at the destination
// is replaced atomically or left as it was. Where the file system has no O_TMPFILE the file is
// created under a hidden temporary name and removed on failure.
//
// A destination that exists and is not a regular file (/dev/stdout, a FIFO, /dev/full) is
// written in place: there is nothing to rename over, and its write errors are still reported.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace spw {

class OutputFile {
  public:
    // Opens the anonymous file. Throws std::runtime_error "cannot write 'PATH': why".
    explicit OutputFile(std::string path);
    ~OutputFile(); // discards the bytes unless commit() ran
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    // Throws std::runtime_error naming the path on any error (a full disk, a file-size limit).
    void write(const void* data, std::size_t size);
    void write(const std::string& text) { write(text.data(), text.size()); }
    // Writes at `offset` from the start of the file (pwrite), where seekable(): an image writer
    // that goes back to fill in a table. Throws like write().
    void writeAt(std::uint64_t offset, const void* data, std::size_t size);
    // Whether writeAt() can be used: not for a destination written in place (a FIFO).
    bool seekable() const { return !inPlace_; }
    // Flushes to disk: where a late write-back error (a full disk) surfaces. Throws like write().
    void flush();
    // Flushes (if not done) and gives the file its name. Throws like write().
    void commit();
    const std::string& path() const { return path_; }

  private:
    [[noreturn]] void fail(const std::string& what, int err) const;
    std::string path_;
    std::string tempName_; // the named temporary, where O_TMPFILE was not available
    int fd_ = -1;
    bool inPlace_ = false;
    bool flushed_ = false;
    bool committed_ = false;
};

// The whole file in one go.
void writeFileAtomically(const std::string& path, const void* data, std::size_t size);
inline void writeFileAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(path, text.data(), text.size());
}

// Throws std::runtime_error "cannot write 'PATH': why" when a file could not be created at
// `path` later: its folder is missing or not a folder or not writable, or `path` is a folder.
// Called for every output before a render starts, so that no work is lost to a typo.
void checkWritable(const std::string& path);

// Whether two paths name one file: both exist and are the same file (a hard link, a symbolic
// link, another spelling), or, where one does not exist yet, they resolve to the same path.
bool sameFile(const std::string& a, const std::string& b);

} // namespace spw
