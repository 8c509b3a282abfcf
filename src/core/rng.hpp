#pragma once
// Counter-based random numbers: Philox4x32-10 (Salmon, Moraes, Dror & Shaw, "Parallel random numbers: as easy as
// 1, 2, 3", SC11; the generator of the Random123 library). Each output block is a pure function of
// (seed, stream, counter), so a result depends only on the seed and on which stream and counter a caller uses, never on
// thread count or memory order. Streams separate independent users of the same seed; their ids live in RngStream.
#include <array>
#include <cmath>
#include <cstdint>

namespace haet {

/// Stream ids: one per operation that draws random numbers, so two operations never share a sequence.
enum class RngStream : std::uint64_t {
    Insert = 1,  ///< particle insertion (positions, radii, velocities)
    /// Inlets (run/flow.hpp): inlet k, 0-based in file order, draws from stream InletFirst + k.
    InletFirst = 0x100,
};

/// One Philox4x32-10 block: 128-bit counter and 64-bit key to 128 random bits.
/// Checked against the Random123 known-answer vectors (tests/test_scenario.cpp).
inline std::array<std::uint32_t, 4> philox4x32(std::array<std::uint32_t, 4> ctr, std::array<std::uint32_t, 2> key) {
    constexpr std::uint32_t kM0 = 0xD2511F53u, kM1 = 0xCD9E8D57u;  // round multipliers
    constexpr std::uint32_t kW0 = 0x9E3779B9u, kW1 = 0xBB67AE85u;  // Weyl key increments
    for (int round = 0; round < 10; ++round) {
        const std::uint64_t p0 = std::uint64_t(kM0) * ctr[0];
        const std::uint64_t p1 = std::uint64_t(kM1) * ctr[2];
        ctr = {std::uint32_t(p1 >> 32) ^ ctr[1] ^ key[0], std::uint32_t(p1), std::uint32_t(p0 >> 32) ^ ctr[3] ^ key[1],
               std::uint32_t(p0)};
        key[0] += kW0;
        key[1] += kW1;
    }
    return ctr;
}

/// A sequence of random numbers keyed by (seed, stream). The 64-bit seed is the Philox key, the stream fills the
/// high half of the counter and the position in the sequence its low half, so 2^64 streams of 2^65 doubles each.
class Rng {
public:
    Rng(std::uint64_t seed, std::uint64_t stream) : seed_(seed), stream_(stream) {}
    Rng(std::uint64_t seed, RngStream stream) : Rng(seed, static_cast<std::uint64_t>(stream)) {}

    /// Next 64 random bits.
    std::uint64_t bits() {
        if (have_ == 0) refill();
        --have_;
        return block_[have_];
    }

    /// Uniform in [0, 1), 53 random bits.
    double uniform() { return double(bits() >> 11) * 0x1.0p-53; }

    /// Uniform in [a, b).
    double uniform(double a, double b) { return a + (b - a) * uniform(); }

    /// Standard normal deviate (Box-Muller; the second value of each pair is kept for the next call).
    double normal() {
        if (haveNormal_) {
            haveNormal_ = false;
            return spareNormal_;
        }
        constexpr double twoPi = 6.28318530717958647692;
        const double u1 = 1.0 - uniform();  // in (0, 1]: log stays finite
        const double u2 = uniform();
        const double rad = std::sqrt(-2.0 * std::log(u1));
        spareNormal_ = rad * std::sin(twoPi * u2);
        haveNormal_ = true;
        return rad * std::cos(twoPi * u2);
    }

    /// Position in the sequence (number of 128-bit blocks consumed so far).
    std::uint64_t counter() const { return counter_; }

    /// Where the sequence stands, whole (a checkpoint's copy): a generator of the same seed and stream set to it
    /// draws what this one would. No padding, so that its bytes are its value.
    struct Position {
        std::uint64_t counter = 0;
        std::array<std::uint64_t, 2> block{};
        std::uint64_t have = 0;  ///< values of block not served yet (0, 1 or 2)
        std::uint64_t haveNormal = 0;
        double spareNormal = 0;
    };
    Position position() const {
        return {counter_, block_, static_cast<std::uint64_t>(have_), haveNormal_ ? 1u : 0u, spareNormal_};
    }
    /// Returns false (and changes nothing) for a position no generator can be in.
    bool setPosition(const Position& p) {
        if (p.have > 2 || p.haveNormal > 1) return false;
        counter_ = p.counter;
        block_ = p.block;
        have_ = static_cast<int>(p.have);
        haveNormal_ = p.haveNormal != 0;
        spareNormal_ = p.spareNormal;
        return true;
    }

private:
    void refill() {
        const auto out = philox4x32({std::uint32_t(counter_), std::uint32_t(counter_ >> 32), std::uint32_t(stream_),
                                     std::uint32_t(stream_ >> 32)},
                                    {std::uint32_t(seed_), std::uint32_t(seed_ >> 32)});
        ++counter_;
        // Served from index 1 down to 0, so the first value drawn is the block's first 64 bits.
        block_[1] = std::uint64_t(out[0]) | (std::uint64_t(out[1]) << 32);
        block_[0] = std::uint64_t(out[2]) | (std::uint64_t(out[3]) << 32);
        have_ = 2;
    }

    std::uint64_t seed_;
    std::uint64_t stream_;
    std::uint64_t counter_ = 0;
    std::array<std::uint64_t, 2> block_{};
    int have_ = 0;
    bool haveNormal_ = false;
    double spareNormal_ = 0;
};

}  // namespace haet
