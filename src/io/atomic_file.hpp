// Atomic file replacement: write a temporary file beside the target, flush it to disk, rename.
// A reader (or a run killed mid-write) sees either the old file or the complete new one.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

namespace kairos {

// Calls `write(tmp_path)` to produce the new content, then renames it over `target`.
// Throws InputError naming the file if anything fails; the old target is left untouched.
void replace_file_atomically(const std::filesystem::path& target,
                             const std::function<void(const std::filesystem::path&)>& write);

void write_text_atomically(const std::filesystem::path& target, std::string_view text);

// fsync of a file or a directory (its entries: renames in it); InputError naming it if the
// disk reports an error (a file system that cannot sync that kind of file is not one).
void sync_to_disk(const std::filesystem::path& path);

}  // namespace kairos
