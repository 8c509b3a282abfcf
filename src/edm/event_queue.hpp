#pragma once
// Priority structures over N particle slots, one pending event time per slot (docs/physics.md D.1, D.5).
// All three give the same answer: the slot with the smallest time, ties broken by the lower slot index.
//
//  * EventTree: complete binary (tournament) tree, Marin, Risso & Cordero, J. Comput. Phys. 109, 306 (1993).
//    Internal node k holds the winner (the slot of smallest time) of its two children; changing one slot replays
//    the path to the root and stops early once a node's winner is unchanged and is not the changed slot. N leaves
//    and N - 1 nodes, 12 bytes per slot (a tree padded to a power of two took up to twice that).
//    (A variant holding the winner's time in the node, one cache line per level, measured no faster in the
//    engine and takes twice the memory.)
//  * EventHeap: binary heap of slots with handles (position of each slot in the heap), decrease/increase-key.
//  * EventCalendar: buckets of equal time width with lazy deletion, a small heap for the current bucket.
//  * EventScan: the reference twin, a linear scan for the minimum.
//
// The engine uses EventCalendar: fewer cache misses per collision than the tree (docs/edm.md has the numbers;
// bench/edm_queue.cpp measures the three on the engine's access pattern).
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

/// Calendar queue (Brown 1988) with lazy deletion, after the event calendars of the fast public codes (Paul,
/// J. Comput. Phys. 221, 615 (2007); Smallenburg 2022). Time is cut into buckets of equal width. The events of the
/// current bucket are in a small binary heap of (time, slot); those of the next B - 1 buckets (a ring) in unsorted
/// lists of slots, stored in chunks of 14 from a pool; the rest in an overflow list. A new time is appended where
/// it belongs and the entry it replaces stays where it is: it is dropped when its turn comes, its time no longer
/// being the slot's. Moving on to the next bucket takes the slots of its list whose time falls into it into the
/// heap. The order is the tree's: the smallest time, ties to the lower slot. The width is chosen from the times
/// whenever the queue is filled or rebuilt: about kPerBucket events per bucket, a ring of ~4 N / kPerBucket
/// buckets (a power of two). An update touches the slot's time and one chunk, where the tree replays a path of
/// log2 N nodes; memory: 8 bytes per slot, 4 per entry in the lists (a valid one per slot, plus the replaced ones
/// not yet dropped) and the chunks' unused room.
class EventCalendar {
public:
    static constexpr double kPerBucket = 64;

    void reset(std::size_t n) {
        time_.assign(n, std::numeric_limits<double>::infinity());
        dirty_ = true;
    }
    std::size_t size() const { return time_.size(); }
    /// Sets all times at once (t.size() slots).
    void build(const std::vector<double>& t) {
        time_ = t;
        dirty_ = true;
    }
    void update(std::uint32_t i, double t) {
        time_[i] = t;
        if (!dirty_) place(i, t);
    }
    std::uint32_t top() const {
        settle();
        return heap_.empty() ? 0 : heap_.front().slot;  // every time infinite: the lowest slot, as the tree
    }
    double topTime() const {
        settle();
        return heap_.empty() ? std::numeric_limits<double>::infinity() : heap_.front().time;
    }
    double time(std::uint32_t i) const { return time_[i]; }
    /// Elements in use (the room a vector's growth leaves at its end is never touched, so never resident).
    std::size_t memoryBytes() const {
        return time_.size() * sizeof(double) + heap_.size() * sizeof(Entry) + ring_.size() * 4 + pool_.size() * 4 +
               overflow_.size() * 4;
    }

private:
    struct Entry {
        double time;
        std::uint32_t slot;
    };
    static constexpr std::uint32_t kNil = 0xFFFFFFFFu;
    // A chunk: the next chunk of the bucket's list (or of the free list), the count, then kChunkSlots slots.
    static constexpr std::uint32_t kChunk = 16, kChunkSlots = kChunk - 2;
    // The heap's order, as a function object: the heap algorithms inline it (a function pointer is called).
    struct Later {
        bool operator()(const Entry& a, const Entry& b) const {
            return a.time > b.time || (a.time == b.time && a.slot > b.slot);
        }
    };
    static constexpr Later later{};
    double rel(double t) const { return (t - origin_) * invWidth_; }  // bucket coordinate

