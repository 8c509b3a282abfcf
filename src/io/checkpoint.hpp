#pragma once
// The checkpoint file format (ARCHITECTURE.md, "Checkpoints"): a run's whole state in one versioned binary file, for
// `haet run --resume`. Little-endian throughout:
//
//   magic "HAETCKPT" (8 bytes) | format version (u32) | body length (u64) | CRC-32 of the body (u32) | body
//   body: the header's fields (dimension, method, scenario hash, time, sequence), then sections, each
//         tag (4 bytes) | length (u64) | bytes
//
// The version is read before anything else, so that a file of a later format is named as such, not as corrupt; the
// checksum (zlib's CRC-32) covers every byte after it, so that a truncated or damaged file is found before any of its
// contents is believed. Readers take bytes from memory (parseCheckpoint) and check every length against what is left:
// no input makes them read outside it, allocate more than it holds, or loop.
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace haet {

static_assert(std::endian::native == std::endian::little, "the checkpoint format is little-endian");

/// The format this program writes and the newest it reads. Raise it with every change of what any section holds;
/// a reader of version k reads files of version k only (a state whose meaning changed cannot be carried over).
inline constexpr std::uint32_t kCheckpointVersion = 3;
inline constexpr std::string_view kCheckpointMagic = "HAETCKPT";

/// What is wrong with a checkpoint, for the message and for whether an older one may serve instead.
enum class CheckpointFault {
    Truncated,      ///< shorter than it says: a write that never finished
    Corrupt,        ///< not a checkpoint, or its checksum or structure is wrong
    FutureVersion,  ///< written by a later format
    OtherScenario,  ///< of another scenario (hash), or of the same one changed in a key that is not safe to change
};

class CheckpointError : public std::runtime_error {
public:
    CheckpointError(CheckpointFault fault, const std::string& what) : std::runtime_error(what), fault_(fault) {}
    CheckpointFault fault() const { return fault_; }

private:
    CheckpointFault fault_;
};

/// Appends values as their bytes. Only types without padding (numbers, Vec, arrays of them): a padded struct would
/// write bytes no one set, and the same state would not give the same file.
class ByteWriter {
public:
    template <class T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto* b = reinterpret_cast<const char*>(&v);
        bytes_.append(b, sizeof(T));
    }
    /// A count (u64), then the elements' bytes.
    template <class T>
    void putVector(const std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        put<std::uint64_t>(v.size());
        bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    void putString(std::string_view s) {
        put<std::uint64_t>(s.size());
        bytes_.append(s);
    }
    /// Starts a section (tag: 4 characters); its length is filled in by endSection.
    void beginSection(std::string_view tag);
    void endSection();

    const std::string& bytes() const { return bytes_; }
    std::string take() { return std::move(bytes_); }

private:
    std::string bytes_;
    std::size_t open_ = std::string::npos;  // offset of the open section's length field
};

/// Reads what a ByteWriter wrote, from bytes it does not own. Every read checks the length left: running out, or a
/// count larger than the bytes left can hold, throws CheckpointError (Corrupt), naming `what` (the section).
class ByteReader {
public:
    ByteReader(std::string_view bytes, std::string what) : b_(bytes), what_(std::move(what)) {}

    template <class T>
    T get() {
        static_assert(std::is_trivially_copyable_v<T>);
        need(sizeof(T), "a value");
        T v;
        std::memcpy(&v, b_.data() + at_, sizeof(T));
        at_ += sizeof(T);
        return v;
    }
    template <class T>
    void getVector(std::vector<T>& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const std::uint64_t n = get<std::uint64_t>();
        if (n > (b_.size() - at_) / sizeof(T)) fail("an array longer than the bytes left");
        v.resize(n);
        if (n) std::memcpy(v.data(), b_.data() + at_, n * sizeof(T));
        at_ += n * sizeof(T);
    }
    /// A vector that must hold exactly n elements.
    template <class T>
    void getVector(std::vector<T>& v, std::size_t n, const char* name) {
        getVector(v);
        if (v.size() != n)
            fail(std::string(name) + " has " + std::to_string(v.size()) + " entries, not " + std::to_string(n));
    }
    std::string getString() {
        const std::uint64_t n = get<std::uint64_t>();
        if (n > b_.size() - at_) fail("a text longer than the bytes left");
        std::string s(b_.substr(at_, n));
        at_ += n;
        return s;
    }
    bool done() const { return at_ == b_.size(); }
    /// The bytes not read yet.
    std::string_view rest() const { return b_.substr(at_); }
    /// Skips n bytes (throws when fewer are left).
    void skip(std::size_t n) {
        need(n, "a skipped block");
        at_ += n;
    }
    /// Throws unless every byte was read.
    void expectEnd() const {
        if (!done()) fail(std::to_string(b_.size() - at_) + " bytes left over");
    }
    /// Throws CheckpointError (Corrupt): "section WHAT: why".
    [[noreturn]] void fail(const std::string& why) const;
    const std::string& what() const { return what_; }

private:
    void need(std::size_t n, const char* thing) const {
        if (n > b_.size() - at_) fail(std::string("ends inside ") + thing);
    }
    std::string_view b_;
    std::size_t at_ = 0;
    std::string what_;
};

/// The header's fields.
struct CheckpointHeader {
    std::uint32_t version = kCheckpointVersion;
    std::uint32_t dimension = 0;  ///< 2 or 3
    std::string method;           ///< "tdm", "edm", "haet"
    std::string scenarioHash;     ///< hash of the scenario's keys that a resume may not change (16 hex digits)
    double time = 0;              ///< simulated time of the state [s]
    std::uint64_t sequence = 0;   ///< 1 for a run's first checkpoint, then one more each
};

/// A parsed checkpoint: the header and its sections, as views into the bytes given to parseCheckpoint.
struct CheckpointFile {
    CheckpointHeader header;
    std::vector<std::pair<std::string, std::string_view>> sections;  ///< (tag, bytes) in file order

    bool has(std::string_view tag) const;
    /// A reader over section `tag`; throws CheckpointError (Corrupt) when the file has none.
    ByteReader section(std::string_view tag) const;
};

/// The whole file: header, then `body` (sections written by a ByteWriter), with the checksum.
std::string encodeCheckpoint(const CheckpointHeader& h, std::string_view sections);

/// Checks and splits a checkpoint held in memory: magic, version (a later one: FutureVersion), length (shorter:
/// Truncated), checksum and structure (Corrupt). Throws CheckpointError; on success the views point into `bytes`.
/// The fuzz target's entry point: it never reads outside `bytes`, whatever they hold.
CheckpointFile parseCheckpoint(std::string_view bytes);

/// CRC-32 (zlib's) of bytes.
std::uint32_t crc32Of(std::string_view bytes);

}  // namespace haet
