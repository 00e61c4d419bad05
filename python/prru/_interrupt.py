"""Ctrl-C during a long library call (simulate, map).

Python runs its SIGINT handler only in the main thread, between
bytecodes: while the main thread is inside a C call the handler waits for
the call to return or to call back into Python. Two ways round it:

call_in_worker (simulate): the C call runs in a worker thread (ctypes
releases the GIL during it) while the main thread waits in short joins,
where the handler runs at once; the exception it raises (KeyboardInterrupt,
or a program's own handler's) sets the int the library polls
(prru_sim_options.interrupt, read inside every right-hand-side
evaluation), so the library stops within one evaluation and the caller
gets the exception when it has.

SigintFlag (map): while the call runs, SIGINT sets the polled int
(prru_map_options.interrupt) instead of raising; the handler runs when the
library calls back into Python (its progress report) and the caller raises
KeyboardInterrupt afterwards.
"""

import ctypes
import signal
import threading

# How often the waiting main thread lets Python run a pending signal
# handler (it may also run as soon as the signal arrives; this bounds it).
POLL_SECONDS = 0.05


def call_in_worker(fn, flag, name="prru"):
    """(fn(), interrupt): fn, a library call that polls flag (a ctypes
    c_int) and stops soon after it turns non-zero, run in a worker thread
    while this thread waits. interrupt is the exception raised in this
    thread while it waited (a SIGINT handler's: KeyboardInterrupt by
    default), None if none was; on one, flag is set and fn is waited for
    (further exceptions then are dropped: fn's buffers and its callbacks'
    results stay valid until it returns). Outside the main thread, where
    no signal handler runs, fn() is simply called."""
    if threading.current_thread() is not threading.main_thread():
        return fn(), None
    result, failure, done = [], [], threading.Event()

    def work():
        try:
            result.append(fn())
        except BaseException as e:  # re-raised in the caller's thread
            failure.append(e)
        finally:
            done.set()
    # Waited for on an Event, not by Thread.join: a KeyboardInterrupt in
    # join can leave the thread marked as finished while it still runs
    # (CPython 3.11's Thread._wait_for_tstate_lock, interrupted, releases
    # the lock the running thread holds and marks it stopped).
    interrupt = None
    threading.Thread(target=work, name=name, daemon=True).start()
    try:
        while not done.wait(POLL_SECONDS):
            pass
    except BaseException as e:
        interrupt = e
        flag.value = 1
        while not done.is_set():
            try:
                done.wait(POLL_SECONDS)
            except BaseException:
                pass
    if failure:
        raise failure[0]
    return result[0], interrupt


class SigintFlag:
    """with SigintFlag() as f: pass f.pointer to the library; f.raised
    says whether SIGINT arrived. Only in the main thread, and only when
    SIGINT has Python's default handler (a program's own handler is left
    alone)."""

    def __init__(self):
        self.flag = ctypes.c_int(0)
        self.pointer = ctypes.pointer(self.flag)
        self._old = None

    def _handler(self, signum, frame):
        self.flag.value = 1

    def __enter__(self):
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
            self._old = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc):
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
        return False

    @property
    def raised(self):
        return self.flag.value != 0