    // Time t of slot i to the heap (its bucket is the current one or earlier), a bucket of the ring, or the overflow.
    void place(std::uint32_t i, double t) const {
        if (!(t < std::numeric_limits<double>::infinity())) return;
        const double r = rel(t);
        if (r < static_cast<double>(cur_ + 1)) {
            heap_.push_back({t, i});
            std::push_heap(heap_.begin(), heap_.end(), later);
        } else if (r < static_cast<double>(cur_ + ring_.size())) {
            std::uint32_t& head = ring_[static_cast<std::uint64_t>(r) & mask_];
            std::uint32_t c = head;
            if (c == kNil || pool_[c * kChunk + 1] == kChunkSlots) {
                std::uint32_t n = free_;
                if (n != kNil) {
                    free_ = pool_[n * kChunk];
                } else {
                    n = static_cast<std::uint32_t>(pool_.size() / kChunk);
                    pool_.resize(pool_.size() + kChunk);
                }
                pool_[n * kChunk] = c;
                pool_[n * kChunk + 1] = 0;
                head = c = n;
            }
            std::uint32_t* chunk = &pool_[c * kChunk];
            chunk[2 + chunk[1]++] = i;
            ++inRing_;
        } else {
            overflow_.push_back(i);
        }
    }
    // The front of the heap is a valid event, or there is none.
    void settle() const {
        if (dirty_) retune();
        for (;;) {
            while (!heap_.empty() && heap_.front().time != time_[heap_.front().slot]) {
                std::pop_heap(heap_.begin(), heap_.end(), later);
                heap_.pop_back();
            }
            if (!heap_.empty()) return;
            if (inRing_ == 0) {
                if (overflow_.empty()) return;
                retune();
                continue;
            }
            ++cur_;
            std::uint32_t& head = ring_[cur_ & mask_];
            for (std::uint32_t c = head; c != kNil;) {
                std::uint32_t* chunk = &pool_[c * kChunk];
                inRing_ -= chunk[1];
                for (std::uint32_t q = 0; q < chunk[1]; ++q) {
                    const std::uint32_t i = chunk[2 + q];
                    const double t = time_[i];
                    const double r = rel(t);
                    if (r >= static_cast<double>(cur_) && r < static_cast<double>(cur_ + 1)) heap_.push_back({t, i});
                }
                const std::uint32_t next = chunk[0];
                chunk[0] = free_;
                free_ = c;
                c = next;
            }
            head = kNil;
            std::make_heap(heap_.begin(), heap_.end(), later);
            // Every half turn of the ring the overflow's times that now fall within it move in; the others are at
            // least half a turn ahead, so none is due before the next half turn.
            if ((cur_ & (mask_ >> 1)) == 0 && !overflow_.empty()) {
                std::vector<std::uint32_t> o;
                o.swap(overflow_);
                for (const std::uint32_t i : o)
                    if (rel(time_[i]) >= static_cast<double>(cur_ + 1)) place(i, time_[i]);  // else replaced since
            }
        }
    }
    // A new width and ring from the slots' times; every finite time placed afresh.
    void retune() const {
        dirty_ = false;
        heap_.clear();
        overflow_.clear();
        pool_.clear();
        free_ = kNil;
        inRing_ = 0;
        double tmin = std::numeric_limits<double>::infinity();
        std::size_t m = 0;
        for (const double t : time_)
            if (t < std::numeric_limits<double>::infinity()) {
                tmin = std::min(tmin, t);
                ++m;
            }
        std::size_t buckets = 2;
        while (static_cast<double>(buckets) < 4.0 * static_cast<double>(m) / kPerBucket) buckets *= 2;
        ring_.assign(buckets, kNil);
        mask_ = buckets - 1;
        cur_ = 0;
        if (m == 0) return;
        // How far ahead the events lie: the median of up to 1024 of them (every k-th finite time), which a few
        // events far ahead (a particle alone in a large box) do not move as they would move the mean. For
        // exponentially distributed delays the mean is the median / ln 2.
        std::vector<double> sample;
        const std::size_t every = std::max<std::size_t>(1, m / 1024);
        std::size_t k = 0;
        for (const double t : time_)
            if (t < std::numeric_limits<double>::infinity() && k++ % every == 0) sample.push_back(t - tmin);
        std::nth_element(sample.begin(), sample.begin() + sample.size() / 2, sample.end());
        const double span = sample[sample.size() / 2] / 0.6931471805599453;
        origin_ = tmin;
        invWidth_ = span > 0 ? static_cast<double>(m) / (kPerBucket * span) : 1.0;
        for (std::uint32_t i = 0; i < time_.size(); ++i) place(i, time_[i]);
    }

    std::vector<double> time_;
    // Filled and rebuilt lazily by the const queries (top, topTime).
    mutable std::vector<Entry> heap_;
    mutable std::vector<std::uint32_t> ring_;  // first chunk of each bucket's list
    mutable std::vector<std::uint32_t> pool_;  // the chunks
    mutable std::vector<std::uint32_t> overflow_;
    mutable double origin_ = 0, invWidth_ = 1;
    mutable std::uint64_t cur_ = 0, mask_ = 1;
    mutable std::uint32_t free_ = kNil;
    mutable std::size_t inRing_ = 0;
    mutable bool dirty_ = true;
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
