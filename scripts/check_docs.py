#!/usr/bin/env python3
"""check_docs.py: the documentation and the file references of the repository are true.

Usage: scripts/check_docs.py --shadesim PATH [--root REPO] [--no-commands] [--only CHECK ...]

Checks (each prints its offenders as file:line and a reason; exit 1 if any fails):
  links     every relative Markdown link [text](path) or [text](path#anchor) in README.md and
            docs/*.md names a file or directory inside the repository, and the anchor a heading
            of the target (GitHub's slugs: lower case, punctuation dropped, spaces to '-',
            "-1", "-2" for repeated headings).
  paths     every repository path named in backticks in README.md and docs/*.md (a token that
            starts with rtl/, model/, sim/, testbench/, vectors/, scripts/, docs/ or .ci/)
            exists. A trailing ":line" is allowed; '*', "<name>" and "{a,b}" are patterns that
            must match something.
  code      the same for file references in the code: model/, sim/, testbench/, rtl/,
            scripts/, .ci/ and every CMakeLists.txt (#include lines excepted: their paths are
            relative to an include directory). A token counts as a file reference when its
            last part has an extension or it ends in '/'; it may resolve against the
            repository root, the file's top directory (model/, sim/: the include roots) or
            the file's own directory.
  names     no file of the repository (except vector files, *.vec) names the documents the
            repository does not have: the errata and design notes kept outside it, the
            toolchain notes, or a sibling "shared" directory.
  commands  every line of a ```sh block in README.md that starts with "shadesim " (after an
            optional "$ ") runs, in order, in one fresh temporary directory, with the --shadesim
            binary for "shadesim" and arguments that name a path of the repository
            (vectors/..., scripts/..., testbench/..., rtl/...) resolved against --root; so do
            lines that start with scripts/ or testbench/ (except ./scripts/demo.sh and
            ./scripts/test.sh), and "mkdir" lines for the directories they write to. Each must
            exit 0. A block right after the line "<!-- check_docs: skip -->" is not run.
Generated paths (build/..., out/...) are not repository references and are not checked.
"""
import argparse
import glob
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time

PREFIXES = ("rtl/", "model/", "sim/", "testbench/", "vectors/", "scripts/", "docs/", ".ci/")
PREFIX_RE = r"(?:rtl|model|sim|testbench|vectors|scripts|docs|\.ci)/"
# Built from parts so that this file does not name them itself.
FORBIDDEN = [
    (re.compile("ERRATA" + r"\.md", re.I), "names a file that is not in the repository (the corrections are docs/paper-corrections.md)"),
    (re.compile("DESIGN" + r"\.md", re.I), "names a file that is not in the repository (see docs/)"),
    (re.compile(r"\b" + "TOOL" + "CHAIN" + r"\b"), "names toolchain notes that are not in the repository"),
    (re.compile(re.escape(".." + "/shared")), "names a directory outside the repository"),
]
CODE_DIRS = ("model", "sim", "testbench", "rtl", "scripts", ".ci")
SKIP_DIRS = {".git", "build", "out", "__pycache__"}
SKIP_MARK = "<!-- check_docs: skip -->"


class Report:
    def __init__(self):
        self.failures = 0

    def fail(self, where, msg):
        self.failures += 1
        print(f"  {where}: {msg}")


# ---------------------------------------------------------------------------------------------
# Files


def repo_files(root):
    """Every file of the working tree that belongs to the repository (tracked or new, not
    ignored); without git, a walk that leaves out build directories."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                             capture_output=True, check=True).stdout.decode("utf-8", "replace")
        files = [f for f in out.split("\0") if f and os.path.isfile(os.path.join(root, f))]
        if files:
            return sorted(set(files))
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for d, dirs, names in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS and not x.startswith("build")
                   and not os.path.exists(os.path.join(d, x, "CMakeCache.txt"))]
        for n in names:
            files.append(os.path.relpath(os.path.join(d, n), root))
    return sorted(files)


class Repo:
    """The repository's files and directories, for 'does this path belong to it'."""

    def __init__(self, root):
        self.root = root
        self.files = repo_files(root)
        self.file_set = set(self.files)
        self.dirs = {""}
        for f in self.files:
            d = os.path.dirname(f)
            while d and d not in self.dirs:
                self.dirs.add(d)
                d = os.path.dirname(d)

    def has(self, abs_path):
        rel = os.path.relpath(abs_path, self.root)
        if rel.startswith(".."):
            return False
        rel = "" if rel == "." else rel
        return rel in self.file_set or rel in self.dirs


def read_text(root, rel):
    try:
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            return f.read()
    except (UnicodeDecodeError, OSError):
        return None  # binary or unreadable: nothing to check


