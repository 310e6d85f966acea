// InputFile: every file volref reads is checked here before it is opened (docs/robustness.md,
// "Special files"). It must exist and, after symbolic links, be a regular file: a FIFO, a character or
// block device, a socket or a directory is refused by its type, because reading one can block forever
// (a FIFO without a writer), never end (/dev/zero) or mean nothing (a directory). A file read whole is
// also checked against the memory limit (core/MemoryLimit.h) before it is read.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

namespace volref::io {

// "" for a regular file; otherwise why it cannot be read: strerror ("No such file or directory"), "it is a
// directory", "it is a FIFO (volref reads regular files only)", ...
std::string input_file_problem(const std::filesystem::path& path);

// Throws Error "<where>: cannot read file: <problem>" unless `path` is a regular file; returns its size.
std::uint64_t check_input_file(const std::filesystem::path& path, const std::string& where);

// check_input_file, then the file's size against the memory limit (it is about to be read whole):
// Error "<where>: reading the file: needs N, more than the memory limit".
std::uint64_t check_whole_file(const std::filesystem::path& path, const std::string& where);

// The whole contents of the file at `path`, after check_whole_file; errors start with `where` (the path
// when empty).
std::string read_file_bytes(const std::filesystem::path& path, const std::string& where = "");

}  // namespace volref::io
