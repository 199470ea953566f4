// A small persistent pool of worker threads for draws (docs/device.md "Threads"): run(n, f)
// calls f(worker) on n workers (the calling thread is worker 0) and returns when all are done.
// Work is split by the caller (e.g. bands of rows taken from a RangeQueue), so results
// never depend on the number of threads.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace emu {

class ThreadPool {
public:
    // `threads` workers in total including the caller; 0 = std::thread::hardware_concurrency().
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    // The pool of `threads` workers (0 = hardware_concurrency) that every caller asking for
    // that many shares in this process, alive while one holds it. The software devices draw on
    // it: a process with several devices (the benchmark runs eighteen) has one set of workers
    // instead of one per device. With a pool per device, now and then one device drew every
    // frame of a benchmark 1.5 times as long, as if on one core (bench/README.md "One runner
    // drawing on one core").
    static std::shared_ptr<ThreadPool> shared(int threads);

    int size() const { return m_size; }
    // Runs f(0) … f(min(n, size()) − 1) in parallel; f(0) on the calling thread. While the pool
    // runs another call (from another thread, or from inside a job), this one calls them all on
    // the calling thread, one after the other.
    void run(int n, const std::function<void(int)>& f);

    // How long a worker that finished a job, and the caller waiting for its workers, poll before
    // they sleep on the condition variable: a frame's draws follow each other within
    // microseconds, and waking a sleeping thread costs tens of them (a pass of a few thousand
    // pixels took twice as long on two threads as on one).
    static constexpr std::chrono::microseconds kSpin{200};

private:
    void workerLoop(int index);

    int m_size = 1;
    std::vector<std::thread> m_threads;
    std::mutex m_mutex;
    std::condition_variable m_start, m_done;
    const std::function<void(int)>* m_job = nullptr;
    int m_jobWorkers = 0;
    // Written under m_mutex; read without it only by the polls (which then take the mutex).
    std::atomic<uint64_t> m_generation{0};
    std::atomic<int> m_pending{0};
    std::atomic<bool> m_stop{false};
    std::atomic<bool> m_busy{false};  // a run() is using the workers
};

// Items [0, count) in one contiguous range per worker: worker w takes its own range's items in
// order from the front and, once that is empty, the others' from their back. Every item is
// taken exactly once, whatever the timing, and a worker's items are mostly consecutive: what it
// built for one (a band of a draw's rows: the H rows of the texel rows its last pixel rows read)
// serves the next.
class RangeQueue {
public:
    RangeQueue(int count, int workers);
    // The next item for `worker` (in [0, workers)), or −1 when every item is taken.
    int take(int worker);

private:
    std::vector<std::atomic<uint64_t>> m_ranges;  // per worker: (front << 32) | back, items left [front, back)
};

// `bytes` from `from` to `to` (not overlapping), each of the pool's workers copying its share (in
// whole 64-byte lines but the last): the host's memory speed as the renderer's threads see it
// (Runner::copySpeed, bench_glare's copy_gbps).
void parallelCopy(ThreadPool& pool, void* to, const void* from, size_t bytes);

}  // namespace emu
