#include "io/line_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"

namespace kairos {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what, int error) {
  throw InputError(
      fmt::format("cannot write '{}': {}: {}", path.string(), what, std::strerror(error)));
}

// The byte offset just past the first `lines` newlines of the file (and how many it found).
std::pair<std::uint64_t, std::uint64_t> offset_after_lines(int fd, std::uint64_t lines) {
  std::vector<char> buffer(1 << 16);
  std::uint64_t offset = 0, found = 0, end = 0;
  for (;;) {
    const ssize_t got = ::pread(fd, buffer.data(), buffer.size(), static_cast<off_t>(offset));
    if (got <= 0) break;
    for (ssize_t k = 0; k < got; ++k) {
      if (buffer[static_cast<std::size_t>(k)] != '\n') continue;
      ++found;
      end = offset + static_cast<std::uint64_t>(k) + 1;
      if (found == lines) return {end, found};
    }
    offset += static_cast<std::uint64_t>(got);
  }
  return {end, found};  // fewer lines: up to the last complete one
}

}  // namespace

LineFile::LineFile(const std::filesystem::path& path, const std::string& header,
                   std::optional<std::uint64_t> keep_rows)
    : path_(path) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) fail(path, "cannot open", errno);
  struct stat st {};
  if (::fstat(fd_, &st) != 0) fail(path, "cannot stat", errno);
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw InputError("cannot write '" + path.string() + "': not a regular file");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  if (size_ == 0) {
    write_all(header);
    return;
  }
  // Whole lines only: the header plus keep_rows rows, or every complete line.
  const std::uint64_t wanted = keep_rows ? *keep_rows + 1 : ~std::uint64_t{0};
  const auto [end, lines] = offset_after_lines(fd_, wanted);
  if (end != size_) {
    if (::ftruncate(fd_, static_cast<off_t>(end)) != 0) fail(path, "cannot truncate", errno);
    size_ = end;
  }
  rows_ = lines > 0 ? lines - 1 : 0;
  if (size_ == 0) write_all(header);
}

LineFile LineFile::create(const std::filesystem::path& path, const std::string& header) {
  {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) fail(path, "cannot create", errno);
    ::close(fd);
  }
  return LineFile(path, header);
}

LineFile::LineFile(LineFile&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      size_(other.size_),
      rows_(other.rows_) {}

LineFile& LineFile::operator=(LineFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    size_ = other.size_;
    rows_ = other.rows_;
  }
  return *this;
}

LineFile::~LineFile() {
  if (fd_ >= 0) ::close(fd_);
}

void LineFile::append(std::string_view line) {
  write_all(line);
  ++rows_;
}

void LineFile::write_all(std::string_view text) {
  std::uint64_t done = 0;
  while (done < text.size()) {
    const ssize_t n =
        ::pwrite(fd_, text.data() + done, text.size() - done, static_cast<off_t>(size_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      // Cut back to the last whole line: no reader may see a torn one.
      if (::ftruncate(fd_, static_cast<off_t>(size_)) != 0) {
        // The file keeps a partial line beyond size_; a continued run drops it (keep_rows).
      }
      fail(path_, "the line could not be written", error);
    }
    done += static_cast<std::uint64_t>(n);
  }
  size_ += done;
}

void LineFile::sync() {
  if (::fsync(fd_) == 0) return;
  const int error = errno;
  if (error != EINVAL) {
    throw InputError(
        fmt::format("{}: cannot sync to disk: {}", path_.string(), std::strerror(error)));
  }
}

}  // namespace kairos
