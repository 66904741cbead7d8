// Helpers for tests that give a reader a FIFO, a directory or a device instead of a file.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <string>

#include "core/error.hpp"

namespace kairos::testing {

// Creates a FIFO at `path` (failing the test if it cannot).
inline void make_fifo(const std::filesystem::path& path) {
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0) << path;
}

// The message of the InputError that `read` throws when it is given the special file `path`.
// `read` runs in another thread: should it block (opening a FIFO for reading waits for a
// writer), the FIFO's writing end is opened and closed to release it, and the test fails
// instead of hanging. Fails the test, returning "", if `read` throws nothing or another type.
template <class Read>
std::string refusal_without_blocking(const std::filesystem::path& path, Read read) {
  auto result = std::async(std::launch::async, [&]() -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no InputError)";
  });
  if (result.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    ADD_FAILURE() << "reading " << path << " blocked";
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  const std::string message = result.get();
  EXPECT_NE(message, "(no InputError)") << path;
  return message == "(no InputError)" ? "" : message;
}

}  // namespace kairos::testing
