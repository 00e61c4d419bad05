"""Simulated measurements (prru_measure.h): a method of Model."""

import collections
import ctypes

from . import _convert, _lib, errors

Measurement = collections.namedtuple("Measurement", "t d fd window degree qdd_error default_error")
Measurement.__doc__ = """A simulated run as the sensors report it: the sample
times t, the slider readings d (rows of nact, quantised to the encoder
resolution) and the actuator forces fd (rows of nact, with noise). With the
run's exact qdd given: window and degree, the differentiation setting
(half-width M and degree P of identify's --window and --degree) whose qdd
from the readings is nearest the exact one, its error and the default
setting's (max over q1..q3 of RMS(error) / RMS(qdd)); else None."""


def _table(name, rows, width):
    """rows (a sequence of sequences of width numbers) as one flat ctypes
    array, row-major; TypeError/ValueError naming name and the row."""
    rows = _convert.ordered(name, rows, "a sequence of rows", ndim=2)
    flat = (ctypes.c_double * (len(rows) * width))()
    for r, row in enumerate(rows):
        v = _convert.vector("%s[%d]" % (name, r), row, width)
        ctypes.memmove(ctypes.byref(flat, r * width * 8), v, width * 8)
    return flat, len(rows)


def measure(self, t, d, fd, *, rate=0.0, d_resolution=0.0, force_noise=0.0, seed=1, qdd=None):
    """The sensors' view of a run: t (increasing, s), d and fd (one row of
    nact per time). rate (Hz, 0: every row) keeps the rows at t[0] + k /
    rate (each must exist); d_resolution (m, 0: exact) quantises d;
    force_noise (N, 0: none) adds Gaussian noise to fd from a generator
    seeded by seed (0 .. 2^32 - 1: the same seed gives the same numbers).
    qdd (rows of 3, the run's exact accelerations) also chooses the
    differentiation setting for identify. Returns a Measurement; InputError
    with the library's message for a rate off the run's clock."""
    n = self.nact
    tt = _convert.vector("t", _convert.ordered("t", t, "a sequence of times"), len(t))
    dd, nd = _table("d", d, n)
    ff, nf = _table("fd", fd, n)
    if not (len(tt) == nd == nf):
        raise ValueError("t, d and fd must have as many rows, got %d, %d and %d" % (len(tt), nd, nf))
    o = _lib._MeasureOptions(_convert.scalar("rate", rate, positive=True),
                             _convert.scalar("d_resolution", d_resolution, positive=True),
                             _convert.scalar("force_noise", force_noise, positive=True),
                             _convert.integer("seed", seed, 0))
    if o.seed != seed:
        raise ValueError("seed must be below 2^32 on this platform's unsigned long, got %d" % seed)
    lib, msg = self.lib, ctypes.create_string_buffer(600)
    idx, nout = (ctypes.c_int * max(len(tt), 1))(), ctypes.c_int()
    st = lib.measure_rows(tt, len(tt), ctypes.byref(o), idx, ctypes.byref(nout), msg, len(msg))
    if st != errors.OK:
        raise errors.make_error(st, "measure: " + msg.value.decode("utf-8", "replace"))
    k = nout.value
    ts = (ctypes.c_double * k)(*[tt[idx[i]] for i in range(k)])
    ds = (ctypes.c_double * (k * n))(*[dd[idx[i] * n + j] for i in range(k) for j in range(n)])
    fs = (ctypes.c_double * (k * n))(*[ff[idx[i] * n + j] for i in range(k) for j in range(n)])
    st = lib.measure_apply(ctypes.byref(o), k, n, ds, fs, msg, len(msg))
    if st != errors.OK:
        raise errors.make_error(st, "measure: " + msg.value.decode("utf-8", "replace"))
    window = degree = err = err_default = None
    if qdd is not None:
        aa, na = _table("qdd", qdd, 3)
        if na != len(tt):
            raise ValueError("qdd must have a row per time, got %d for %d" % (na, len(tt)))
        qs = (ctypes.c_double * (3 * k))(*[aa[idx[i] * 3 + j] for i in range(k) for j in range(3)])
        c = _lib._DiffChoice()
        st = lib.measure_best_diff(ctypes.byref(self._m), k, ts, ds, qs, ctypes.byref(c), msg, len(msg))
        if st != errors.OK:
            raise errors.make_error(st, "measure: " + msg.value.decode("utf-8", "replace"))
        window, degree = c.best.half_width, c.best.degree
        err, err_default = c.best_error, c.default_error
    out = self._out
    return Measurement(out.vec(ts), out.mat(ds, k, n), out.mat(fs, k, n), window, degree, err, err_default)
