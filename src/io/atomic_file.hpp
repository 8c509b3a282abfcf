#pragma once
// Atomic file replacement: write a temporary file next to the target, then rename it over the target.
// A reader (ParaView, a plotting script, a crashed run's post-mortem) sees either the old file or the new
// one, never a half-written one. rename() within one directory is atomic on POSIX file systems.
//
// The data is flushed to the kernel before the rename but not fsync'ed: this protects against the process
// crashing or being killed, not against a power loss. An fsync per snapshot would cost more than the
// guarantee is worth for simulation output. One writer per target at a time (the temp name is per process).
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace haet {

/// An output file that could not be written. The message starts with the path.
class IoError : public std::runtime_error {
public:
    IoError(const std::filesystem::path& path, const std::string& what)
        : std::runtime_error(path.string() + ": " + what), path_(path) {}
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

/// Replaces `path` with `content` atomically. Throws IoError on failure (the old file, if any, is kept).
void writeFileAtomic(const std::filesystem::path& path, std::string_view content);

/// A binary output stream for large files that replaces its target only on commit().
/// Without commit() (an exception, an early return) the destructor removes the temp file and the old
/// target stays as it was. Write errors are collected by the stream and reported by commit().
class AtomicOfstream {
public:
    /// Opens `<target>.tmp.<pid>` in the target's directory. Throws IoError if it cannot be created.
    explicit AtomicOfstream(std::filesystem::path target);
    ~AtomicOfstream();
    AtomicOfstream(const AtomicOfstream&) = delete;
    AtomicOfstream& operator=(const AtomicOfstream&) = delete;

    std::ostream& stream() { return out_; }
    AtomicOfstream& write(const void* data, std::size_t bytes);
    template <class T>
    AtomicOfstream& operator<<(const T& value) {
        out_ << value;
        return *this;
    }

    /// Flushes, closes and renames the temp file over the target. Throws IoError on any failure so far.
    void commit();

    const std::filesystem::path& target() const { return target_; }
    const std::filesystem::path& tempPath() const { return temp_; }

private:
    std::filesystem::path target_;
    std::filesystem::path temp_;
    std::ofstream out_;
    int error_ = 0;  ///< errno of the first failed write (a later call may change errno before commit reports it)
    bool committed_ = false;
};

}  // namespace haet
