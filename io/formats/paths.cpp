#include "io/formats/paths.hpp"

#include <cerrno>
#include <climits>
#include <cstring>

#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "io/formats/error.hpp"

namespace vrelab::io {
namespace {

// Why stat(2) cannot describe `path` (its errno in words), "" when it can; *missing when
// nothing is there (a writer may create it).
std::string stat_problem(const std::string& path, struct stat* st, bool* missing) {
  *missing = false;
  if (path.empty()) return "an empty path";
  if (const std::size_t nul = path.find('\0'); nul != std::string::npos)
    return fmt::format("the path holds a NUL byte (at byte {}), which no file name can", nul + 1);
  if (::stat(path.c_str(), st) == 0) return "";
  switch (errno) {
    case ENOENT: *missing = true; return "no such file";
    case ENOTDIR: return "a part of the path before the last '/' is not a folder";
    case ELOOP: return "a loop of symbolic links (too many levels of links to follow)";
    case ENAMETOOLONG:
      return fmt::format("the path is longer than the system allows ({} bytes; at most {} bytes a name and {} in all)",
                         path.size(), NAME_MAX, PATH_MAX);
    case EACCES: return "permission denied (a folder on the way cannot be searched)";
    default: return std::strerror(errno);
  }
}

// Why a file of this type is not read or written as a regular file, "" for a regular file.
std::string type_problem(mode_t mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISDIR(mode)) return "is a directory, not a file";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe), not a regular file (vrelab reads and writes regular files only: a pipe may never end)";
  if (S_ISCHR(mode) || S_ISBLK(mode))
    return "a device, not a regular file (vrelab reads and writes regular files only: a device such as /dev/zero never ends)";
  if (S_ISSOCK(mode)) return "a socket, not a regular file";
  return "not a regular file";
}

}  // namespace

std::string path_for_message(const std::string& path) {
  std::string shown;
  for (char ch : path) shown += ch == '\0' ? std::string("\\0") : std::string(1, ch);
  if (shown.size() <= 160) return shown;
  return fmt::format("{}...[{} bytes]...{}", shown.substr(0, 60), path.size(), shown.substr(shown.size() - 60));
}

std::string readable_file_problem(const std::string& path) {
  struct stat st {};
  bool missing = false;
  if (std::string why = stat_problem(path, &st, &missing); !why.empty()) return why;
  if (std::string why = type_problem(st.st_mode); !why.empty()) return why;
  if (::access(path.c_str(), R_OK) != 0) return "permission denied";
  return "";
}

std::string writable_file_problem(const std::string& path) {
  struct stat st {};
  bool missing = false;
  std::string why = stat_problem(path, &st, &missing);
  if (missing) return "";
  if (!why.empty()) return why;
  return type_problem(st.st_mode);
}

void require_readable_file(const std::string& path, const std::string& what) {
  if (const std::string why = readable_file_problem(path); !why.empty())
    throw FormatError({.file = path_for_message(path)}, fmt::format("cannot open {}: {}", what, why));
}

void require_writable_file(const std::string& path, const std::string& what) {
  if (const std::string why = writable_file_problem(path); !why.empty())
    throw FormatError({.file = path_for_message(path)}, fmt::format("cannot write {}: {}", what, why));
}

}  // namespace vrelab::io
