// The main of a fuzz target outside libFuzzer (the gcc builds, plain and SHD_SANITIZE): runs
// LLVMFuzzerTestOneInput once on every file named, and on every file of every directory
// named (sorted by name), so that ctest replays the checked-in corpus (testbench/fuzz/corpus/)
// in every build.
//   fuzz_<name> [FILE | DIR]...
// Exit 0 when every input ran; 1 when an exception escaped the target (the target catches the
// rejections its reader documents: any other is a finding), an input ran over 10 s (a hang, as
// libFuzzer's -timeout in scripts/fuzz.sh) or an argument cannot be read. A
// crash, an abort (a target's finding()) or a sanitizer report ends the process with the
// input's path on stderr.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include "fuzz_util.h"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#define SHD_FUZZ_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#include <sanitizer/common_interface_defs.h>
#define SHD_FUZZ_SANITIZER 1
#endif
#endif

namespace {

// The input running now, for the crash message (written by a signal handler: a fixed buffer).
char g_current[4096];

// "<what><the input running now>" on stderr, with write() alone (safe in a signal handler).
template <size_t N>
void sayWithCurrent(const char (&what)[N]) {
  ssize_t ignored = write(STDERR_FILENO, what, N - 1);
  ignored = write(STDERR_FILENO, g_current, strnlen(g_current, sizeof g_current));
  ignored = write(STDERR_FILENO, "\n", 1);
  (void)ignored;
}

void sayCurrent() { sayWithCurrent("fuzz replay: the process died on input "); }

void onSignal(int sig) {
  sayCurrent();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// An input that runs longer than scripts/fuzz.sh's libFuzzer -timeout is a hang: the process
// ends naming it (exit 1), instead of the test waiting for ctest's 1500 s.
constexpr unsigned kHangSeconds = 10;
void onHang(int) {
  sayWithCurrent("fuzz replay: a hang (over 10 s) on input ");
  _exit(1);
}

std::vector<std::string> inputsOf(const std::string& arg) {
  std::vector<std::string> files;
  if (std::filesystem::is_directory(arg)) {
    for (const auto& e : std::filesystem::directory_iterator(arg))
      if (e.is_regular_file()) files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
  } else {
    files.push_back(arg);
  }
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  for (int sig : {SIGSEGV, SIGABRT, SIGFPE, SIGILL, SIGBUS}) std::signal(sig, onSignal);
  std::signal(SIGALRM, onHang);
#ifdef SHD_FUZZ_SANITIZER
  __sanitizer_set_death_callback(sayCurrent);  // a sanitizer report exits without a signal
#endif
  size_t runs = 0;
  for (int i = 1; i < argc; ++i) {
    for (const std::string& path : inputsOf(argv[i])) {
      std::ifstream in(path, std::ios::binary);
      if (!in) {
        std::fprintf(stderr, "fuzz replay: cannot read %s\n", path.c_str());
        return 1;
      }
      const std::vector<uint8_t> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::snprintf(g_current, sizeof g_current, "%s", path.c_str());
      alarm(kHangSeconds);
      try {
        LLVMFuzzerTestOneInput(data.data(), data.size());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz replay: %s: uncaught exception: %s\n", path.c_str(), e.what());
        return 1;
      } catch (...) {
        std::fprintf(stderr, "fuzz replay: %s: uncaught exception of unknown type\n", path.c_str());
        return 1;
      }
      alarm(0);
      ++runs;
    }
  }
  std::printf("fuzz replay: %zu inputs, no finding\n", runs);
  return 0;
}
