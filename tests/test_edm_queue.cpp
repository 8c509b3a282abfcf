// The event queues (tournament tree, heap with handles) against their reference twin, the linear scan.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.hpp"
#include "edm/event_queue.hpp"

namespace haet {
namespace {

template <class Q>
void compareWithScan(std::size_t n, std::uint64_t seed) {
    Q q;
    EventScan ref;
    q.reset(n);
    ref.reset(n);
    EXPECT_EQ(q.top(), ref.top());  // all infinite: slot 0
    Rng rng(seed, 5000);
    double now = 0;
    for (int step = 0; step < 20000; ++step) {
        const std::uint32_t i = q.top();
        ASSERT_EQ(i, ref.top()) << "step " << step;
        ASSERT_EQ(q.topTime(), ref.topTime());
        now = std::isinf(q.topTime()) ? now : q.topTime();
        // the popped slot and a random partner get new times; some ties on purpose (coarse times)
        auto newTime = [&]() {
            const double r = rng.uniform();
            if (r < 0.05) return std::numeric_limits<double>::infinity();
            return now + std::floor(rng.uniform(0, 50)) * 0.125;
        };
        const double ti = newTime();
        q.update(i, ti);
        ref.update(i, ti);
        const auto j = static_cast<std::uint32_t>(rng.bits() % n);
        const double tj = newTime();
        q.update(j, tj);
        ref.update(j, tj);
        // a decrease to "now" (collide immediately) now and then
        if (step % 7 == 0) {
            const auto k = static_cast<std::uint32_t>(rng.bits() % n);
            q.update(k, now);
            ref.update(k, now);
        }
    }
}

TEST(EdmQueue, TreeMatchesScan) {
    for (std::size_t n : {1u, 2u, 3u, 7u, 64u, 100u, 1000u}) compareWithScan<EventTree>(n, n);
}

TEST(EdmQueue, CalendarMatchesScan) {
    for (std::size_t n : {1u, 2u, 3u, 7u, 64u, 100u, 1000u, 5000u}) compareWithScan<EventCalendar>(n, n + 2);
}

TEST(EdmQueue, HeapMatchesScan) {
    for (std::size_t n : {1u, 2u, 3u, 7u, 64u, 100u, 1000u}) compareWithScan<EventHeap>(n, n + 1);
}

}  // namespace
}  // namespace haet
