#!/usr/bin/env python3
"""Runs every command the documentation shows, so that the docs cannot drift.

The commands are the fenced code blocks of the given Markdown files whose
language tag is a shell (sh, bash, shell: every line a command but comments;
console: the lines after a "$ " prompt) or python (the block is one script).
Blocks tagged as something that is not run (c, cmake, json, text) are
skipped; a block without a tag, or with a tag of neither kind, is an error,
so that no command escapes by its fence.

Each file's commands run in document order in one bash (so a variable or a
file one command makes is there for the next ones), in a fresh temporary
directory of that file holding the links given with --link (models/, the
build, ...). The environment is the caller's. A command is run unless a
pattern of the exempt file matches it; that file holds one exemption a line,
"[FILE] REGEX # REASON" (Python re.search over the command with its
continuation lines joined; "[FILE] " limits it to that document, as named on
the command line; blank lines and lines starting with # are comments).

Fails (exit 1) when a command exits non-zero (file:line, the command, its
stderr), when a command is neither run successfully nor exempt (an earlier
command of its file failed), when an exemption matches no command any more
(stale) or has no reason, and for an untagged or unknown block; exit 2 for
bad arguments.
"""
import argparse
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile

SHELL_TAGS = {"sh", "bash", "shell", "console"}
PYTHON_TAGS = {"python"}
NOT_COMMAND_TAGS = {"c", "cmake", "json", "text"}
FENCE = re.compile(r"^( *)(`{3,}|~{3,})\s*([^`\s]*)\s*$")


class Block:
    def __init__(self, path, line, tag):
        self.path, self.line, self.tag = path, line, tag
        self.lines = []  # (line number, text without the fence's indent)


class Command:
    def __init__(self, path, line, text, script=None):
        self.path, self.line, self.text = path, line, text
        self.script = script  # a python block's source; None for a shell line
        self.shown = re.sub(r"\\\n\s*", " ", text) if script is None else (
            "python block: " + "; ".join(l.split("  #")[0].strip() for l in script.splitlines()
                                         if l.strip() and not l.lstrip().startswith("#")))


def read_blocks(path):
    blocks, cur, fence = [], None, None
    with open(path, encoding="utf-8") as f:
        for n, raw in enumerate(f, 1):
            line = raw.rstrip("\n")
            if cur is None:
                m = FENCE.match(line)
                if m:
                    cur, fence = Block(path, n, m.group(3).lower()), m
                continue
            stripped = line.strip()
            if (stripped and set(stripped) == {fence.group(2)[0]}
                    and len(stripped) >= len(fence.group(2))):
                blocks.append(cur)
                cur = None
                continue
            indent = len(fence.group(1))
            if line[:indent].strip() == "":
                line = line[indent:]
            cur.lines.append((n, line))
    if cur is not None:
        blocks.append(cur)  # unclosed: Markdown runs it to the end
    return blocks


def shell_commands(block):
    """The block's commands: logical lines (continued with a trailing
    backslash) less blank and comment lines; in a console block only what
    follows a "$ " prompt."""
    cmds, cur, start = [], None, 0
    for n, line in block.lines:
        if cur is not None:
            if block.tag == "console" and line.startswith("> "):
                line = line[2:]
            cur.append(line)
        else:
            if block.tag == "console":
                if not line.startswith("$ "):
                    continue  # the command's output
                line = line[2:]
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            cur, start = [line], n
        if not line.endswith("\\"):
            cmds.append(Command(block.path, start, "\n".join(cur)))
            cur = None
    if cur is not None:
        cmds.append(Command(block.path, start, "\n".join(cur)))
    return cmds


def read_exempt(path):
    """[(line, regex, pattern, reason, doc or None)] and the errors of the file."""
    out, errors = [], []
    with open(path, encoding="utf-8") as f:
        for n, raw in enumerate(f, 1):
            line = raw.strip()
            if not line or line.startswith("#"):
                continue
            pattern, sep, reason = line.partition(" # ")
            pattern, reason = pattern.strip(), reason.strip()
            m = re.match(r"\[([^]]+)\]\s+", pattern)
            doc = os.path.normpath(m.group(1)) if m else None
            pattern = pattern[m.end():] if m else pattern
            if not sep or not reason:
                errors.append(f"{path}:{n}: exemption without a reason "
                              f"(PATTERN # REASON): {line}")
                continue
            try:
                out.append((n, re.compile(pattern), pattern, reason, doc))
            except re.error as e:
                errors.append(f"{path}:{n}: bad pattern {pattern!r}: {e}")
    return out, errors


