// loadMeshFile: importMeshInProcess (mesh_io.cpp) in a child process under resource limits.
//
// assimp 5.2 is not safe on hostile files: a 309-byte OFF file that declares 353535235358
// vertices (assimp-testmodels' invalid/OutOfMemory.off) makes it allocate until memory runs out,
// some truncated COB files end the process from an exception thrown where it cannot be caught,
// and its assertions abort. None of that may take shadesim down, nor the machine's memory: the
// import runs in a forked child with an address-space limit and a wall-clock deadline, and sends
// the mesh back through a pipe; the parent also watches the child's resident memory (the only
// memory limit of a sanitizer build). A child that dies, runs out of memory or out of time is
// a SceneError naming the file and the limit.
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "io/files.h"
#include "scene/scene.h"

namespace shd {

namespace {

// The child's address space may grow by this much beyond the parent's at the fork, and its
// resident memory may not exceed it. (Under AddressSanitizer the address space at the fork
// already holds its shadow and heap reservations, so the same limit bounds what the import
// maps; its allocator then reports the failure itself and exits, see loadMeshFile.)
constexpr uint64_t kImportMemoryBytes = uint64_t{4} << 30;
constexpr int kImportSeconds = 120;

// A process's address space and resident memory in bytes (/proc/<pid>/statm, in pages); 0 if
// it cannot be read.
struct Memory {
  uint64_t address_space = 0, resident = 0;
};
Memory memoryOf(const std::string& pid) {
  Memory m;
  FILE* f = std::fopen(("/proc/" + pid + "/statm").c_str(), "r");
  unsigned long long size = 0, resident = 0;
  if (f != nullptr) {
    if (std::fscanf(f, "%llu %llu", &size, &resident) == 2) {
      const uint64_t page = static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
      m = {size * page, resident * page};
    }
    std::fclose(f);
  }
  return m;
}

// The pipe's message: a status byte, then the mesh (three counts, then the arrays) or the error.
enum : char { kMeshOk = 'M', kMeshError = 'E', kMeshOutOfMemory = 'O' };

bool writeAll(int fd, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

template <class T>
bool writeVector(int fd, const std::vector<T>& v) {
  const uint64_t n = v.size();
  return writeAll(fd, &n, sizeof n) && writeAll(fd, v.data(), n * sizeof(T));
}

// What the child printed on stderr (an abort's reason): its last two lines, at most 300 bytes.
std::string childStderr(int fd) {
  std::string text;
  char buf[4096];
  if (lseek(fd, 0, SEEK_SET) == 0)
    for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<size_t>(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  size_t from = text.rfind('\n');
  if (from != std::string::npos && from > 0) from = text.rfind('\n', from - 1);
  text = from == std::string::npos ? text : text.substr(from + 1);
  for (char& ch : text)
    if (ch == '\n') ch = ' ';
  return text.size() > 300 ? text.substr(text.size() - 300) : text;
}

[[noreturn]] void childMain(const std::string& path, int fd, int err_fd) {
  dup2(err_fd, STDERR_FILENO);  // the parent reports what matters of it
  const rlim_t bytes = memoryOf("self").address_space + kImportMemoryBytes;
  const rlimit lim{bytes, bytes};
  setrlimit(RLIMIT_AS, &lim);
  char status = kMeshError;
  std::string error;
  Mesh m;
  try {
    m = importMeshInProcess(path);
    status = kMeshOk;
  } catch (const std::bad_alloc&) {
    status = kMeshOutOfMemory;
  } catch (const std::exception& e) {
    error = e.what();
    // assimp catches the allocation failure itself and reports it as its error string.
    if (error.find("std::bad_alloc") != std::string::npos) status = kMeshOutOfMemory;
  }
  bool ok = writeAll(fd, &status, 1);
  if (status == kMeshOk)
    ok = ok && writeVector(fd, m.positions) && writeVector(fd, m.normals) && writeVector(fd, m.triangles);
  else
    ok = ok && writeAll(fd, error.data(), error.size());
  _exit(ok ? 0 : 1);
}

// How the wait for the child ended.
enum class Wait { Closed, Deadline, Memory };

// Everything the child writes, until it closes the pipe (Closed), the deadline passes or its
// resident memory exceeds the limit (checked every 50 ms).
Wait readUntilClosed(int fd, pid_t pid, std::string& out, std::chrono::steady_clock::time_point deadline) {
  char buf[1 << 16];
  const std::string child = std::to_string(pid);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return Wait::Deadline;
    pollfd p{fd, POLLIN, 0};
    const int r = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 50)));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw std::system_error(errno, std::generic_category(), "poll");
    if (r == 0) {
      if (memoryOf(child).resident > kImportMemoryBytes) return Wait::Memory;
      continue;
    }
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::system_error(errno, std::generic_category(), "read");
    if (n == 0) return Wait::Closed;
    out.append(buf, static_cast<size_t>(n));
  }
}

