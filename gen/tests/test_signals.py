"""Stopping the generator: a SIGTERM, SIGHUP or SIGINT at any moment
leaves the output directory with either the old files or the complete new
set, and no hidden temporary file; so does a failed write (a full disk),
which also leaves no directory it created; a model that assembles only
near full stretch is generated with a warning."""

import contextlib
import errno
import io
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

from prrugen import output
from tests.test_generator import ENTRY, MODEL as PAPER, OUTPUT_FILES, read_dir as listing


class AtomicWrites(unittest.TestCase):
    def setUp(self):
        self.saved = {s: signal.getsignal(s) for s in output.STOP_SIGNALS}
        output.handle_termination()
        self.dir = tempfile.mkdtemp()
        output.write_files_atomically(self.dir, {"a.c": "old a", "b.h": "old b"})
        self.new = {"a.c": "new a", "b.h": "new b"}

    def tearDown(self):
        for s, h in self.saved.items():
            signal.signal(s, h)
        for name in os.listdir(self.dir):
            os.unlink(os.path.join(self.dir, name))
        os.rmdir(self.dir)

    def _stop_on(self, target, call_no, signum):
        real = getattr(os, target)
        calls = [0]

        def hook(*args, **kwargs):
            calls[0] += 1
            if calls[0] == call_no:
                os.kill(os.getpid(), signum)
            return real(*args, **kwargs)
        return mock.patch.object(output.os, target, hook)

    def test_signal_while_writing_keeps_the_old_set(self):
        for signum, exc in ((signal.SIGTERM, output.Terminated),
                            (signal.SIGHUP, output.Terminated),
                            (signal.SIGINT, KeyboardInterrupt)):
            with self.subTest(signum=signum):
                with self._stop_on("chmod", 2, signum):
                    with self.assertRaises(exc):
                        output.write_files_atomically(self.dir, self.new)
                self.assertEqual(listing(self.dir),
                                 {"a.c": b"old a", "b.h": b"old b"})

    def test_signal_while_renaming_completes_the_new_set(self):
        with self._stop_on("replace", 1, signal.SIGTERM):
            with self.assertRaises(output.Terminated):
                output.write_files_atomically(self.dir, self.new)
        self.assertEqual(listing(self.dir), {"a.c": b"new a", "b.h": b"new b"})


class _FullDisk(io.StringIO):
    def write(self, text):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def full_disk():
    """Every file the writer opens fails its write with ENOSPC, as on a
    full file system (no small tmpfs needed)."""
    def fdopen(fd, *args, **kwargs):
        os.close(fd)
        return _FullDisk()
    return mock.patch.object(output.os, "fdopen", fdopen)


def tree(d):
    """Every path under d, directories and hidden files included."""
    return sorted(os.path.relpath(os.path.join(folder, n), d)
                  for folder, dirs, files in os.walk(d) for n in dirs + files)