def doc_files(root):
    docs = ["README.md"] if os.path.isfile(os.path.join(root, "README.md")) else []
    docs += sorted(os.path.relpath(p, root) for p in glob.glob(os.path.join(root, "docs", "**", "*.md"), recursive=True))
    return docs


# ---------------------------------------------------------------------------------------------
# Markdown


def markdown_lines(text):
    """(line number, line, in_fence, fence_info) for every line."""
    fence = None
    info = ""
    for i, line in enumerate(text.split("\n"), 1):
        m = re.match(r"^\s*(`{3,}|~{3,})(.*)$", line)
        if fence is None and m:
            fence, info = m.group(1), m.group(2).strip()
            yield i, line, True, info
            continue
        if fence is not None and m and m.group(1).startswith(fence[0]) and len(m.group(1)) >= len(fence) \
                and not m.group(2).strip():
            fence = None
            yield i, line, True, info
            continue
        yield i, line, fence is not None, info if fence is not None else ""


def slug(heading):
    """GitHub's anchor of a heading's text."""
    t = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links: their text
    t = re.sub(r"<[^>]+>", "", t)  # inline HTML
    t = t.strip().lower()
    t = re.sub(r"[^\w\- ]", "", t)  # punctuation (backticks, *, ., :, ...) dropped; '_' kept
    return t.replace(" ", "-")


