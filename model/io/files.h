// The output policy of both programs (shadesim, shadesim_systemc): every file they write goes
// through here.
//
// - Atomic: a file is written to a temporary beside it, flushed to disk and renamed over the
//   target, so a reader sees the old file or the whole new one.
// - Several files of one run are an OutputFiles set: every target is checked and every
//   temporary written before the first rename, so a run that fails writes none of them.
// - Regular files only: an existing target that is a FIFO, a device, a socket or a directory is
//   refused (renaming a file over /dev/null would replace the device node). A symbolic link is
//   followed: the file it names is replaced and the link stays.
// - Never an input: a target that is the same file (device and inode) as a file the run has read
//   (noteInput) is refused, so `-o` naming an input cannot destroy it.
// Errors are std::runtime_error naming the path and what is wrong.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace shd {

// A run of a program (one subcommand): while one exists, noteInput records the files read, and
// outputs may not replace them; its end forgets them. Without a run (a library user, a test
// that writes a file it read before) nothing is recorded.
class RunInputs {
 public:
  RunInputs();
  ~RunInputs();
  RunInputs(const RunInputs&) = delete;
  RunInputs& operator=(const RunInputs&) = delete;
};

// Records that the run reads `path` (a file that exists); every reader of an input file calls
// it. Thread-safe.
void noteInput(const std::string& path);

// Why `path` cannot be an input file: "" if it is a readable regular file of at most max_bytes,
// else the reason ("no such file", "it is a FIFO; ...", "<n> bytes, more than ..."). Every
// reader calls it before opening a file, so that a FIFO does not block and /dev/zero does not
// fill the memory.
std::string inputFileProblem(const std::string& path, uint64_t max_bytes);

// The whole of a small input file, by the rules above (inputFileProblem, noteInput).
// std::runtime_error "<path>: <why>" when it cannot be read.
std::string readInputFile(const std::string& path, uint64_t max_bytes);

// The path an output to `path` replaces: `path` itself, or the file a symbolic link names
// (relative links resolved against the link's directory, chains followed). Throws when the
// target exists and is not a regular file, is a noted input, or is new in a directory that does
// not exist. Writers that are not atomic (the FST waveforms) call it before they start.
std::string outputTarget(const std::string& path);

// One file, atomically, by the policy above.
void writeFileAtomic(const std::string& path, const std::string& content);

// The files of one run, written together: add() them, then commit().
class OutputFiles {
 public:
  void add(std::string path, std::string content) { files_.emplace_back(std::move(path), std::move(content)); }
  // Checks every target, writes every temporary, then renames them in order of add(). On a
  // failure before the renames no target is touched and no temporary is left.
  void commit();

 private:
  std::vector<std::pair<std::string, std::string>> files_;
};

}  // namespace shd
