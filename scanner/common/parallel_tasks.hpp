#pragma once

#include <omp.h>

#include <cstddef>
#include <exception>

namespace uwscan {

// Runs task(i) for every i in [0, count) on `threads` OpenMP threads (0: OpenMP's default), each
// index to whichever thread is free next. An exception a task throws is rethrown here once every
// task has run (the first one caught; thrown out of an OpenMP region it would end the program).
// The tasks must write only their own results: which thread runs which is not fixed.
template <typename Task>
void RunParallelTasks(std::ptrdiff_t count, int threads, const Task& task) {
  std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 1) \
    num_threads(threads > 0 ? threads : omp_get_max_threads())
  for (std::ptrdiff_t i = 0; i < count; ++i) {
    try {
      task(i);
    } catch (...) {
#pragma omp critical(uwscan_parallel_tasks_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace uwscan
