#!/usr/bin/env python3
"""Replays the hostile-input corpus (cases.ini beside this file) against shadesim and
shadesim_systemc, and checks the policy both programs promise on bad input:

  exit status  0 the run completed and every check passed; 1 it completed and a check failed
               (a mismatch); 2 it could not be done (bad input, a refused output, a resource
               limit, an I/O error). One convention for both programs (sim/cli/options.h).
  one message  with exit 2, exactly one stderr line contains "error:", in the form
               "shadesim <subcommand>: error: <message>" or "shadesim_systemc: error: <message>",
               and it matches the case's `error` regex (which names the file, key, option and
               value at fault); nothing on stdout. With exit 0 or 1 no "error:" line at all.
  no crash     no signal, no AddressSanitizer / UndefinedBehaviorSanitizer report.
  no partial   the case's work directory holds after the run exactly what it held before (names,
  output       types, contents), apart from the files the case lists in `outputs`; the run's
               TMPDIR (a fresh directory beside it) is empty again; no process of the run is
               left behind.
  no hang      each case has a timeout (default 30 s, `timeout` in the case; --timeout-scale for
               slow builds); at the timeout the process group is killed and the case fails.
  bounded      the maximum resident memory of the process tree (the program and the children it
  memory       waited for, e.g. the mesh-import process: wait4's rusage) is at most --max-rss-mb,
               1024 MB by default; a watchdog reads /proc every 50 ms and kills a run that passes
               it, so that a sanitizer build cannot take the machine's memory either. With
               --address-limit-gb N (the CMake registration passes 8 except in a sanitizer build,
               where AddressSanitizer reserves terabytes of address space) the program runs under
               RLIMIT_AS = N GB.
  /dev/null    still a character device after every case (no case names it as an output).

Case format (configparser INI, one section per case; see the head of cases.ini):
  what = one line: what is wrong with the input
  run = the command line (shlex); a first word shadesim or shadesim_systemc is the binary,
        {work} the case's work directory (also the current directory), {root} the repository
  exit = the expected status;  error = regex of the error line (exit 2);  warning = regex of a
  "warning:" line (exit 0);  expect = regex that stdout + stderr must match;  outputs = files the
  run must create (exit 0/1 cases);  timeout = seconds;  systemc_config = UNIT:NAME: the case is
  skipped when shadesim_systemc has no model of that configuration (a sanitizer build has few)
  Inputs, made in this order in the fresh work directory:
    mkdir = d, ...                      directories
    copy = SRC [-> DST], ...            files (SRC relative to this directory, or {root}/...)
    file.NAME = text                    text, a newline appended unless empty
    bytes.NAME = python expression      exact bytes (a bytes expression; bytes, range, struct)
    edit.NAME = REGEX => REPL           re.sub on the file's bytes (latin-1), first match; ==> all
                                        matches; one edit per line; the pattern must match
    truncate.NAME = N | -N | lines N    keep N bytes, all but the last N, or the first N lines
    fifo = NAME, ...                    named pipes
    chardev = NAME, ...                 character devices, twins of /dev/null (major 1, minor 3):
                                        the output cases use these, never /dev/null itself, which
                                        a program that wrongly replaced its output target would
                                        destroy for the whole machine
    symlink = LINK -> TARGET, ...       symbolic links

Usage: run_hostile.py --shadesim BIN --systemc BIN [--work DIR] [--jobs 2] [-k PATTERN] [--list]
       [--max-rss-mb 1024] [--address-limit-gb 0] [--timeout-scale 1] [--keep] [-v]
Prints one line per case (PASS/FAIL/SKIP, seconds, max RSS in MB) and a summary; exits 1 if a
case fails, 2 if the corpus itself is malformed. A failing case's directory stays under --work:
its inputs (work/), stdout and stderr.
"""

import argparse
import configparser
import hashlib
import os
import re
import resource
import shlex
import shutil
import signal
import stat
import subprocess
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# "shadesim: error:" only where no subcommand was recognised (none given, or an unknown one).
ERROR_FORMAT = re.compile(r"^(shadesim [a-z-]+|shadesim|shadesim_systemc): error: \S")
# A sanitizer's own report (at the start of a line: a program that reports a crash of a child
# it contained, inside its one error line, is not reported here).
SANITIZER = re.compile(r"^(==\d+==)?(ERROR: \w+Sanitizer|\w+Sanitizer:DEADLYSIGNAL)|^SUMMARY: \w+Sanitizer|"
                       r"^[^\s:]+:\d+:\d+: runtime error: ", re.M)
