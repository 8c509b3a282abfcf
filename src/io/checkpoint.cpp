#include "io/checkpoint.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>

namespace haet {

namespace {

constexpr std::size_t kPrefix = 8 + 4 + 8 + 4;  // magic, version, body length, CRC

template <class T>
void putRaw(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <class T>
T getRaw(std::string_view b, std::size_t at) {
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    return v;
}

}  // namespace

void ByteWriter::beginSection(std::string_view tag) {
    if (tag.size() != 4) throw std::logic_error("checkpoint section tags have 4 characters");
    if (open_ != std::string::npos) throw std::logic_error("checkpoint section opened inside another");
    bytes_.append(tag);
    open_ = bytes_.size();
    put<std::uint64_t>(0);
}

void ByteWriter::endSection() {
    if (open_ == std::string::npos) throw std::logic_error("checkpoint section closed without being opened");
    const std::uint64_t n = bytes_.size() - open_ - sizeof(std::uint64_t);
    std::memcpy(bytes_.data() + open_, &n, sizeof n);
    open_ = std::string::npos;
}

void ByteReader::fail(const std::string& why) const {
    throw CheckpointError(CheckpointFault::Corrupt, "corrupt checkpoint: section " + what_ + ": " + why);
}

bool CheckpointFile::has(std::string_view tag) const {
    return std::any_of(sections.begin(), sections.end(), [&](const auto& s) { return s.first == tag; });
}

ByteReader CheckpointFile::section(std::string_view tag) const {
    for (const auto& [t, bytes] : sections)
        if (t == tag) return ByteReader(bytes, t);
    throw CheckpointError(CheckpointFault::Corrupt,
                          "corrupt checkpoint: no section " + std::string(tag) + " (a " + header.method + " run's)");
}

std::uint32_t crc32Of(std::string_view bytes) {
    return static_cast<std::uint32_t>(
        crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

std::string encodeCheckpoint(const CheckpointHeader& h, std::string_view sections) {
    ByteWriter head;
    head.put<std::uint32_t>(h.dimension);
    head.putString(h.method);
    head.putString(h.scenarioHash);
    head.put<double>(h.time);
    head.put<std::uint64_t>(h.sequence);
    std::string body = head.take();
    body.append(sections);
    std::string out;
    out.reserve(kPrefix + body.size());
    out.append(kCheckpointMagic);
    putRaw<std::uint32_t>(out, kCheckpointVersion);
    putRaw<std::uint64_t>(out, body.size());
    putRaw<std::uint32_t>(out, crc32Of(body));
    out.append(body);
    return out;
}

CheckpointFile parseCheckpoint(std::string_view bytes) {
    auto corrupt = [](const std::string& why) {
        return CheckpointError(CheckpointFault::Corrupt, "corrupt checkpoint: " + why);
    };
    if (bytes.size() < kCheckpointMagic.size() || bytes.substr(0, kCheckpointMagic.size()) != kCheckpointMagic)
        throw corrupt("not a HAET checkpoint (no magic number \"HAETCKPT\" at the start)");
    if (bytes.size() < kPrefix)
        throw CheckpointError(CheckpointFault::Truncated, "truncated checkpoint: " + std::to_string(bytes.size()) +
                                                              " bytes, shorter than its header");
    CheckpointFile f;
    f.header.version = getRaw<std::uint32_t>(bytes, 8);
    if (f.header.version > kCheckpointVersion)
        throw CheckpointError(CheckpointFault::FutureVersion,
                              "checkpoint of format version " + std::to_string(f.header.version) +
                                  ", newer than this program's " + std::to_string(kCheckpointVersion) +
                                  ": resume it with the version of haet that wrote it");
    if (f.header.version == 0) throw corrupt("format version 0 does not exist");
    if (f.header.version != kCheckpointVersion)  // a state whose meaning changed since is not carried over
        throw corrupt("checkpoint of format version " + std::to_string(f.header.version) +
                      ", older than this program's " + std::to_string(kCheckpointVersion) +
                      ": resume it with the version of haet that wrote it");
    const auto length = getRaw<std::uint64_t>(bytes, 12);
    const auto crc = getRaw<std::uint32_t>(bytes, 20);
    const std::size_t have = bytes.size() - kPrefix;
    if (length > have)
        throw CheckpointError(CheckpointFault::Truncated, "truncated checkpoint: " + std::to_string(have) +
                                                              " bytes after the header, " + std::to_string(length) +
                                                              " announced");
    if (length < have) throw corrupt(std::to_string(have - length) + " bytes after the announced end");
    const std::string_view body = bytes.substr(kPrefix);
    if (crc32Of(body) != crc) throw corrupt("checksum mismatch (the file was changed or damaged)");

    ByteReader r(body, "header");
    f.header.dimension = r.get<std::uint32_t>();
    f.header.method = r.getString();
    f.header.scenarioHash = r.getString();
    f.header.time = r.get<double>();
    f.header.sequence = r.get<std::uint64_t>();
    if (f.header.dimension != 2 && f.header.dimension != 3) r.fail("dimension " + std::to_string(f.header.dimension));
    if (f.header.method != "tdm" && f.header.method != "edm" && f.header.method != "haet")
        r.fail("unknown method \"" + f.header.method + "\"");
    // Sections: tag, length, bytes, to the end of the body.
    while (!r.done()) {
        const std::string_view rest = r.rest();
        if (rest.size() < 4) r.fail("a section tag cut short");
        std::string tag(rest.substr(0, 4));
        r.skip(4);
        const auto n = r.get<std::uint64_t>();
        if (n > r.rest().size()) r.fail("section " + tag + " longer than the bytes left");
        f.sections.emplace_back(std::move(tag), r.rest().substr(0, n));
        r.skip(n);
    }
    return f;
}

}  // namespace haet
