// An append-only text file of whole lines (thermo.tsv): every line reaches the file completely
// or not at all, and every write is checked.
//
// A line is written with one write loop; if any part fails (a full disk, a file size limit,
// an I/O error) the file is cut back to its size before the line and InputError names the file
// and the reason, so a reader never sees a torn row. Each line is flushed to the kernel at once
// (an interrupted or killed run keeps every row written before).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace kairos {

class LineFile {
 public:
  // Opens `path` for appending, creating it when missing. A new or empty file gets `header`
  // (one line, with its newline) first. `keep_rows`: a run continued into this file keeps
  // only that many data lines after the header (those it had written up to the state it
  // continues from) and drops the rest, a torn last line included; if the file holds fewer,
  // `rows()` says how many.
  LineFile(const std::filesystem::path& path, const std::string& header,
           std::optional<std::uint64_t> keep_rows = std::nullopt);
  // Truncates or creates `path` and writes the header.
  static LineFile create(const std::filesystem::path& path, const std::string& header);
  LineFile(LineFile&& other) noexcept;
  LineFile& operator=(LineFile&& other) noexcept;
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;
  ~LineFile();

  // Appends one line (with its newline); InputError, the file unchanged, if it cannot.
  void append(std::string_view line);
  // Flushes the file to disk (fsync): what a checkpoint that counts its rows relies on.
  // InputError naming the file if the disk reports an error.
  void sync();
  // Data lines in the file (after the header).
  std::uint64_t rows() const { return rows_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  LineFile() = default;
  void write_all(std::string_view text);
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;  // bytes in the file
  std::uint64_t rows_ = 0;
};

}  // namespace kairos