def run_file(path, cmds, base, links, timeout):
    """Runs cmds (one file's, in order) in one bash in a fresh directory;
    returns {index: (status, seconds)} of those that ran, and the index of
    a command that timed out (or None)."""
    tag = re.sub(r"[^A-Za-z0-9]+", "_", os.path.relpath(path))
    work = tempfile.mkdtemp(prefix="work_" + tag + "_", dir=base)
    res = tempfile.mkdtemp(prefix="res_" + tag + "_", dir=base)
    for name, target in links:
        os.symlink(target, os.path.join(work, name))
    q = shlex.quote
    script = ["set -o pipefail", "cd " + q(work)]
    for i, c in enumerate(cmds):
        body = c.text
        if c.script is not None:
            py = os.path.join(res, f"{i}.py")
            with open(py, "w", encoding="utf-8") as f:
                f.write(c.script)
            body = "python3 " + q(py)
        out, err = q(os.path.join(res, f"{i}.out")), q(os.path.join(res, f"{i}.err"))
        script += [
            f"echo {i} start $EPOCHREALTIME >>{q(res)}/status",
            "{ " + body, "} </dev/null >" + out + " 2>" + err,
            f"__rc=$?; echo {i} $__rc $EPOCHREALTIME >>{q(res)}/status",
            "[ $__rc = 0 ] || exit 0"]
    proc = subprocess.Popen(["bash", "--noprofile", "--norc", "-c", "\n".join(script)],
                            stdin=subprocess.DEVNULL, start_new_session=True)
    timed_out = False
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        timed_out = True
    done, started, running = {}, {}, None
    try:
        with open(os.path.join(res, "status")) as f:
            for line in f:
                i, rc, t = line.split()
                if rc == "start":
                    started[int(i)], running = float(t), int(i)
                else:
                    done[int(i)] = (int(rc), float(t) - started[int(i)])
                    running = None
    except FileNotFoundError:
        pass
    return done, (running if timed_out else None), res


def tail(path, n=20):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except FileNotFoundError:
        return []
    return lines[-n:]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exempt", required=True, help="the exempt list")
    ap.add_argument("--link", action="append", default=[], metavar="NAME=PATH",
                    help="a symbolic link NAME -> PATH in every file's directory")
    ap.add_argument("--timeout", type=float, default=600,
                    help="seconds for one file's commands (default 600)")
    ap.add_argument("docs", nargs="+")
    a = ap.parse_args()
    links = []
    for spec in a.link:
        name, sep, target = spec.partition("=")
        if not sep or not name or "/" in name:
            ap.error(f"--link {spec}: want NAME=PATH")
        links.append((name, os.path.abspath(target)))

    problems = []
    exempt, errors = read_exempt(a.exempt)
    problems += errors
    used = set()
    per_file = []
    n_skipped = n_exempt = 0
    for path in a.docs:
        cmds = []
        for b in read_blocks(path):
            if b.tag in SHELL_TAGS:
                cmds += shell_commands(b)
            elif b.tag in PYTHON_TAGS:
                cmds.append(Command(path, b.line, "", "\n".join(t for _, t in b.lines) + "\n"))
            elif b.tag in NOT_COMMAND_TAGS:
                n_skipped += 1
            elif not b.tag:
                problems.append(f"{path}:{b.line}: code block without a language tag "
                                f"(commands: {', '.join(sorted(SHELL_TAGS | PYTHON_TAGS))}; "
                                f"others: {', '.join(sorted(NOT_COMMAND_TAGS))})")
            else:
                problems.append(f"{path}:{b.line}: code block tagged '{b.tag}': "
                                "neither a command language "
                                f"({', '.join(sorted(SHELL_TAGS | PYTHON_TAGS))}) nor one "
                                f"known not to be run ({', '.join(sorted(NOT_COMMAND_TAGS))})")
        to_run = []
        for c in cmds:
            hits = [e for e in exempt if e[1].search(c.shown)
                    and e[4] in (None, os.path.normpath(c.path))]
            used.update(e[0] for e in hits)
            if hits:
                n_exempt += 1
                print(f"exempt {c.path}:{c.line}: {c.shown}  [{a.exempt}:{hits[0][0]}: {hits[0][3]}]")
            else:
                to_run.append(c)
        per_file.append((path, to_run))

    n_ok = n_bad = 0
    with tempfile.TemporaryDirectory(prefix="doc_commands_") as base:
        for path, cmds in per_file:
            if not cmds:
                continue
            done, hung, res = run_file(path, cmds, base, links, a.timeout)
            for i, c in enumerate(cmds):
                if i in done and done[i][0] == 0:
                    n_ok += 1
                    print(f"ok {c.path}:{c.line} ({done[i][1]:.2f} s): {c.shown}")
                    continue
                n_bad += 1
                if i in done:
                    msg = [f"{c.path}:{c.line}: exit status {done[i][0]}: {c.shown}"]
                    err = tail(os.path.join(res, f"{i}.err")) or \
                        tail(os.path.join(res, f"{i}.out"))
                    msg += ["    " + l for l in err]
                elif i == hung:
                    msg = [f"{c.path}:{c.line}: still running after {a.timeout:g} s "
                           f"(the file's limit): {c.shown}"]
                else:
                    msg = [f"{c.path}:{c.line}: not run (an earlier command of "
                           f"{c.path} failed): {c.shown}"]
                problems.append("\n".join(msg))
    for n, _, pattern, _, _ in exempt:
        if n not in used:
            problems.append(f"{a.exempt}:{n}: stale exemption, matches no command: {pattern}")
    for p in problems:
        print("FAIL: " + p)
    print(f"{n_ok} commands run, {n_bad} failed or not run, {n_exempt} exempt, "
          f"{n_skipped} blocks not commands, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
