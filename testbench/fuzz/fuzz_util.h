// Helpers shared by the libFuzzer targets (testbench/fuzz/fuzz_*.cpp).
//
// A target's LLVMFuzzerTestOneInput returns 0 for every input the code under test handles: a
// result, or a rejection through the exception type its header documents. Everything else is
// a finding: a crash or sanitizer report, an exception of another type (it escapes the target:
// libFuzzer aborts on it, replay_main.cpp reports it), a hang (-timeout), a leak, or a broken
// property, which the target reports through finding() (an abort, so that libFuzzer saves the
// input as crash-<sha1>).
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <system_error>

#include <unistd.h>

namespace shd::fuzz {

// A scratch directory of this process, in RAM (/dev/shm) where there is one: readers that take
// only a path read the input from a file in it. Removed at a normal exit; a crashed run leaves
// its directory (shd-fuzz-<random>) behind.
inline std::string makeScratchDir() {
  std::error_code ec;
  std::filesystem::path base = "/dev/shm";
  if (!std::filesystem::is_directory(base, ec)) base = std::filesystem::temp_directory_path();
  std::string templ = (base / "shd-fuzz-XXXXXX").string();
  if (mkdtemp(templ.data()) == nullptr) {
    std::perror("fuzz: mkdtemp");
    std::abort();
  }
  return templ;
}

inline void removeScratchDir();

inline const std::string& scratchDir() {
  static const std::string dir = makeScratchDir();
  // Registered after dir is constructed, so it runs before dir is destroyed.
  static const bool registered = std::atexit(removeScratchDir) == 0;
  (void)registered;
  return dir;
}

inline void removeScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(scratchDir(), ignored);
}

// Writes the input to <scratchDir>/<name> (replacing the previous input) and returns the path.
inline std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratchDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// A property of the code under test does not hold for this input: says which, and aborts.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "FUZZ FINDING: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// A bug found by fuzzing, reported and not yet fixed (docs/verification.md, "Fuzzing"; its
// reproducer is a corpus file): a finding, except with SHD_FUZZ_SKIP_KNOWN=1 in the environment
// (scripts/fuzz.sh sets it for the fuzzing, not for the corpus merge), where it is a rejection,
// said once per process, so that a long run goes on to look for other bugs. Delete the call
// with the bug's fix.
inline void knownFinding(const char* id, const std::string& what) {
  static const bool skip = [] {
    const char* v = std::getenv("SHD_FUZZ_SKIP_KNOWN");
    return v != nullptr && v[0] == '1';
  }();
  if (!skip) finding(std::string("known finding ") + id + ": " + what);
  static std::set<std::string> said;
  if (said.insert(id).second) std::fprintf(stderr, "known finding %s skipped: %s\n", id, what.c_str());
}

// A clean rejection: nothing to do, except with SHD_FUZZ_VERBOSE=1 in the environment, which
// prints the reader's message (to see why a corpus file is refused: fuzz_<name> FILE).
inline void rejected(const std::exception& e) {
  static const bool verbose = [] {
    const char* v = std::getenv("SHD_FUZZ_VERBOSE");
    return v != nullptr && v[0] == '1';
  }();
  if (verbose) std::fprintf(stderr, "rejected: %s\n", e.what());
}

// Reads the input as little-endian fields, front to back; past the end every field reads 0, so
// that every input decodes (libFuzzer's mutations then never fall off a length check).
class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  uint8_t u8() { return p_ < end_ ? *p_++ : 0; }
  uint16_t u16() { return static_cast<uint16_t>(u8() | (u8() << 8)); }
  uint32_t u32() { return static_cast<uint32_t>(u16()) | (static_cast<uint32_t>(u16()) << 16); }
  uint64_t u64() { return static_cast<uint64_t>(u32()) | (static_cast<uint64_t>(u32()) << 32); }
  bool empty() const { return p_ >= end_; }
  size_t left() const { return static_cast<size_t>(end_ - p_); }
  const uint8_t* pos() const { return p_; }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

}  // namespace shd::fuzz

// The libFuzzer entry point every target defines.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
