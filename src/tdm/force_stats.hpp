#pragma once
// What a force pass reports of its particles: contacts, the worst overlap, the virial, the first non-finite
// particle. Summed range by range in particle order (tdm/pair_pass.hpp), so the result does not depend on the
// thread count.
#include <cstddef>
#include <cstdint>

namespace haet {

struct ForceStats {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t contacts = 0;       ///< pair and wall contacts
    double maxOverlapRatio = 0;     ///< largest overlap / smaller radius
    std::size_t worstParticle = 0;  ///< particle with that overlap
    double virial = 0;              ///< sum over pair contacts of r_ij . F_ij, summed particle by particle [J]
    std::size_t nonFinite = kNone;  ///< first particle with a non-finite position or force, or kNone
};

/// What a range of the pass reports of its particles: ForceStats without the virial, which is summed per particle.
struct RangeTally {
    std::size_t contacts = 0;
    double maxOverlapRatio = 0;
    std::size_t worstParticle = 0;
    std::size_t nonFinite = ForceStats::kNone;
};

/// Folds a range's statistics into the step's; ranges come in particle order, so the result is the one-thread one.
inline void addTally(ForceStats& st, const RangeTally& t) {
    st.contacts += t.contacts;
    if (t.maxOverlapRatio > st.maxOverlapRatio) {
        st.maxOverlapRatio = t.maxOverlapRatio;
        st.worstParticle = t.worstParticle;
    }
    if (st.nonFinite == ForceStats::kNone) st.nonFinite = t.nonFinite;
}

/// What finishing one particle reports.
struct ParticleTally {
    double worst;            ///< largest overlap / smaller radius, pairs and walls
    std::uint32_t contacts;  ///< own pairs and walls in contact
    bool finite;             ///< position and force finite
};

}  // namespace haet
