#include "table_refiner.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>

namespace hunting_monitor {

TableRefiner::TableRefiner(const hm_vehicle& vehicle) : vehicle_(vehicle) {
  worker_ = std::thread(&TableRefiner::run, this);  // every member is initialised by now
}

TableRefiner::~TableRefiner() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  worker_.join();
  hm_table_destroy(result_);
  hm_table_destroy(retired_);
}

bool TableRefiner::request(hm_table table, double conicity) {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || busy_) return false;
  input_ = table;
  conicity_ = conicity;
  busy_ = work_ = true;
  done_ = false;
  lock.unlock();
  wake_.notify_one();
  return true;
}

bool TableRefiner::busy() const {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  return !lock.owns_lock() || busy_;
}

void TableRefiner::retire(hm_table table) {
  if (!table) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || retired_) {
    if (lock.owns_lock()) lock.unlock();
    hm_table_destroy(table);
    return;
  }
  retired_ = table;
  work_ = true;
  lock.unlock();
  wake_.notify_one();
}

hm_table TableRefiner::take(bool* failed, hm_status* status, double* conicity, double* seconds) {
  *failed = false;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || !done_) return nullptr;
  done_ = busy_ = false;
  hm_table out = result_;
  result_ = nullptr;
  *failed = out == nullptr;
  *status = status_;
  *conicity = conicity_;
  *seconds = seconds_;
  return out;
}

void TableRefiner::run() {
  // only on otherwise idle processor time (SCHED_IDLE): a waking callback preempts it at once, so the monitoring never
  // waits for it (best effort: the lowest nice value if the policy is refused)
  const sched_param idle{0};
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0)
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || work_; });
    if (stop_) return;
    work_ = false;
    if (retired_) {
      hm_table old = retired_;
      retired_ = nullptr;
      lock.unlock();
      hm_table_destroy(old);
      lock.lock();
    }
    if (!busy_ || done_) continue;  // only a table to retire
    const hm_table input = input_;
    const double conicity = conicity_;
    lock.unlock();  // the computation runs without the lock: the callbacks only ever try it
    const auto t0 = std::chrono::steady_clock::now();
    hm_table out = nullptr;
    const hm_status st = hm_table_refine(input, &vehicle_, conicity, &out);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    lock.lock();
    result_ = st == HM_OK ? out : nullptr;
    status_ = st;
    seconds_ = secs;
    done_ = true;
  }
}

}  // namespace hunting_monitor
