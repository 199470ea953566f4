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
