"""Writing generated files so that a failure never leaves a half-written or
mixed set behind: every file goes to a temporary name in its directory
first, and only when all are written are they renamed into place. A
directory that does not exist yet is built whole beside its final name and
renamed into place; a failure removes it and any parent this call created.

Signals: SIGINT raises KeyboardInterrupt and, once handle_termination() is
called, SIGTERM and SIGHUP raise Terminated, so the cleanup below runs for
them too; during the renames they are held back, so a stop leaves either
the old set or the new one. (SIGKILL cannot be caught: it may leave a
hidden `.<name>.XXXX` file or directory, never a mixed set of visible
ones.)
"""

import os
import signal
import sys
import tempfile

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived; .signum says which."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _raise_terminated(signum, _frame):
    raise Terminated(signum)


def handle_termination():
    """Make SIGTERM and SIGHUP raise Terminated (for command-line entry
    points; a library caller keeps its own handlers)."""
    for s in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(s, _raise_terminated)


def run_stoppable(prog, out, run):
    """run() for a command-line entry point writing to out: a stop by
    SIGINT, SIGTERM or SIGHUP becomes one message and exit 128 + signal."""
    handle_termination()
    try:
        return run()
    except (KeyboardInterrupt, Terminated) as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        print("%s: stopped by signal %d: %s left as it was" % (prog, signum, out),
              file=sys.stderr)
        return 128 + signum


def write_files_atomically(out_dir, files):
    """files: name -> text. Creates out_dir if missing: then the files are
    written into a hidden directory beside it, renamed to out_dir when all
    are written, and on failure nothing that this call created is left
    (no empty out_dir, nor the parents it had to create)."""
    created = _make_parents(out_dir)
    try:
        if os.path.isdir(out_dir):
            _replace_files(out_dir, files)
        else:
            _new_directory(out_dir, files)
    except BaseException:
        for d in reversed(created):
            try:
                os.rmdir(d)
            except OSError:
                pass  # someone else put something there meanwhile
        raise


def _make_parents(path):
    """Creates the missing directories above path; returns them, outermost
    first."""
    missing = []
    head = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(head):
        missing.append(head)
        head = os.path.dirname(head)
    created = []
    try:
        for d in reversed(missing):
            try:
                os.mkdir(d)
                created.append(d)
            except FileExistsError:
                if not os.path.isdir(d):
                    raise
    except BaseException:
        for d in reversed(created):
            os.rmdir(d)
        raise
    return created


def _stage(folder, files):
    """Writes files to hidden temporary names in folder; returns the list
    of (temporary path, final path). On failure removes what it wrote."""
    staged = []
    try:
        for name, text in sorted(files.items()):
            fd, tmp = tempfile.mkstemp(prefix="." + name + ".", dir=folder)
            staged.append((tmp, os.path.join(folder, name)))
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
            os.chmod(tmp, 0o644)
    except BaseException:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        raise
    return staged


def _replace_files(out_dir, files):
    staged = _stage(out_dir, files)
    try:
        held = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    except BaseException:
        for tmp, _ in staged:
            os.unlink(tmp)
        raise
    try:
        for tmp, final in staged:
            os.replace(tmp, final)
    finally:
        # A signal that arrived meanwhile is delivered here, after the set
        # is complete.
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _new_directory(out_dir, files):
    """out_dir, which does not exist, built as a hidden directory beside it
    and renamed into place once complete."""
    out_dir = os.path.abspath(out_dir)
    parent, base = os.path.split(out_dir)
    aside = tempfile.mkdtemp(prefix="." + base + ".", dir=parent)
    try:
        os.chmod(aside, 0o777 & ~_umask())  # as os.mkdir would make it
        staged = _stage(aside, files)
        for tmp, final in staged:
            os.rename(tmp, final)
        held = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
        try:
            os.rename(aside, out_dir)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
    except BaseException:
        if os.path.isdir(aside):
            for name in os.listdir(aside):
                os.unlink(os.path.join(aside, name))
            os.rmdir(aside)
        raise
