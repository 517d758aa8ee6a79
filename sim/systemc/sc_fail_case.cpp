#include "sc_fail_case.h"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

extern char** environ;

namespace shd {

namespace {

// The program's own executable: the kernel's link (independent of the current directory and
// PATH), else argv[0].
std::string selfExe(const ScOptions& o) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? o.argv0 : p.string();
}

// Runs argv, returns its exit status (-1 if it did not exit normally) and what it wrote on
// stdout and stderr (read together with poll, so that neither pipe can fill and block it).
int runChild(const std::vector<std::string>& argv, std::string& out, std::string& err, std::string& error) {
  int po[2], pe[2];
  if (pipe2(po, O_CLOEXEC) != 0) {
    error = fmt::format("pipe: {}", std::strerror(errno));
    return -1;
  }
  if (pipe2(pe, O_CLOEXEC) != 0) {
    error = fmt::format("pipe: {}", std::strerror(errno));
    close(po[0]);
    close(po[1]);
    return -1;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, po[1], STDOUT_FILENO);  // dup2 clears O_CLOEXEC on the copy
  posix_spawn_file_actions_adddup2(&fa, pe[1], STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(po[1]);
  close(pe[1]);
  if (rc != 0) {
    error = fmt::format("cannot run {}: {}", argv[0], std::strerror(rc));
    close(po[0]);
    close(pe[0]);
    return -1;
  }
  pollfd fds[2] = {{po[0], POLLIN, 0}, {pe[0], POLLIN, 0}};
  std::string* sink[2] = {&out, &err};
  int open_fds = 2;
  char buf[4096];
  while (open_fds > 0) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      const ssize_t n = read(fds[i].fd, buf, sizeof buf);
      if (n > 0) {
        sink[i]->append(buf, static_cast<size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        close(fds[i].fd);
        fds[i].fd = -1;  // poll ignores negative descriptors
        --open_fds;
      }
    }
  }
  for (const pollfd& f : fds)
    if (f.fd >= 0) close(f.fd);
  int st = 0;
  while (waitpid(pid, &st, 0) < 0)
    if (errno != EINTR) {
      error = fmt::format("waitpid: {}", std::strerror(errno));
      return -1;
    }
  if (WIFEXITED(st)) return WEXITSTATUS(st);
  error = WIFSIGNALED(st) ? fmt::format("the replay was killed by signal {} ({})", WTERMSIG(st), strsignal(WTERMSIG(st)))
                          : std::string("the replay did not exit normally");
  return -1;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

std::string ScFailReplay::command() const {
  std::string c;
  for (const std::string& a : argv) {
    if (!c.empty()) c += ' ';
    c += a.find_first_of(" \t'\"\\$*?;&|<>()") == std::string::npos ? a : "'" + a + "'";
  }
  return c;
}

ScFailReplay replayFailCase(const ScOptions& o, const ScFailCase& c) {
  ScFailReplay r;
  r.argv = {selfExe(o), "--unit", o.unit, "--config", o.config, "--vector-file", c.vec, "--fst", c.fst,
            "--json", "--quiet", "--no-fail-save"};
  std::error_code ec;
  std::filesystem::remove(c.fst, ec);  // an old waveform must not pass for this one
  std::string out, err;
  r.status = runChild(r.argv, out, err, r.error);
  r.fst_written = std::filesystem::file_size(c.fst, ec) > 0 && !ec;
  if (r.status < 0) {
    if (!err.empty()) r.error += "; its stderr: " + trimmed(err);
    return r;
  }
  if (r.status != 0 && r.status != 1) {  // bad input, or an abort (a sanitizer report)
    r.error = fmt::format("exit status {}: {}", r.status, trimmed(err));
    return r;
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(out);
    r.mismatch_cycle = j.value("mismatch_file_cycle", uint64_t{0});
    r.file_mismatch_cycle = j.value("file_mismatch_cycle", uint64_t{0});
    r.first = j.value("first_mismatch", std::string());
    if (r.first.empty()) r.first = j.value("first_item_mismatch", std::string());
  } catch (const std::exception& e) {
    r.error = fmt::format("no result from the replay ({}); exit status {}, stderr: {}", e.what(), r.status, trimmed(err));
  }
  return r;
}

}  // namespace shd
