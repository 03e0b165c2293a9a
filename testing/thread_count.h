// The threads of this process, counted outside the code under test (Linux: /proc/self/task),
// for the tests that check that dpc leaves no thread behind.
#pragma once

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace dpc::test {

inline int threadCount() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry :
       std::filesystem::directory_iterator("/proc/self/task"))
    ++n;
  return n;
}

/// The names (/proc/self/task/N/comm) of this process's threads, comma-separated: what a
/// failing count prints, so a thread left behind says whose it is.
inline std::string threadNames() {
  std::string names;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(entry.path() / "comm");
    std::string name;
    std::getline(comm, name);
    names += (names.empty() ? "" : ", ") + name;
  }
  return names;
}

/// The thread count once it has come down to `expected`, or after 10 s: a joined thread's
/// entry may outlive pthread_join by a moment (the kernel releases it after waking the joiner).
inline int threadCountSettled(int expected) {
  int n = threadCount();
  for (int i = 0; i < 1000 && n != expected; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    n = threadCount();
  }
  return n;
}

}  // namespace dpc::test
