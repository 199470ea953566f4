// emu::ThreadPool: every worker index runs once per call, however the pool is shared, called
// from several threads at once or from inside one of its own jobs; parallelCopy.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "emu/thread_pool.h"

TEST_CASE("thread pool: one pool per worker count in a process, alive while held", "[threads]") {
    std::shared_ptr<emu::ThreadPool> a = emu::ThreadPool::shared(3), b = emu::ThreadPool::shared(3),
                                     c = emu::ThreadPool::shared(2);
    CHECK(a == b);
    CHECK(a != c);
    CHECK(a->size() == 3);
    CHECK(c->size() == 2);
    std::weak_ptr<emu::ThreadPool> gone = c;
    c.reset();
    CHECK(gone.expired());  // nobody held it: its threads stopped
    CHECK(emu::ThreadPool::shared(0)->size() == int(std::max(1u, std::thread::hardware_concurrency())));
}

TEST_CASE("thread pool: each index runs once, from several threads at once and from inside a job", "[threads]") {
    std::shared_ptr<emu::ThreadPool> pool = emu::ThreadPool::shared(4);
    constexpr int kCalls = 300;
    // Four threads call run() on the one pool at the same time; each counts its indices.
    std::vector<std::thread> callers;
    std::vector<std::vector<int>> counts(4, std::vector<int>(4 * kCalls, 0));
    for (int t = 0; t < 4; ++t)
        callers.emplace_back([&, t] {
            for (int k = 0; k < kCalls; ++k) {
                std::atomic<int> seen[4] = {};
                pool->run(4, [&](int w) { seen[w].fetch_add(1); });
                for (int w = 0; w < 4; ++w) counts[size_t(t)][size_t(4 * k + w)] = seen[w].load();
            }
        });
    for (std::thread& t : callers) t.join();
    for (const std::vector<int>& c : counts)
        for (int n : c) CHECK(n == 1);
    // A job that runs the pool again: the inner call runs its indices on the job's thread.
    std::atomic<int> inner{0}, outer{0};
    pool->run(3, [&](int) {
        outer.fetch_add(1);
        pool->run(4, [&](int) { inner.fetch_add(1); });
    });
    CHECK(outer == 3);
    CHECK(inner == 12);
}

TEST_CASE("thread pool: parallelCopy copies every byte and nothing past them, on any thread count", "[threads]") {
    // Sizes around the 64-byte lines the shares are cut at, and sizes smaller than one share each.
    for (int threads : {1, 2, 3, 7})
        for (size_t bytes : {size_t(0), size_t(1), size_t(63), size_t(64), size_t(65), size_t(200), size_t(4097),
                             size_t(1) << 20}) {
            INFO(threads << " threads, " << bytes << " bytes");
            std::shared_ptr<emu::ThreadPool> pool = emu::ThreadPool::shared(threads);
            std::vector<uint8_t> from(bytes), to(bytes + 64, 0xee);
            for (size_t i = 0; i < bytes; ++i) from[i] = uint8_t(i * 131 + i / 251);
            emu::parallelCopy(*pool, to.data(), from.data(), bytes);
            CHECK(std::equal(from.begin(), from.end(), to.begin()));
            CHECK(std::all_of(to.begin() + std::ptrdiff_t(bytes), to.end(), [](uint8_t b) { return b == 0xee; }));
        }
}

TEST_CASE("range queue: each item once, a worker's own range in order, then the others' from their back",
          "[threads]") {
    // One caller taking for worker 1 of 3 over 10 items (ranges [0,3) [3,6) [6,10)): its own
    // items in order, then worker 2's from the back, then worker 0's.
    {
        emu::RangeQueue q(10, 3);
        std::vector<int> order;
        for (int b; (b = q.take(1)) >= 0;) order.push_back(b);
        CHECK(order == std::vector<int>{3, 4, 5, 9, 8, 7, 6, 2, 1, 0});
    }
    // Owners and a thief interleaved: nothing twice, nothing left out.
    {
        emu::RangeQueue q(7, 2);  // [0,3) [3,7)
        CHECK(q.take(0) == 0);
        CHECK(q.take(1) == 3);
        CHECK(q.take(0) == 1);
        CHECK(q.take(0) == 2);
        CHECK(q.take(0) == 6);  // worker 0's range is empty: worker 1's last item
        CHECK(q.take(1) == 4);
        CHECK(q.take(0) == 5);
        CHECK(q.take(1) == -1);
        CHECK(q.take(0) == -1);
    }
    // No items, and more workers than items.
    CHECK(emu::RangeQueue(0, 2).take(0) == -1);
    {
        emu::RangeQueue q(2, 5);
        std::vector<int> got;
        for (int w = 0; w < 5; ++w)
            for (int b; (b = q.take(w)) >= 0;) got.push_back(b);
        std::sort(got.begin(), got.end());
        CHECK(got == std::vector<int>{0, 1});
    }
    // Four threads racing over many items, uneven work: every item exactly once.
    for (int round = 0; round < 20; ++round) {
        constexpr int kItems = 5000;
        emu::RangeQueue q(kItems, 4);
        std::vector<std::atomic<int>> seen(kItems);
        std::vector<std::thread> workers;
        for (int w = 0; w < 4; ++w)
            workers.emplace_back([&, w] {
                for (int b; (b = q.take(w)) >= 0;) {
                    seen[size_t(b)].fetch_add(1);
                    if (w == 0 && b % 7 == 0) std::this_thread::yield();  // a slow worker: the others take its items
                }
            });
        for (std::thread& t : workers) t.join();
        int wrong = 0;
        for (const std::atomic<int>& s : seen) wrong += s.load() != 1;
        CHECK(wrong == 0);
    }
}
