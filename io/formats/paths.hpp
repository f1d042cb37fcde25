#pragma once
// io/formats/paths.hpp -- file arguments checked before anything opens them.
//
// Takes: a path a user gave (on the command line, in a data file, from Python) and what it
//        names ("the case file", "the PSD file", ...).
// Gives: FormatError (io/formats/error.hpp; exit code 2) naming the path and the reason when
//        a reader would be given anything but a regular file it can read -- a folder, a FIFO
//        or a device (whose reading may never end: /dev/zero), a socket, a loop of symbolic
//        links, a path longer than the system allows, a NUL byte inside the path (Python
//        strings may hold one; the system would read the path only up to it) -- or when a
//        writer would be given anything but a regular file or a new name. The check uses
//        stat(2), which follows symbolic links and opens nothing.
// Every reader of the library calls require_readable_file before it opens a file, and every
// writer require_writable_file, so each kind of path gets the same answer wherever it is given.
#include <string>

namespace vrelab::io {

// The path as a message shows it: a NUL byte written as \0 (a message is a C string: the
// text after a NUL would be lost), a path over 160 bytes shortened to its first and last 60
// bytes with the length between them.
std::string path_for_message(const std::string& path);

// "" when `path` names a regular file this process can read, else why not ("a folder, not a
// file", "no such file", "a FIFO (named pipe), not a regular file: ...").
std::string readable_file_problem(const std::string& path);
// "" when `path` names a regular file or nothing yet (a new file), else why not.
std::string writable_file_problem(const std::string& path);

// FormatError "<path>: cannot open <what>: <reason>" when readable_file_problem is not empty.
void require_readable_file(const std::string& path, const std::string& what);
// FormatError "<path>: cannot write <what>: <reason>" when writable_file_problem is not empty.
void require_writable_file(const std::string& path, const std::string& what);

}  // namespace vrelab::io
