#pragma once
// The TC model against inelastic collapse (Luding & McNamara 1998; docs/physics.md A.4, D.7; docs/edm.md): a collision
// less than the TC time after the previous collision of either particle is elastic (e = 1, beta = -1), and against a
// fixed obstacle that gravity pushes a particle into, the normal speed after a collision is at least |n.g| t_c (the
// rest hop: a flight of 2 t_c instead of coming to rest through infinitely many collisions).
#include <cstdint>
#include <limits>
#include <vector>

namespace haet::edm {

class TcModel {
public:
    /// TC time [s]; 0: off.
    explicit TcModel(double tc = 0) : tc_(tc) {}
    double time() const { return tc_; }
    bool on() const { return tc_ > 0; }

    /// n slots, none collided yet.
    void reset(std::size_t n) {
        if (on())
            last_.assign(n, -std::numeric_limits<double>::infinity());
        else
            std::vector<double>().swap(last_);
    }
    /// Room for n slots; the new ones have not collided.
    void grow(std::size_t n) {
        if (on() && last_.size() < n) last_.resize(n, -std::numeric_limits<double>::infinity());
    }
    /// Slots renumbered: slot k is old slot order[k].
    void permute(const std::vector<std::uint32_t>& order) {
        if (last_.empty()) return;
        std::vector<double> t(order.size());
        for (std::size_t k = 0; k < order.size(); ++k) t[k] = last_[order[k]];
        last_.swap(t);
    }
    /// Whether a collision of slots a and b (b = kNil: a wall or frozen partner) at time t is made elastic.
    bool elastic(std::uint32_t a, std::uint32_t b, double t) const {
        if (!on()) return false;
        if (t - last_[a] < tc_) return true;
        return b != 0xFFFFFFFFu && t - last_[b] < tc_;
    }
    /// Slot s collided at time t.
    void collided(std::uint32_t s, double t) {
        if (on()) last_[s] = t;
    }
    /// A new particle in slot s: no previous collision.
    void forget(std::uint32_t s) {
        if (on()) last_[s] = -std::numeric_limits<double>::infinity();
    }
    /// The least normal speed after a collision with a fixed obstacle whose normal has gravity component gAcc
    /// (n.g) [m/s]: |n.g| t_c when gravity pushes into the obstacle, else 0.
    double restSpeed(double gAcc) const { return (on() && gAcc < 0) ? -gAcc * tc_ : 0; }
    std::size_t memoryBytes() const { return last_.capacity() * sizeof(double); }
    /// Each slot's time of its last collision (empty when off): a checkpoint's copy, and back.
    const std::vector<double>& lastCollisions() const { return last_; }
    void setLastCollisions(std::vector<double> t) { last_ = std::move(t); }

private:
    double tc_ = 0;
    std::vector<double> last_;  // per slot: time of the last collision (only when on)
};

}  // namespace haet::edm
