#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace haet {

namespace {

std::filesystem::path tempPathFor(const std::filesystem::path& target) {
    std::filesystem::path temp = target;
    temp += ".tmp." + std::to_string(::getpid());
    return temp;
}

// errno is set by the failed open/write underneath std::ofstream (libstdc++ uses POSIX calls).
std::string systemError(int code) { return code != 0 ? std::string(std::strerror(code)) : "unknown error"; }
std::string lastSystemError() { return systemError(errno); }

}  // namespace

AtomicOfstream::AtomicOfstream(std::filesystem::path target) : target_(std::move(target)), temp_(tempPathFor(target_)) {
    errno = 0;
    out_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!out_) throw IoError(target_, "cannot create temporary file " + temp_.string() + ": " + lastSystemError());
}

AtomicOfstream::~AtomicOfstream() {
    if (committed_) return;
    out_.close();
    std::error_code ignored;  // a destructor must not throw; a stale temp file is harmless
    std::filesystem::remove(temp_, ignored);
}

AtomicOfstream& AtomicOfstream::write(const void* data, std::size_t bytes) {
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    if (!out_ && error_ == 0) error_ = errno;  // EFBIG, ENOSPC: before anything else can change errno
    return *this;
}

void AtomicOfstream::commit() {
    if (committed_) throw IoError(target_, "AtomicOfstream committed twice");
    // A write through stream() that failed left its errno (the stream makes no system call once it has failed).
    if (!out_ && error_ == 0) error_ = errno;
    errno = 0;
    out_.flush();
    if (!out_ && error_ == 0) error_ = errno;
    const bool written = static_cast<bool>(out_);
    out_.close();
    if (out_.fail() && error_ == 0) error_ = errno;
    // The temporary file stays where it is (the destructor removes it): a short file never takes the target's place.
    if (!written || out_.fail())
        throw IoError(target_, "write to " + temp_.string() + " failed: " + systemError(error_));
    std::error_code ec;
    std::filesystem::rename(temp_, target_, ec);
    if (ec) throw IoError(target_, "cannot rename " + temp_.string() + " over it: " + ec.message());
    committed_ = true;
}

void writeFileAtomic(const std::filesystem::path& path, std::string_view content) {
    AtomicOfstream out(path);
    out.write(content.data(), content.size());
    out.commit();
}

}  // namespace haet