KNOWN_KEYS = {"what", "run", "exit", "error", "warning", "expect", "outputs", "timeout", "systemc_config",
              "mkdir", "copy", "fifo", "chardev", "symlink"}
FILE_KEYS = ("file.", "bytes.", "edit.", "truncate.")


class CorpusError(Exception):
    pass


class Skip(Exception):
    """The case cannot be set up on this machine (e.g. no right to make a device node)."""


_SC_BUILT = {}


def systemc_has(binary, unit, name):
    """Whether shadesim_systemc was built with a model of <unit>:<name>: its error for an unknown
    configuration lists the ones it has ("(built: a, b)")."""
    if (binary, unit) not in _SC_BUILT:
        r = subprocess.run([binary, "--unit", unit, "--config", "none-such", "--quiet"],
                           capture_output=True, text=True, timeout=60)
        m = re.search(r"\(built: ([^)]*)\)", r.stderr)
        _SC_BUILT[(binary, unit)] = set(split_list(m.group(1))) if m else set()
    return name in _SC_BUILT[(binary, unit)]


def split_list(value):
    return [item.strip() for item in re.split(r"[,\n]", value) if item.strip()]


def expand(text, work):
    return text.replace("{work}", work).replace("{root}", ROOT)


# --- the corpus -----------------------------------------------------------------------------

def load_cases(path):
    parser = configparser.RawConfigParser(delimiters=("=",), comment_prefixes=("#",),
                                          inline_comment_prefixes=None, strict=True,
                                          empty_lines_in_values=False)
    parser.optionxform = str  # file names are case-sensitive
    with open(path, encoding="utf-8") as f:
        parser.read_file(f)
    cases = []
    for name in parser.sections():
        c = dict(parser.items(name))
        for key in c:
            if key not in KNOWN_KEYS and not key.startswith(FILE_KEYS):
                raise CorpusError(f"[{name}]: unknown key '{key}'")
        for key in ("what", "run", "exit"):
            if not c.get(key):
                raise CorpusError(f"[{name}]: '{key}' missing")
        try:
            c["exit"] = int(c["exit"])
        except ValueError:
            raise CorpusError(f"[{name}]: exit = {c['exit']!r} is not a number") from None
        if c["exit"] == 2 and not c.get("error"):
            raise CorpusError(f"[{name}]: exit 2 needs an 'error' regex")
        if c["exit"] != 2 and c.get("error"):
            raise CorpusError(f"[{name}]: 'error' only with exit 2")
        if c.get("warning") and c["exit"] != 0:
            raise CorpusError(f"[{name}]: 'warning' only with exit 0")
        if c.get("outputs") and c["exit"] == 2:
            raise CorpusError(f"[{name}]: a run that fails (exit 2) writes no outputs")
        for key in ("error", "warning", "expect"):
            if c.get(key):
                try:
                    re.compile(c[key])
                except re.error as e:
                    raise CorpusError(f"[{name}]: {key} is not a regex: {e}") from None
        c["name"] = name
        cases.append(c)
    return cases


