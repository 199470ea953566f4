// A small persistent pool of worker threads for draws (docs/device.md "Threads"): run(n, f)
// calls f(worker) on n workers (the calling thread is worker 0) and returns when all are done.
// Work is split by the caller (e.g. bands of rows taken from an atomic counter), so results
// never depend on the number of threads.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
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

    int size() const { return m_size; }
    // Runs f(0) … f(min(n, size()) − 1) in parallel; f(0) on the calling thread. Not reentrant.
    void run(int n, const std::function<void(int)>& f);

private:
    void workerLoop(int index);

    int m_size = 1;
    std::vector<std::thread> m_threads;
    std::mutex m_mutex;
    std::condition_variable m_start, m_done;
    const std::function<void(int)>* m_job = nullptr;
    int m_jobWorkers = 0;
    uint64_t m_generation = 0;
    int m_pending = 0;
    bool m_stop = false;
};

}  // namespace emu
