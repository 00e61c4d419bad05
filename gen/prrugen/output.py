"""Writing generated files so that a failure never leaves a half-written or
mixed set behind: every file goes to a temporary name in its directory
first, and only when all are written are they renamed into place.

Signals: SIGINT raises KeyboardInterrupt and, once handle_termination() is
called, SIGTERM and SIGHUP raise Terminated, so the cleanup below runs for
them too; during the renames they are held back, so a stop leaves either
the old set or the new one. (SIGKILL cannot be caught: it may leave a
hidden `.<name>.XXXX` file, never a mixed set of visible ones.)
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
    """files: name -> text. Creates out_dir if missing."""
    os.makedirs(out_dir, exist_ok=True)
    staged = []
    try:
        for name, text in sorted(files.items()):
            fd, tmp = tempfile.mkstemp(prefix="." + name + ".", dir=out_dir)
            staged.append((tmp, os.path.join(out_dir, name)))
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
            os.chmod(tmp, 0o644)
        held = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    except BaseException:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        raise
    try:
        for tmp, final in staged:
            os.replace(tmp, final)
    finally:
        # A signal that arrived meanwhile is delivered here, after the set
        # is complete.
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
