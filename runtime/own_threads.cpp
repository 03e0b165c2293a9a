#include "runtime/own_threads.h"

#include <exception>
#include <future>
#include <vector>

namespace dpc {

void onOwnThreads(size_t n, const std::function<void(size_t)>& f) {
  std::vector<std::future<void>> jobs;
  for (size_t i = 1; i < n; ++i) jobs.push_back(std::async(std::launch::async, f, i));
  std::exception_ptr error;
  try {
    if (n > 0) f(0);
  } catch (...) {
    error = std::current_exception();
  }
  for (std::future<void>& job : jobs) try {
      job.get();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  if (error) std::rethrow_exception(error);
}

}  // namespace dpc
