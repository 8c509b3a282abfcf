#pragma once
// Priority structures over N particle slots, one pending event time per slot (PHYSICS.md D.1, D.5).
// All three give the same answer: the slot with the smallest time, ties broken by the lower slot index.
//
//  * EventTree: complete binary (tournament) tree, Marin, Risso & Cordero, J. Comput. Phys. 109, 306 (1993).
//    Internal node k holds the winner (the slot of smallest time) of its two children; changing one slot replays
//    the path to the root and stops early once a node's winner is unchanged and is not the changed slot. N leaves
//    and N - 1 nodes, 12 bytes per slot (a tree padded to a power of two took up to twice that).
//    (A variant holding the winner's time in the node, one cache line per level, measured no faster in the
//    engine and takes twice the memory.)
//  * EventHeap: binary heap of slots with handles (position of each slot in the heap), decrease/increase-key.
//  * EventScan: the reference twin, a linear scan for the minimum.
//
// The engine uses EventTree: bench/edm_queue.cpp measures it against EventHeap (docs/edm.md has the numbers).
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace haet {

class EventTree {
public:
    /// n slots, every time +infinity.
    void reset(std::size_t n) {
        n_ = n;
        leaves_ = std::max<std::size_t>(n, 2);
        pow_ = 1;
        while (pow_ < leaves_) pow_ *= 2;
        time_.assign(leaves_, std::numeric_limits<double>::infinity());
        node_.assign(leaves_, 0);
        for (std::size_t k = leaves_ - 1; k >= 1; --k) node_[k] = play(k);
    }
    std::size_t size() const { return n_; }
    /// Sets all times at once (t.size() slots), O(N).
    void build(const std::vector<double>& t) {
        reset(t.size());
        std::copy(t.begin(), t.end(), time_.begin());
        for (std::size_t k = leaves_ - 1; k >= 1; --k) node_[k] = play(k);
    }

    void update(std::uint32_t i, double t) {
        time_[i] = t;
        std::size_t k = leafOf(i) >> 1;
        while (k >= 1) {
            const std::uint32_t w = play(k);
            if (node_[k] == w && w != i) break;  // the subtree's winner and its time are unchanged
            node_[k] = w;
            k >>= 1;
        }
    }
    std::uint32_t top() const { return node_[1]; }
    double topTime() const { return time_[node_[1]]; }
    double time(std::uint32_t i) const { return time_[i]; }
    std::size_t memoryBytes() const { return time_.capacity() * sizeof(double) + node_.capacity() * 4; }

private:
    // The tree has as many leaves as slots (at least two), node k has the children 2k and 2k + 1, and the leaves are
    // the nodes leaves_ to 2 leaves_ - 1. Unless leaves_ is a power of two they lie on two levels, the deeper ones
    // (from pow_ on) to the left of the others; the lower slots go to the deeper leaves, so that left is always the
    // lower slot and a tie goes to the left child without comparing slots (a comparison of slots made the choice a
    // branch, mispredicted half the time).
    std::size_t leafOf(std::uint32_t i) const { return i < 2 * leaves_ - pow_ ? pow_ + i : i + pow_ - leaves_; }
    std::uint32_t winner(std::size_t k) const {
        if (k < leaves_) return node_[k];
        return static_cast<std::uint32_t>(k >= pow_ ? k - pow_ : k + leaves_ - pow_);
    }
    std::uint32_t play(std::size_t k) const {
        const std::uint32_t a = winner(2 * k), b = winner(2 * k + 1);
        return time_[b] < time_[a] ? b : a;  // ties: the left (lower) slot
    }
    std::size_t n_ = 0, leaves_ = 2, pow_ = 2;
    std::vector<double> time_;         // one per leaf (a padding leaf stays infinite)
    std::vector<std::uint32_t> node_;  // node_[1..leaves_-1]: winner slot of the subtree
};

class EventHeap {
public:
    void reset(std::size_t n) {
        time_.assign(n, std::numeric_limits<double>::infinity());
        heap_.resize(n);
        pos_.resize(n);
        for (std::size_t i = 0; i < n; ++i) heap_[i] = pos_[i] = static_cast<std::uint32_t>(i);
    }
    std::size_t size() const { return time_.size(); }

    void update(std::uint32_t i, double t) {
        const double old = time_[i];
        time_[i] = t;
        if (t < old)
            up(pos_[i]);
        else
            down(pos_[i]);
    }
    std::uint32_t top() const { return heap_[0]; }
    double topTime() const { return time_[heap_[0]]; }
    double time(std::uint32_t i) const { return time_[i]; }
    std::size_t memoryBytes() const { return time_.capacity() * 8 + heap_.capacity() * 4 + pos_.capacity() * 4; }

private:
    bool less(std::uint32_t a, std::uint32_t b) const { return time_[a] < time_[b] || (time_[a] == time_[b] && a < b); }
    void place(std::size_t k, std::uint32_t i) {
        heap_[k] = i;
        pos_[i] = static_cast<std::uint32_t>(k);
    }
    void up(std::size_t k) {
        const std::uint32_t i = heap_[k];
        while (k > 0) {
            const std::size_t p = (k - 1) / 2;
            if (!less(i, heap_[p])) break;
            place(k, heap_[p]);
            k = p;
        }
        place(k, i);
    }
    void down(std::size_t k) {
        const std::size_t n = heap_.size();
        const std::uint32_t i = heap_[k];
        for (;;) {
            std::size_t c = 2 * k + 1;
            if (c >= n) break;
            if (c + 1 < n && less(heap_[c + 1], heap_[c])) ++c;
            if (!less(heap_[c], i)) break;
            place(k, heap_[c]);
            k = c;
        }
        place(k, i);
    }
    std::vector<double> time_;
    std::vector<std::uint32_t> heap_, pos_;
};

/// Reference twin: the minimum by a linear scan (O(N) per query).
class EventScan {
public:
    void reset(std::size_t n) { time_.assign(n, std::numeric_limits<double>::infinity()); }
    std::size_t size() const { return time_.size(); }
    void update(std::uint32_t i, double t) { time_[i] = t; }
    std::uint32_t top() const {
        std::uint32_t best = 0;
        for (std::uint32_t i = 1; i < time_.size(); ++i)
            if (time_[i] < time_[best]) best = i;
        return best;
    }
    double topTime() const { return time_.empty() ? std::numeric_limits<double>::infinity() : time_[top()]; }
    double time(std::uint32_t i) const { return time_[i]; }

private:
    std::vector<double> time_;
};

}  // namespace haet