template <class T>
bool readVector(const std::string& s, size_t& at, std::vector<T>& v) {
  uint64_t n = 0;
  if (s.size() - at < sizeof n) return false;
  std::memcpy(&n, s.data() + at, sizeof n);
  at += sizeof n;
  if (n > (s.size() - at) / sizeof(T)) return false;
  v.resize(n);
  std::memcpy(static_cast<void*>(v.data()), s.data() + at, n * sizeof(T));
  at += n * sizeof(T);
  return true;
}

std::string describeSignal(int sig) {
  const char* name = strsignal(sig);
  return fmt::format("signal {}{}", sig, name != nullptr ? fmt::format(", {}", name) : std::string());
}

}  // namespace

Mesh loadMeshFile(const std::string& path) {
  if (const std::string why = inputFileProblem(path, kMaxMeshFileBytes); !why.empty()) failMeshFile(path, why);
  noteInput(path);
  int fds[2];
  if (pipe(fds) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  const int err_fd = memfd_create("shadesim-mesh-stderr", 0);
  std::fflush(nullptr);  // nothing buffered is written twice by the child
  const pid_t pid = err_fd < 0 ? -1 : fork();
  if (pid < 0) {
    const int e = errno;
    close(fds[0]);
    close(fds[1]);
    if (err_fd >= 0) close(err_fd);
    throw std::system_error(e, std::generic_category(), "starting the mesh import process");
  }
  if (pid == 0) {
    close(fds[0]);
    childMain(path, fds[1], err_fd);
  }
  close(fds[1]);
  struct CloseFd {
    int fd;
    ~CloseFd() { close(fd); }
  } close_err{err_fd};
  std::string msg;
  Wait end = Wait::Closed;
  try {
    end = readUntilClosed(fds[0], pid, msg, std::chrono::steady_clock::now() + std::chrono::seconds(kImportSeconds));
  } catch (...) {
    kill(pid, SIGKILL);
    close(fds[0]);
    waitpid(pid, nullptr, 0);
    throw;
  }
  close(fds[0]);
  if (end != Wait::Closed) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (end == Wait::Deadline)
    failMeshFile(path, fmt::format("the import took longer than {} s (the time limit of a mesh import)", kImportSeconds));
  if (end == Wait::Memory) msg = std::string(1, kMeshOutOfMemory);
  const bool no_result = msg.empty() || (msg[0] != kMeshOk && msg[0] != kMeshError && msg[0] != kMeshOutOfMemory);
  if (end == Wait::Closed && (WIFSIGNALED(status) || no_result)) {
    const std::string said = childStderr(err_fd);
    // A sanitizer's allocator reports an allocation over the limit itself, then exits or, with
    // ASAN_OPTIONS=abort_on_error=1, aborts.
    if (said.find("out-of-memory") != std::string::npos || said.find("allocation-size-too-big") != std::string::npos)
      msg = std::string(1, kMeshOutOfMemory);
    else if (WIFSIGNALED(status))
      failMeshFile(path, fmt::format("assimp crashed on it ({}{}; a malformed file)", describeSignal(WTERMSIG(status)),
                             said.empty() ? std::string() : ": " + said));
    else if (no_result)
      failMeshFile(path, fmt::format("the import process ended without a result (exit status {}{})", WEXITSTATUS(status),
                             said.empty() ? std::string() : ": " + said));
  }
  if (msg[0] == kMeshOutOfMemory)
    failMeshFile(path, fmt::format("the import needs more than {} MB (the memory limit of a mesh import; a file that "
                           "declares more elements than it holds?)",
                           kImportMemoryBytes >> 20));
  if (msg[0] == kMeshError) throw SceneError(msg.substr(1));
  Mesh m;
  size_t at = 1;
  if (!readVector(msg, at, m.positions) || !readVector(msg, at, m.normals) || !readVector(msg, at, m.triangles) ||
      at != msg.size() || WEXITSTATUS(status) != 0)
    failMeshFile(path, "the import process sent an incomplete mesh");
  return m;
}

}  // namespace shd
