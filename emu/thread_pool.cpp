// The draw worker pool: threads started once per device, woken per draw.
#include "emu/thread_pool.h"

#include <algorithm>

namespace emu {

ThreadPool::ThreadPool(int threads) {
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    m_size = std::clamp(threads, 1, 64);
    for (int i = 1; i < m_size; ++i) m_threads.emplace_back([this, i] { workerLoop(i); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_stop = true;
    }
    m_start.notify_all();
    for (std::thread& t : m_threads) t.join();
}

void ThreadPool::run(int n, const std::function<void(int)>& f) {
    n = std::clamp(n, 1, m_size);
    if (n == 1) {
        f(0);
        return;
    }
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_job = &f;
        m_jobWorkers = n;
        m_pending = n - 1;
        ++m_generation;
    }
    m_start.notify_all();
    f(0);
    std::unique_lock<std::mutex> lock(m_mutex);
    m_done.wait(lock, [this] { return m_pending == 0; });
    m_job = nullptr;
}

void ThreadPool::workerLoop(int index) {
    uint64_t seen = 0;
    for (;;) {
        const std::function<void(int)>* job = nullptr;
        {
            std::unique_lock<std::mutex> lock(m_mutex);
            m_start.wait(lock, [&] { return m_stop || m_generation != seen; });
            if (m_stop) return;
            seen = m_generation;
            if (index >= m_jobWorkers) continue;
            job = m_job;
        }
        (*job)(index);
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            if (--m_pending == 0) m_done.notify_one();
        }
    }
}

}  // namespace emu
