#include "io/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

namespace shd {

namespace {

struct FileId {
  dev_t dev;
  ino_t ino;
  std::string path;
};

std::mutex g_inputs_mutex;
int g_runs = 0;  // RunInputs alive
std::vector<FileId> g_inputs;

std::string dirOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

const char* kindOf(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

std::runtime_error writeError(const std::string& path, const char* step, int err) {
  return std::runtime_error(fmt::format("cannot write '{}': {}: {}", path, step, std::strerror(err)));
}

// A staged output: its target and the temporary beside it holding the whole content.
struct Staged {
  std::string target, tmp;
};

Staged stage(const std::string& path, const std::string& content) {
  static std::atomic<unsigned long> counter{0};
  Staged s{outputTarget(path), ""};
  int fd = -1;
  // O_EXCL: never reuse a stale temporary (a crashed run with a recycled pid); try a few names.
  for (int attempt = 0; attempt < 16 && fd < 0; ++attempt) {
    s.tmp = fmt::format("{}.tmp.{}.{}", s.target, static_cast<long>(::getpid()), counter++);
    fd = ::open(s.tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) throw writeError(path, "create temporary file", errno);
  auto abandon = [&](const char* step, int err) {
    if (fd >= 0) ::close(fd);
    ::unlink(s.tmp.c_str());
    throw writeError(path, step, err);
  };
  const char* data = content.data();
  size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      abandon("write", errno);
    }
    data += n;
    left -= static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) abandon("fsync", errno);
  const int rc = ::close(fd);
  fd = -1;
  if (rc != 0) abandon("close", errno);
  return s;
}

// Makes a rename durable. The new file is already in place, so a failure is not reported.
void syncDir(const std::string& dir) {
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace

RunInputs::RunInputs() {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  ++g_runs;
}

RunInputs::~RunInputs() {
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  if (--g_runs == 0) g_inputs.clear();
}

void noteInput(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // the reader reports a missing file itself
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  if (g_runs == 0) return;
  for (const FileId& f : g_inputs)
    if (f.dev == st.st_dev && f.ino == st.st_ino) return;
  g_inputs.push_back({st.st_dev, st.st_ino, path});
}

std::string inputFileProblem(const std::string& path, uint64_t max_bytes) {
  struct stat st {};
  if (path.empty()) return "an empty file name";
  if (::stat(path.c_str(), &st) != 0) return errno == ENOENT ? "no such file" : std::strerror(errno);
  if (!S_ISREG(st.st_mode)) return fmt::format("it is {}; inputs are read only from regular files", kindOf(st.st_mode));
  if (static_cast<uint64_t>(st.st_size) > max_bytes)
    return fmt::format("{} bytes, more than the {} bytes a file of this kind may have", st.st_size, max_bytes);
  if (::access(path.c_str(), R_OK) != 0) return std::strerror(errno);
  return {};
}

std::string readInputFile(const std::string& path, uint64_t max_bytes) {
  if (const std::string why = inputFileProblem(path, max_bytes); !why.empty())
    throw std::runtime_error(fmt::format("{}: {}", path, why));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open it: {}", path, std::strerror(errno)));
  noteInput(path);
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error(fmt::format("{}: cannot read it", path));
  return s.str();
}

std::string outputTarget(const std::string& path) {
  if (path.empty()) throw std::runtime_error("cannot write '': an empty file name");
  std::string target = path;
  struct stat st {};
  for (int hops = 0;; ++hops) {
    if (::lstat(target.c_str(), &st) != 0) {
      if (errno != ENOENT) throw writeError(path, "stat", errno);
      // A new file (or a dangling link's target): its directory must exist.
      struct stat dir {};
      if (::stat(dirOf(target).c_str(), &dir) != 0 || !S_ISDIR(dir.st_mode))
        throw std::runtime_error(fmt::format("cannot write '{}': no directory '{}'", path, dirOf(target)));
      return target;
    }
    if (!S_ISLNK(st.st_mode)) break;
    if (hops == 40) throw writeError(path, "follow symbolic links", ELOOP);
    char buf[PATH_MAX];
    const ssize_t n = ::readlink(target.c_str(), buf, sizeof buf - 1);
    if (n < 0) throw writeError(path, "readlink", errno);
    const std::string link(buf, static_cast<size_t>(n));
    target = link.front() == '/' ? link : dirOf(target) + "/" + link;
  }
  const std::string shown = target == path ? fmt::format("'{}'", path) : fmt::format("'{}' (-> '{}')", path, target);
  if (!S_ISREG(st.st_mode))
    throw std::runtime_error(fmt::format("cannot write {}: it is {}; outputs are written only to regular files",
                                         shown, kindOf(st.st_mode)));
  const std::lock_guard<std::mutex> lock(g_inputs_mutex);
  for (const FileId& f : g_inputs)
    if (f.dev == st.st_dev && f.ino == st.st_ino)
      throw std::runtime_error(
          fmt::format("cannot write {}: it is an input of this run ('{}'); writing it would destroy it", shown, f.path));
  return target;
}

void OutputFiles::commit() {
  std::vector<Staged> staged;
  auto drop = [&staged](size_t from) {
    for (size_t i = from; i < staged.size(); ++i) ::unlink(staged[i].tmp.c_str());
  };
  try {
    for (const auto& [path, content] : files_) {
      staged.push_back(stage(path, content));
      for (size_t i = 0; i + 1 < staged.size(); ++i)
        if (staged[i].target == staged.back().target)
          throw std::runtime_error(fmt::format("cannot write '{}': the run writes it twice", path));
    }
  } catch (...) {
    drop(0);
    throw;
  }
  for (size_t i = 0; i < staged.size(); ++i) {
    if (::rename(staged[i].tmp.c_str(), staged[i].target.c_str()) != 0) {
      const int err = errno;
      drop(i);
      throw writeError(files_[i].first, i == 0 ? "rename" : "rename (the files before it are written)", err);
    }
    syncDir(dirOf(staged[i].target));
  }
  files_.clear();
}

void writeFileAtomic(const std::string& path, const std::string& content) {
  OutputFiles out;
  out.add(path, content);
  out.commit();
}

}  // namespace shd