class FailedWrites(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = self.tmp.name
        self.files = {"a.c": "new a", "b.h": "new b"}

    def tearDown(self):
        self.tmp.cleanup()

    def test_full_disk_leaves_no_directory_it_created(self):
        for out in ("out", os.path.join("new", "nested", "out")):
            with self.subTest(out), full_disk():
                with self.assertRaises(OSError) as ctx:
                    output.write_files_atomically(
                        os.path.join(self.root, out), self.files)
                self.assertEqual(ctx.exception.errno, errno.ENOSPC)
                self.assertEqual(tree(self.root), [])

    def test_full_disk_keeps_an_existing_directory_as_it_was(self):
        out = os.path.join(self.root, "parent", "out")
        output.write_files_atomically(out, {"a.c": "old a"})
        with full_disk(), self.assertRaises(OSError):
            output.write_files_atomically(out, self.files)
        self.assertEqual(tree(self.root), ["parent", "parent/out",
                                           "parent/out/a.c"])
        self.assertEqual(listing(out), {"a.c": b"old a"})
        # An existing empty directory stays too.
        os.unlink(os.path.join(out, "a.c"))
        with full_disk(), self.assertRaises(OSError):
            output.write_files_atomically(out, self.files)
        self.assertEqual(tree(self.root), ["parent", "parent/out"])

    def test_new_directory_is_complete_with_the_usual_mode(self):
        out = os.path.join(self.root, "a", "out")
        output.write_files_atomically(out, self.files)
        self.assertEqual(tree(self.root), ["a", "a/out", "a/out/a.c",
                                           "a/out/b.h"])
        mask = os.umask(0)
        os.umask(mask)
        self.assertEqual(os.stat(out).st_mode & 0o777, 0o777 & ~mask)

    def test_generator_on_a_full_disk(self):
        import prru_gen
        out = os.path.join(self.root, "gen", "out")
        err = io.StringIO()
        with full_disk(), contextlib.redirect_stderr(err), \
                mock.patch.object(prru_gen, "generate_model",
                                  lambda model, prefix, sets, types_header: (self.files, [])):
            rc = prru_gen.main([PAPER, "--out", out, "--quiet"])
        self.assertEqual(rc, 1)
        self.assertEqual(err.getvalue(), "prru_gen: error: %s: cannot write: "
                         "%s\n" % (out, os.strerror(errno.ENOSPC)))
        self.assertEqual(tree(self.root), [])


class KilledGenerator(unittest.TestCase):
    def test_sigterm_at_any_time_leaves_old_or_new_and_no_temp_file(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "out")
            os.makedirs(out)
            with open(os.path.join(out, "paper3prru_kernels.c"), "w") as f:
                f.write("old")
            old = listing(out)
            seen = set()
            for delay in (0.02, 0.08, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.7, 1.0):
                proc = subprocess.Popen([sys.executable, ENTRY, PAPER, "--out",
                                         out, "--quiet"],
                                        stderr=subprocess.PIPE, text=True)
                time.sleep(delay)
                proc.send_signal(signal.SIGTERM)
                _, err = proc.communicate(timeout=60)
                files = listing(out)
                self.assertFalse([n for n in files if n.startswith(".")],
                                 "temporary file left: %s" % sorted(files))
                # Whatever the moment: the old set, or the whole new one.
                whole = sorted(files) == OUTPUT_FILES and all(
                    v.startswith(b"/* GENERATED FILE") for v in files.values())
                self.assertTrue(files == old or whole, sorted(files))
                if proc.returncode == 128 + signal.SIGTERM:
                    # Stopped by the generator's own handler.
                    self.assertIn("stopped by signal", err)
                    seen.add("stopped")
                else:
                    # 0: finished first; -SIGTERM: killed before the handlers
                    # were installed or after they were dropped at exit.
                    self.assertIn(proc.returncode, (0, -signal.SIGTERM), err)
                self.assertNotIn("Traceback", err)
                old = files
            self.assertIn("stopped", seen, "no run was stopped by the handler")


class Warnings(unittest.TestCase):
    def test_near_full_stretch_is_generated_with_a_warning(self):
        with open(PAPER, encoding="utf-8") as f:
            m = json.load(f)
        # gap b3 - l2 = 0.224 m against l1 = 0.23 m: 97.4 % of full stretch
        m["geometry"]["b3"] = 0.449
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "stretched.json")
            with open(path, "w") as f:
                json.dump(m, f)
            r = subprocess.run([sys.executable, ENTRY, path, "--out",
                                os.path.join(d, "out"), "--quiet"],
                               capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("warning: %s: limb 3 is within 2.6%% of full stretch"
                      % path, r.stderr)
        self.assertEqual(r.stderr.count("\n"), 1)

    def test_paper_model_has_no_warning(self):
        with tempfile.TemporaryDirectory() as d:
            r = subprocess.run([sys.executable, ENTRY, PAPER, "--out", d,
                                "--quiet"], capture_output=True, text=True)
        self.assertEqual((r.returncode, r.stderr), (0, ""))


if __name__ == "__main__":
    unittest.main()
