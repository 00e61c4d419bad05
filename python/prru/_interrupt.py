"""Ctrl-C during a long library call (simulate, map).

Python runs its SIGINT handler only between bytecodes, so during a C call
it runs inside the next ctypes callback; a KeyboardInterrupt raised there
could escape the callback's own handling (ctypes then prints it and goes
on). Instead, while a call runs, SIGINT sets the int the library polls
(prru_sim_options.interrupt, prru_map_options.interrupt): the library
stops cleanly and the caller raises KeyboardInterrupt afterwards.
"""

import ctypes
import signal
import threading


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
