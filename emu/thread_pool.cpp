// The draw worker pool: threads started once per device, woken per draw.
#include "emu/thread_pool.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <map>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace emu {

namespace {

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#else
    std::this_thread::yield();
#endif
}

// Polls `done` until it holds or ThreadPool::kSpin has passed (the caller then waits under the
// mutex). Every 64 polls it yields the core: where more threads are runnable than there are cores
// (another device's workers, the GL renderer's), the thread polled for would otherwise wait behind
// the poll.
template <typename Done>
void spinUntil(Done done) {
    const auto until = std::chrono::steady_clock::now() + ThreadPool::kSpin;
    do {
        for (int i = 0; i < 64; ++i) {
            if (done()) return;
            relax();
        }
        std::this_thread::yield();
    } while (std::chrono::steady_clock::now() < until);
}

}  // namespace

ThreadPool::ThreadPool(int threads) {
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    m_size = std::clamp(threads, 1, 64);
    for (int i = 1; i < m_size; ++i) m_threads.emplace_back([this, i] { workerLoop(i); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_stop.store(true, std::memory_order_release);
    }
    m_start.notify_all();
    for (std::thread& t : m_threads) t.join();
}

std::shared_ptr<ThreadPool> ThreadPool::shared(int threads) {
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::clamp(threads, 1, 64);
    static std::mutex mutex;
    static std::map<int, std::weak_ptr<ThreadPool>> pools;
    std::lock_guard<std::mutex> lock(mutex);
    std::shared_ptr<ThreadPool> pool = pools[threads].lock();
    if (!pool) pools[threads] = pool = std::make_shared<ThreadPool>(threads);
    return pool;
}

void ThreadPool::run(int n, const std::function<void(int)>& f) {
    n = std::clamp(n, 1, m_size);
    if (n == 1) {
        f(0);
        return;
    }
    if (m_busy.exchange(true, std::memory_order_acquire)) {
        for (int w = 0; w < n; ++w) f(w);
        return;
    }
    struct Release {
        std::atomic<bool>& busy;
        ~Release() { busy.store(false, std::memory_order_release); }
    } release{m_busy};
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_job = &f;
        m_jobWorkers = n;
        m_pending.store(n - 1, std::memory_order_relaxed);
        m_generation.fetch_add(1, std::memory_order_release);
    }
    m_start.notify_all();
    f(0);
    spinUntil([this] { return m_pending.load(std::memory_order_acquire) == 0; });
    std::unique_lock<std::mutex> lock(m_mutex);
    m_done.wait(lock, [this] { return m_pending.load(std::memory_order_relaxed) == 0; });
    m_job = nullptr;
}

void ThreadPool::workerLoop(int index) {
    uint64_t seen = 0;
    for (;;) {
        const std::function<void(int)>* job = nullptr;
        spinUntil([&] {
            return m_stop.load(std::memory_order_acquire) ||
                   m_generation.load(std::memory_order_acquire) != seen;
        });
        {
            std::unique_lock<std::mutex> lock(m_mutex);
            m_start.wait(lock, [&] {
                return m_stop.load(std::memory_order_relaxed) || m_generation.load(std::memory_order_relaxed) != seen;
            });
            if (m_stop.load(std::memory_order_relaxed)) return;
            seen = m_generation.load(std::memory_order_relaxed);
            if (index >= m_jobWorkers) continue;
            job = m_job;
        }
        (*job)(index);
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            if (m_pending.fetch_sub(1, std::memory_order_acq_rel) == 1) m_done.notify_one();
        }
    }
}

RangeQueue::RangeQueue(int count, int workers) : m_ranges(size_t(std::max(workers, 1))) {
    const int64_t n = int64_t(m_ranges.size()), items = std::max(count, 0);
    for (int64_t w = 0; w < n; ++w) {
        const uint64_t front = uint64_t(items * w / n), back = uint64_t(items * (w + 1) / n);
        m_ranges[size_t(w)].store((front << 32) | back, std::memory_order_relaxed);
    }
}

int RangeQueue::take(int worker) {
    const size_t n = m_ranges.size();
    for (size_t k = 0; k < n; ++k) {
        const bool own = k == 0;
        std::atomic<uint64_t>& range = m_ranges[(size_t(std::max(worker, 0)) + k) % n];
        uint64_t v = range.load(std::memory_order_relaxed);
        for (;;) {
            const uint32_t front = uint32_t(v >> 32), back = uint32_t(v);
            if (front >= back) break;
            const uint64_t taken = own ? (uint64_t(front + 1) << 32) | back : (uint64_t(front) << 32) | (back - 1);
            // (Relaxed: the items' data is published by ThreadPool::run, which also joins their results.)
            if (range.compare_exchange_weak(v, taken, std::memory_order_relaxed)) return int(own ? front : back - 1);
        }
    }
    return -1;
}

void parallelCopy(ThreadPool& pool, void* to, const void* from, size_t bytes) {
    const int n = pool.size();
    pool.run(n, [&](int i) {
        const size_t a = bytes * size_t(i) / size_t(n) / 64 * 64;
        const size_t b = i + 1 == n ? bytes : bytes * size_t(i + 1) / size_t(n) / 64 * 64;
        if (b > a) std::memcpy(static_cast<uint8_t*>(to) + a, static_cast<const uint8_t*>(from) + a, b - a);
    });
}

}  // namespace emu