def make_inputs(case, work):
    """Builds the case's inputs in the empty directory `work`."""
    def target(name):
        p = os.path.normpath(os.path.join(work, name))
        if not p.startswith(work + os.sep):
            raise CorpusError(f"[{case['name']}]: '{name}' is outside the work directory")
        return p

    for d in split_list(case.get("mkdir", "")):
        os.makedirs(target(d), exist_ok=True)
    for item in split_list(case.get("copy", "")):
        src, _, dst = (s.strip() for s in item.partition("->"))
        src = expand(src, work)
        src = src if os.path.isabs(src) else os.path.join(HERE, src)
        dst = target(dst or os.path.basename(src))
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copyfile(src, dst)
    for key, value in case.items():
        if key.startswith("file."):
            data = expand(value, work).encode()
            with open(target(key[5:]), "wb") as f:
                f.write(data + (b"\n" if data else b""))
        elif key.startswith("bytes."):
            try:
                data = eval(value, {"__builtins__": {}, "bytes": bytes, "range": range, "struct": struct})  # our corpus
            except Exception as e:  # noqa: BLE001 - any mistake in the corpus
                raise CorpusError(f"[{case['name']}]: {key}: {e}") from None
            if not isinstance(data, bytes):
                raise CorpusError(f"[{case['name']}]: {key} is not a bytes expression")
            with open(target(key[6:]), "wb") as f:
                f.write(data)
    for key, value in case.items():
        if key.startswith("edit."):
            path = target(key[5:])
            with open(path, "rb") as f:
                text = f.read().decode("latin-1")
            for line in value.splitlines():
                m = re.fullmatch(r"(.+?) (==?>)(?: (.*))?", line)
                if not m:
                    raise CorpusError(f"[{case['name']}]: {key}: '{line}' is not 'REGEX => REPL'")
                pattern, every, repl = m.group(1), m.group(2) == "==>", m.group(3) or ""
                text, n = re.subn(pattern, repl, text, count=0 if every else 1, flags=re.M)
                if n == 0:
                    raise CorpusError(f"[{case['name']}]: {key}: '{pattern}' matches nothing")
            with open(path, "wb") as f:
                f.write(text.encode("latin-1"))
    for key, value in case.items():
        if key.startswith("truncate."):
            path = target(key[9:])
            with open(path, "rb") as f:
                data = f.read()
            m = re.fullmatch(r"\s*(lines\s+)?(-?\d+)\s*", value)
            if not m:
                raise CorpusError(f"[{case['name']}]: {key} = {value!r}")
            n = int(m.group(2))
            if m.group(1):
                data = b"".join(data.splitlines(keepends=True)[:n])
            else:
                data = data[:n] if n >= 0 else data[:len(data) + n]
            with open(path, "wb") as f:
                f.write(data)
    for name in split_list(case.get("fifo", "")):
        os.mkfifo(target(name))
    for name in split_list(case.get("chardev", "")):
        try:  # a private twin of /dev/null: a program that wrongly replaces it harms nothing else
            os.mknod(target(name), stat.S_IFCHR | 0o666, os.makedev(1, 3))
        except PermissionError:
            raise Skip("no permission to make a device node (mknod)") from None
    for item in split_list(case.get("symlink", "")):
        link, sep, dest = (s.strip() for s in item.partition("->"))
        if not sep:
            raise CorpusError(f"[{case['name']}]: symlink '{item}' is not 'LINK -> TARGET'")
        os.symlink(expand(dest, work), target(link))


def tree_rss_mb(pid):
    """The largest resident memory (MB) of `pid` and its descendants, from /proc; 0 if gone."""
    page_mb = os.sysconf("SC_PAGE_SIZE") / (1 << 20)
    best, todo = 0.0, [pid]
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/statm") as f:
                best = max(best, int(f.read().split()[1]) * page_mb)
            for task in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{task}/children") as f:
                    todo.extend(int(c) for c in f.read().split())
        except (OSError, ValueError, IndexError):
            continue
    return best


def snapshot(top):
    """{relative path: (kind, detail)} of everything under `top`; special files are never opened."""
    state = {}
    for dirpath, dirnames, filenames in os.walk(top):
        for name in dirnames + filenames:
            path = os.path.join(dirpath, name)
            rel = os.path.relpath(path, top)
            st = os.lstat(path)
            if stat.S_ISREG(st.st_mode):
                with open(path, "rb") as f:
                    state[rel] = ("file", hashlib.sha256(f.read()).hexdigest())
            elif stat.S_ISLNK(st.st_mode):
                state[rel] = ("link", os.readlink(path))
            elif stat.S_ISDIR(st.st_mode):
                state[rel] = ("dir", "")
            elif stat.S_ISFIFO(st.st_mode):
                state[rel] = ("fifo", "")
            else:
                state[rel] = ("special", oct(st.st_mode))
    return state


# --- one run --------------------------------------------------------------------------------

