// The boundary table's refinement off the callbacks: a worker thread that computes the exact cycle family at a
// conicity (the core's hm_table_refine) while the node keeps monitoring with the table it has. Plumbing only: the
// monitor (the core) decides where a family is wanted and takes the result.
#ifndef HUNTING_MONITOR_TABLE_REFINER_H
#define HUNTING_MONITOR_TABLE_REFINER_H

#include <condition_variable>
#include <mutex>
#include <thread>

extern "C" {
#include "hunting_monitor/model.h"
#include "hunting_monitor/tables.h"
}

namespace hunting_monitor {

class TableRefiner {
 public:
  explicit TableRefiner(const hm_vehicle& vehicle);
  ~TableRefiner();  // stops the worker (after the family it is computing) and frees an untaken result

  // Starts computing table + the family at conicity unless a computation is under way or its result has not been
  // taken. The table is only read, and must stay alive (unreplaced) until take() has returned the result.
  bool request(hm_table table, double conicity);
  // True from request() until take() returns the result.
  bool busy() const;
  // Hands a table over to be destroyed on the worker's thread (its memory came from there: freeing it on a callback
  // would contend with the worker for the allocator). Never waits; destroyed here if the lock is busy.
  void retire(hm_table table);
  // The finished table (owned by the caller from now on) or nullptr: never waits (a worker holding the lock for a
  // moment means "not yet"). On a finished failure returns nullptr with *failed true and the status in *status.
  hm_table take(bool* failed, hm_status* status, double* conicity, double* seconds);

 private:
  void run();

  hm_vehicle vehicle_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread worker_;
  bool stop_ = false, busy_ = false, work_ = false, done_ = false;
  hm_table input_ = nullptr, result_ = nullptr, retired_ = nullptr;
  double conicity_ = 0.0, seconds_ = 0.0;
  hm_status status_ = HM_OK;
};

}  // namespace hunting_monitor

#endif