def anchors(text):
    seen = {}
    out = set()
    for _, line, in_fence, _ in markdown_lines(text):
        if in_fence:
            continue
        m = re.match(r"^ {0,3}#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        s = slug(m.group(1))
        n = seen.get(s, 0)
        seen[s] = n + 1
        out.add(s if n == 0 else f"{s}-{n}")
    return out


def strip_code_spans(line):
    return re.sub(r"(`+)(.+?)\1", lambda m: " " * len(m.group(0)), line)


def check_links(repo, docs, rep):
    root = repo.root
    cache = {}
    for rel in docs:
        text = read_text(root, rel)
        for n, line, in_fence, _ in markdown_lines(text):
            if in_fence:
                continue
            for m in re.finditer(r"\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)",
                                 strip_code_spans(line)):
                target = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                    continue  # http:, https:, mailto:
                where = f"{rel}:{n}"
                path, _, anchor = target.partition("#")
                if path.startswith("/"):
                    rep.fail(where, f"link {target}: absolute path (links are relative to the file)")
                    continue
                full = os.path.normpath(os.path.join(root, os.path.dirname(rel), path)) if path else \
                    os.path.join(root, rel)
                if os.path.relpath(full, root).startswith(".."):
                    rep.fail(where, f"link {target}: outside the repository")
                    continue
                if not os.path.exists(full) or not repo.has(full):
                    rep.fail(where, f"link {target}: no such file in the repository")
                    continue
                if anchor:
                    if not full.endswith(".md") or not os.path.isfile(full):
                        rep.fail(where, f"link {target}: an anchor into a file that is not Markdown")
                        continue
                    if full not in cache:
                        cache[full] = anchors(read_text(root, os.path.relpath(full, root)) or "")
                    if anchor not in cache[full]:
                        rep.fail(where, f"link {target}: no heading '#{anchor}' in {os.path.relpath(full, root)}")


# ---------------------------------------------------------------------------------------------
# Paths


def expand_braces(token):
    m = re.search(r"\{([^{}]*,[^{}]*)\}", token)
    if not m:
        return [token]
    out = []
    for alt in m.group(1).split(","):
        out += expand_braces(token[:m.start()] + alt + token[m.end():])
    return out


def path_matches(repo, bases, token):
    """True when the token names a file or directory of the repository under one of the bases
    (relative to the root)."""
    root = repo.root
    t = re.sub(r":\d+(-\d+)?$", "", token)  # file:line
    # Placeholders: <name>, {} (format), @CFG@ (configure_file), ${VAR} (CMake/shell).
    t = re.sub(r"<[^<>/]*>|\{\}|@[A-Z_]+@|\$\{[^}]*\}|\$[A-Za-z_]+", "*", t)
    alts = expand_braces(t)
    for base in bases:
        ok = True
        for alt in alts:
            want_dir = alt.endswith("/")
            p = os.path.join(root, base, alt.rstrip("/"))
            hits = glob.glob(p) if any(c in alt for c in "*?[") else ([p] if os.path.exists(p) else [])
            hits = [h for h in hits if repo.has(h) and (not want_dir or os.path.isdir(h))]
            if not hits:
                ok = False
                break
        if ok:
            return True
    return False


def doc_path_tokens(line):
    """Repository paths named in the backtick spans of a Markdown line (or a whole code line)."""
    for m in re.finditer(r"(`+)(.+?)\1", line):
        for tok in m.group(2).split():
            yield tok


def clean_doc_token(tok):
    tok = tok.strip("\"'()[],;")
    tok = re.sub(r"^(?:\./)", "", tok)
    if "=" in tok and not tok.startswith(PREFIXES):  # --opt=path
        tok = tok.split("=", 1)[1]
    return tok


def check_doc_paths(repo, docs, rep):
    for rel in docs:
        text = read_text(repo.root, rel)
        for n, line, in_fence, _ in markdown_lines(text):
            if in_fence:
                if re.match(r"^\s*(`{3,}|~{3,})", line):
                    continue
                # Inside a code block: tokens that are repository paths (not .../vectors/...).
                toks = [t for t in re.split(r"\s+", line) if t]
            else:
                toks = list(doc_path_tokens(line))
            for tok in toks:
                tok = clean_doc_token(tok)
                if in_fence:
                    tok = tok.rstrip(".,;:")  # prose punctuation in a program's output
                    last = tok.rstrip("/").rsplit("/", 1)[-1]
                    if tok.count("/") < 2 and "." not in last and not tok.endswith("/"):
                        continue  # "M vectors/s" in a program's output: not a path
                if not tok.startswith(PREFIXES):
                    continue
                if not path_matches(repo, [""], tok):
                    rep.fail(f"{rel}:{n}", f"`{tok}` does not exist in the repository")


CODE_TOKEN_RE = re.compile(r"(?<![A-Za-z0-9_./$@{}\\-])(" + PREFIX_RE + r"[A-Za-z0-9_.*/{},<>@$-]*)")


def is_code_file(rel):
    base = os.path.basename(rel)
    if base == "CMakeLists.txt":
        return True
    if not rel.startswith(tuple(d + "/" for d in CODE_DIRS)):
        return False
    return not base.endswith((".vec", ".hex", ".mem", ".coe", ".mif", ".csv", ".json", ".png", ".obj", ".md"))


def check_code_paths(repo, rep):
    for rel in repo.files:
        if not is_code_file(rel):
            continue
        text = read_text(repo.root, rel)
        if text is None:
            continue
        top = rel.split("/", 1)[0] if "/" in rel else ""
        bases = ["", os.path.dirname(rel)]
        if top in ("model", "sim"):
            bases.insert(1, top)
        for n, line in enumerate(text.split("\n"), 1):
            if re.match(r"^\s*#\s*include\b", line):
                continue
            for m in CODE_TOKEN_RE.finditer(line):
                tok = m.group(1).rstrip(".,;:)}")
                tok = re.sub(r"\{[^{}]*$", "", tok)  # an unclosed format field: "...{}" cut off
                last = tok.rstrip("/").rsplit("/", 1)[-1]
                if not (tok.endswith("/") or "." in last):
                    continue  # prose ("M vectors/s") or a directory named without '/'
                if not path_matches(repo, bases, tok):
                    rep.fail(f"{rel}:{n}", f"{tok} does not exist in the repository")


def check_names(repo, rep):
    me = os.path.relpath(os.path.abspath(__file__), repo.root)
    for rel in repo.files:
        if rel.endswith(".vec") or rel == me:
            continue
        text = read_text(repo.root, rel)
        if text is None:
            continue
        for n, line in enumerate(text.split("\n"), 1):
            for rx, why in FORBIDDEN:
                m = rx.search(line)
                if m:
                    rep.fail(f"{rel}:{n}", f"'{m.group(0)}' {why}")


# ---------------------------------------------------------------------------------------------
# The README's commands


def readme_commands(root):
    """[(line of the fence, [(line number, command)])] for the ```sh blocks of README.md that run."""
    text = read_text(root, "README.md") or ""
    blocks = []
    cur = None  # the block being read: {"line", "run", "cmds"}
    prev = ""  # the last non-blank line outside code blocks
    for n, line, in_fence, info in markdown_lines(text):
        fence_line = re.match(r"^\s*(`{3,}|~{3,})", line) is not None
        if in_fence and fence_line and cur is None:  # an opening fence
            lang = info.split()[0] if info else ""
            cur = {"line": n, "cmds": [],
                   "run": lang in ("sh", "bash", "shell", "console") and prev.strip() != SKIP_MARK}
            continue
        if cur is not None and (not in_fence or fence_line):  # the closing fence
            if cur["run"] and cur["cmds"]:
                blocks.append((cur["line"], cur["cmds"]))
            cur = None
            prev = line
            continue
        if cur is not None:
            s = re.sub(r"^\$ ", "", line.strip())
            if cur["cmds"] and cur["cmds"][-1][1].endswith("\\"):  # a continued line
                cur["cmds"][-1] = (cur["cmds"][-1][0], cur["cmds"][-1][1][:-1] + " " + s)
            elif re.match(r"^(shadesim |mkdir |(\./)?scripts/|(\./)?testbench/)", s) and \
                    not re.match(r"^(\./)?scripts/(demo|test)\.sh\b", s):
                cur["cmds"].append((n, s))
        elif line.strip():
            prev = line
    return blocks


def resolve_arg(root, tok):
    t = tok[2:] if tok.startswith("./") else tok
    if t.startswith(PREFIXES) and os.path.exists(os.path.join(root, t.rstrip("/"))):
        return os.path.join(root, t)
    return tok


def run_command(root, shadesim, tmp, where, cmd, rep):
    try:
        argv = shlex.split(cmd, comments=True)
    except ValueError as e:
        rep.fail(where, f"cannot parse '{cmd}': {e}")
        return
    bad = [t for t in argv if t in ("|", "||", "&&", ";", ">", ">>", "<", "&") or t.startswith(("$", "`"))]
    if bad:
        rep.fail(where, f"'{cmd}': pipes, redirections and variables are not run here ({bad[0]})")
        return
    if argv[0] == "shadesim":
        argv[0] = shadesim
    elif argv[0] == "mkdir":
        if any(os.path.isabs(t) or ".." in t.split("/") for t in argv[1:]):
            rep.fail(where, f"'{cmd}': mkdir is run only inside the temporary directory")
            return
    else:
        argv[0] = resolve_arg(root, argv[0])
    argv[1:] = [resolve_arg(root, t) for t in argv[1:]]
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(shadesim) + os.pathsep + env.get("PATH", "")
    t0 = time.monotonic()
    try:
        r = subprocess.run(argv, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, timeout=300)
        status, err = r.returncode, r.stderr.decode("utf-8", "replace").strip()
    except (OSError, subprocess.TimeoutExpired) as e:
        status, err = -1, str(e)
    print(f"  {'ok  ' if status == 0 else 'FAIL'} {time.monotonic() - t0:5.1f} s  {cmd}")
    if status != 0:
        lines = [x for x in err.splitlines() if x.strip()]
        tail = next((x for x in lines if "error" in x.lower()), lines[-1] if lines else "")
        rep.fail(where, f"'{cmd}' exited {status}" + (f": {tail}" if tail else ""))


def check_commands(root, shadesim, rep):
    shadesim = os.path.abspath(shadesim)
    if not (os.path.isfile(shadesim) and os.access(shadesim, os.X_OK)):
        rep.fail("--shadesim", f"{shadesim} is not an executable")
        return
    blocks = readme_commands(root)
    if not blocks:
        rep.fail("README.md", "no ```sh block with shadesim commands")
    # One temporary directory for the whole README: its blocks are a tour, run in order.
    with tempfile.TemporaryDirectory(prefix="check_docs_") as tmp:
        for _, cmds in blocks:
            for n, cmd in cmds:
                run_command(root, shadesim, tmp, f"README.md:{n}", cmd, rep)


# ---------------------------------------------------------------------------------------------


def main(argv):
    p = argparse.ArgumentParser(prog="check_docs.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--shadesim", help="the shadesim binary the README's commands run with")
    p.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                   help="the repository (default: the one holding this script)")
    p.add_argument("--no-commands", action="store_true", help="leave out the README's commands")
    p.add_argument("--only", action="append", choices=["links", "paths", "code", "names", "commands"],
                   help="run only this check (repeatable)")
    a = p.parse_args(argv)
    root = os.path.abspath(a.root)
    checks = a.only or ["links", "paths", "code", "names"] + ([] if a.no_commands else ["commands"])
    if "commands" in checks and not a.shadesim:
        p.error("--shadesim is required for the commands check (or --no-commands)")
    repo = Repo(root)
    docs = doc_files(root)
    failed = []
    titles = {"links": "relative links in README.md and docs/",
              "paths": "repository paths in backticks in README.md and docs/",
              "code": "file references in the code",
              "names": "documents that are not in the repository",
              "commands": "the README's commands"}
    for c in checks:
        print(f"check_docs: {titles[c]}")
        rep = Report()
        if c == "links":
            check_links(repo, docs, rep)
        elif c == "paths":
            check_doc_paths(repo, docs, rep)
        elif c == "code":
            check_code_paths(repo, rep)
        elif c == "names":
            check_names(repo, rep)
        else:
            check_commands(root, a.shadesim, rep)
        print(f"check_docs: {titles[c]}: " + ("ok" if rep.failures == 0 else f"{rep.failures} FAILED"))
        if rep.failures:
            failed.append(c)
    if failed:
        print(f"check_docs: FAILED ({', '.join(failed)})")
        return 1
    print("check_docs: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
