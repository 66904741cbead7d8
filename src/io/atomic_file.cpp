#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/error.hpp"

namespace kairos {

void sync_to_disk(const std::filesystem::path& p) {
  std::error_code ec;
  const bool directory = std::filesystem::is_directory(p, ec);
  const int fd = ::open(p.c_str(), directory ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) {
    throw InputError("cannot open '" + p.string() + "' to sync it: " + std::strerror(errno));
  }
  const int status = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  // EINVAL: a file system that cannot sync this kind of file (some do not sync directories).
  if (status != 0 && error != EINVAL) {
    throw InputError("cannot sync '" + p.string() + "' to disk: " + std::strerror(error));
  }
}

void replace_file_atomically(const std::filesystem::path& target,
                             const std::function<void(const std::filesystem::path&)>& write) {
  std::filesystem::path tmp = target;
  tmp += ".tmp";
  try {
    write(tmp);
    sync_to_disk(tmp);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::error_code ignored;  // the rename's error is the one to report
    std::filesystem::remove(tmp, ignored);
    throw InputError("cannot replace '" + target.string() + "': " + ec.message());
  }
  const auto dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  sync_to_disk(dir);
}

void write_text_atomically(const std::filesystem::path& target, std::string_view text) {
  replace_file_atomically(target, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      throw InputError("cannot write '" + tmp.string() + "': " + std::strerror(errno));
    }
  });
}

}  // namespace kairos