class Run:
    """One case's process: started by posix_spawn in its own session, polled with wait4. The C
    library's posix_spawn shares this script's memory until the exec (vfork); a fork copied its
    page tables, and then its pages as it wrote them (with group_alive's signal 0, the test's
    CPU time went from 19.4 to 12.0 s: medians of 3 interleaved rounds, one core). posix_spawn
    cannot change directory or set limits: this script, single-threaded, is in the case's work
    directory for the call, and the address-space limit is its own (main), which every program
    it starts inherits. A run's maximum RSS is at least this script's (some 20 MB), which its
    process was until the exec, as a fork's copy was (then some 13 MB): far below any limit."""

    def __init__(self, case, args, work_root):
        self.case = case
        self.args = args
        self.work = os.path.join(work_root, case["name"], "work")
        self.tmp = os.path.join(work_root, case["name"], "tmp")
        self.log = os.path.join(work_root, case["name"])
        self.problems = []
        self.pid = None
        self.status = None
        self.rss_mb = 0.0
        self.timed_out = False
        self.watchdog_mb = 0.0
        self.next_memory_check = 0.0
        self.seconds = 0.0

    def start(self):
        need = self.case.get("systemc_config")
        if need:
            unit, _, name = need.partition(":")
            if not systemc_has(self.args.systemc, unit, name):
                raise Skip(f"shadesim_systemc has no model of {need} in this build")
        case_dir = self.log
        if os.path.lexists(case_dir):
            shutil.rmtree(case_dir)
        os.makedirs(self.work)
        os.makedirs(self.tmp)
        make_inputs(self.case, self.work)
        self.before = snapshot(self.work)
        argv = [expand(a, self.work) for a in shlex.split(self.case["run"])]
        binaries = {"shadesim": self.args.shadesim, "shadesim_systemc": self.args.systemc}
        if argv and argv[0] in binaries:
            if not binaries[argv[0]]:
                raise CorpusError(f"[{self.case['name']}]: no --{argv[0].replace('shadesim_', '')} given")
            argv[0] = binaries[argv[0]]
        self.argv = argv
        env = dict(os.environ)
        env["TMPDIR"] = self.tmp
        self.out_path = os.path.join(case_dir, "stdout")
        self.err_path = os.path.join(case_dir, "stderr")
        timeout = float(self.case.get("timeout", self.args.timeout)) * self.args.timeout_scale
        out = os.open(self.out_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        err = os.open(self.err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        self.t0 = time.monotonic()
        self.deadline = self.t0 + timeout
        self.timeout = timeout
        here = os.getcwd()
        os.chdir(self.work)
        try:
            # out and err are not inherited (os.open's descriptors close at exec): their copies
            # on 1 and 2 are.
            self.pid = os.posix_spawn(argv[0], argv, env, setsid=True, file_actions=[
                (os.POSIX_SPAWN_OPEN, 0, os.devnull, os.O_RDONLY, 0),
                (os.POSIX_SPAWN_DUP2, out, 1), (os.POSIX_SPAWN_DUP2, err, 2)])
        except OSError as e:  # as a shell reports it: the message, exit status 127
            os.write(err, f"run_hostile.py: cannot start {argv[0]}: {e}\n".encode())
            self.pid = None
        finally:
            os.chdir(here)
            os.close(out)
            os.close(err)

    def poll(self):
        """True once the process has ended (or been killed at its deadline or memory limit)."""
        if self.pid is None:  # never started
            self.seconds, self.status = time.monotonic() - self.t0, 127 << 8
            return True
        pid, status, usage = os.wait4(self.pid, os.WNOHANG)
        if pid == 0:
            now = time.monotonic()
            if now >= self.next_memory_check:
                # The watchdog: a run that grows past the limit is stopped while it runs, so that
                # a sanitizer build (no address-space limit) cannot take the machine's memory.
                self.next_memory_check = now + 0.05
                rss = tree_rss_mb(self.pid)
                if rss > self.args.max_rss_mb:
                    self.watchdog_mb = rss
            if now < self.deadline and not self.watchdog_mb:
                return False
            self.timed_out = not self.watchdog_mb
            self.kill_group()
            pid, status, usage = os.wait4(self.pid, 0)
        self.seconds = time.monotonic() - self.t0
        self.status = status
        self.rss_mb = usage.ru_maxrss / 1024.0  # kB on Linux
        return True

    def kill_group(self):
        if self.pid is None:
            return
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def group_alive(self):
        """Whether a live (not zombie) process of the run's session is left."""
        if self.pid is None:
            return False
        # Most runs leave no process at all in their group: signal 0 tells that without reading
        # every process's stat (the scan below was a quarter of this script's CPU time).
        try:
            os.killpg(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            pass  # a process exists (not ours to signal): the scan decides
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[2]) == self.pid and fields[0] != "Z":  # pgrp, state
                return True
        return False

    def check(self):
        c, p = self.case, self.problems
        if not self.timed_out and not self.watchdog_mb and self.group_alive():
            p.append("a process of the run is still running after it ended (killed)")
            self.kill_group()
        with open(self.out_path, "rb") as f:
            stdout = f.read().decode("utf-8", "replace")
        with open(self.err_path, "rb") as f:
            stderr = f.read().decode("utf-8", "replace")
        self.stdout, self.stderr = stdout, stderr
        if self.timed_out:
            p.append(f"hang: no exit within {self.timeout:g} s (process group killed)")
        elif self.watchdog_mb:
            p.append(f"memory: a process of the run reached {self.watchdog_mb:.0f} MB resident, above the "
                     f"limit of {self.args.max_rss_mb:g} MB (process group killed)")
        elif os.WIFSIGNALED(self.status):
            sig = os.WTERMSIG(self.status)
            p.append(f"crash: killed by signal {sig} ({signal.Signals(sig).name}), expected exit {c['exit']}")
        elif os.WEXITSTATUS(self.status) != c["exit"]:
            p.append(f"exit {os.WEXITSTATUS(self.status)}, expected {c['exit']}")
        if SANITIZER.search(stderr):
            p.append("sanitizer report: " + SANITIZER.search(stderr).group(0))
        if self.rss_mb > self.args.max_rss_mb:
            p.append(f"max RSS {self.rss_mb:.0f} MB above the limit of {self.args.max_rss_mb:g} MB")

        ended = not self.timed_out and not self.watchdog_mb
        error_lines = [ln for ln in stderr.splitlines() if "error:" in ln]
        if c["exit"] == 2 and ended:
            if len(error_lines) != 1:
                p.append(f"{len(error_lines)} 'error:' lines on stderr, expected exactly one")
            for ln in error_lines[:1]:
                if not ERROR_FORMAT.search(ln):
                    p.append(f"error line not in the form '<program>: error: <message>': {ln!r}")
                if not re.search(c["error"], ln):
                    p.append(f"error line does not match /{c['error']}/: {ln!r}")
            if stdout.strip():
                p.append(f"{len(stdout)} bytes on stdout of a failed run: {stdout[:200]!r}")
        elif error_lines and ended:
            p.append(f"an 'error:' line in a run expected to exit {c['exit']}: {error_lines[0]!r}")
        if c.get("warning"):
            warnings = [ln for ln in stderr.splitlines() if "warning:" in ln]
            if not any(re.search(c["warning"], ln) for ln in warnings):
                p.append(f"no warning line matches /{c['warning']}/ (warnings: {warnings!r})")
        if c.get("expect") and not re.search(c["expect"], stdout + stderr, re.M):
            p.append(f"stdout + stderr do not match /{c['expect']}/")

        after = snapshot(self.work)
        outputs = set(c.get("outputs", "").replace(",", " ").split())
        for rel in sorted(set(self.before) | set(after)):
            b, a = self.before.get(rel), after.get(rel)
            if rel in outputs:
                if not a or a[0] != "file":
                    p.append(f"output {rel} not written")
                continue
            if b == a:
                continue
            if b is None:
                p.append(f"partial output: {rel} ({a[0]}) left in the work directory")
            elif a is None:
                p.append(f"input {rel} ({b[0]}) removed")
            else:
                p.append(f"input {rel} changed ({b[0]} -> {a[0]})")
        left = sorted(os.listdir(self.tmp)) if os.path.isdir(self.tmp) else ["(TMPDIR removed)"]
        if left:
            p.append(f"left in TMPDIR: {', '.join(left[:5])}")
        if not os.path.exists("/dev/null") or not stat.S_ISCHR(os.stat("/dev/null").st_mode):
            p.append("/dev/null IS NO LONGER A CHARACTER DEVICE")
        return not p


# --- main -----------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default=os.path.join(HERE, "cases.ini"))
    ap.add_argument("--shadesim", help="the shadesim binary")
    ap.add_argument("--systemc", help="the shadesim_systemc binary")
    ap.add_argument("--work", help="where the cases' directories go (default: a fresh one under $TMPDIR); "
                                   "each case's is made afresh, and left for inspection when it fails")
    ap.add_argument("--jobs", "-j", type=int, default=2, help="cases run at once (default 2)")
    ap.add_argument("-k", dest="pattern", help="only the cases whose name matches this regex")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--timeout", type=float, default=30, help="seconds per case unless it says (default 30)")
    ap.add_argument("--timeout-scale", type=float, default=1, help="multiplies every timeout (slow builds)")
    ap.add_argument("--max-rss-mb", type=float, default=1024,
                    help="maximum resident memory of a case's process tree, MB (default 1024)")
    ap.add_argument("--address-limit-gb", type=float, default=0,
                    help="RLIMIT_AS of each program in GB; 0: none (sanitizer builds)")
    ap.add_argument("--keep", action="store_true", help="keep the directories of passing cases too")
    ap.add_argument("-v", "--verbose", action="store_true", help="show the output of failing cases")
    args = ap.parse_args()

    try:
        cases = load_cases(args.cases)
    except (CorpusError, configparser.Error) as e:
        print(f"run_hostile.py: {args.cases}: {e}", file=sys.stderr)
        return 2
    if args.pattern:
        cases = [c for c in cases if re.search(args.pattern, c["name"])]
    if args.list:
        for c in cases:
            print(f"{c['name']:40s} {c['what']}")
        return 0
    if not args.shadesim or not args.systemc:
        ap.error("--shadesim and --systemc are required")
    args.shadesim = os.path.abspath(args.shadesim)
    args.systemc = os.path.abspath(args.systemc)
    if args.work:
        work_root = os.path.abspath(args.work)
        os.makedirs(work_root, exist_ok=True)
    else:
        import tempfile
        work_root = tempfile.mkdtemp(prefix="hostile-")
    if args.address_limit_gb > 0:  # this script's own: every program it starts inherits it (Run)
        b = int(args.address_limit_gb * (1 << 30))
        resource.setrlimit(resource.RLIMIT_AS, (b, b))

    t_all = time.monotonic()
    pending, running, failed, skipped, max_rss = list(cases), [], [], [], 0.0
    results = {}
    while pending or running:
        while pending and len(running) < max(1, args.jobs):
            r = Run(pending.pop(0), args, work_root)
            try:
                r.start()
            except Skip as e:
                skipped.append(r)
                print(f"SKIP {r.case['name']:40s} {e}", flush=True)
                continue
            except (CorpusError, OSError) as e:
                print(f"run_hostile.py: {e}", file=sys.stderr)
                for x in running:
                    x.kill_group()
                return 2
            running.append(r)
        still = []
        for r in running:
            if r.poll():
                ok = r.check()
                max_rss = max(max_rss, r.rss_mb)
                results[r.case["name"]] = r
                print(f"{'PASS' if ok else 'FAIL'} {r.case['name']:40s} {r.seconds:6.2f} s {r.rss_mb:7.1f} MB", flush=True)
                if ok and not args.keep:
                    shutil.rmtree(r.log, ignore_errors=True)
                if not ok:
                    failed.append(r)
                    for problem in r.problems:
                        print(f"       {problem}", flush=True)
                    if args.verbose:
                        print("       $ " + shlex.join(r.argv))
                        for ln in (r.stdout + r.stderr).splitlines()[-10:]:
                            print(f"       | {ln}")
            else:
                still.append(r)
        running = still
        if running:
            time.sleep(0.005)
    total = time.monotonic() - t_all
    print(f"{len(cases) - len(failed) - len(skipped)} of {len(cases)} cases passed, {len(failed)} failed, "
          f"{len(skipped)} skipped, "
          f"{total:.1f} s, max RSS {max_rss:.0f} MB (limit {args.max_rss_mb:g} MB"
          f"{f', address space {args.address_limit_gb:g} GB' if args.address_limit_gb > 0 else ''}); "
          f"work directories in {work_root}")
    if failed:
        print("failed: " + " ".join(r.case["name"] for r in failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
