#pragma once
// The event-driven engine's reference twin (EdmSettings::reference; tests): the next event by brute force, every
// pair and every wall at every event (O(N^2) per event), no cells, no queue. It reads the engine's slots and
// predicts with the same canonical times (Slots::pairTime, wallTime), so the fast engine and the twin produce
// bit-identical event sequences (tests/test_edm_engine.cpp).
#include <cstdint>

#include "edm/slots.hpp"

namespace haet::edm {

template <int D>
class Reference {
public:
    struct Event {
        double time = kNever;                      ///< [s]
        std::uint32_t slot = 0;                    ///< the moving slot
        std::uint32_t code = kNone << kTypeShift;  ///< kPair or kWall with the partner; kNone: the horizon
    };
    /// rmax: the largest radius [m].
    Reference(const Slots<D>& slots, double rmax) : sl_(slots), rmax_(rmax) {}
    /// The earliest pair or wall event of any moving slot after now; or, if it is sooner, the horizon within which
    /// every pair that collides is at its minimum image (periodic boxes), as an event of type kNone.
    Event next(double now) const;

private:
    const Slots<D>& sl_;
    double rmax_;
};

}  // namespace haet::edm
