"""Simulation: scenarios (initial state, loads, integrator settings),
prru_simulate, and the samples it returns.

These functions are methods of Model (model.simulate(...)); they are kept
here so that model.py stays about single-state calls.
"""

import collections
import ctypes
import dataclasses
import math
import os
from typing import Optional, Sequence, Tuple

from . import _convert, _interrupt, _lib, errors
from ._convert import optional_vector, vector


@dataclasses.dataclass(frozen=True)
class Scenario:
    """One simulation's settings (the library's scenario, key = value files).

    q0, qd0: initial state (rad, rad, m and their rates); fd (N, one per
    actuator), fp (N), mp (N m): constant loads, fd on the sliders, fp and
    mp on the platform at O' in {S}; harmonic: (amplitude N, angular
    frequency rad/s) adds amp (sin wt, -cos wt, 0) to fp (the paper's
    load); table: rows (t, fd1..fdN[, fp1..3[, mp1..3]]) added to the
    constant loads, interpolated linearly in t and held outside; t_end,
    dt: duration and sample interval (s); stepper: rk8pd, rkf45, rkck or
    msbdf; atol, rtol: tolerances (0, or at least 100 DBL_EPSILON); h0:
    first step (s); max_steps: integrator steps allowed between two samples
    (0: the library's default).
    None for fd means zeros, for q0, qd0, fp, mp likewise.
    """
    q0: Sequence[float] = (0.0, 0.0, 0.0)
    qd0: Sequence[float] = (0.0, 0.0, 0.0)
    fd: Optional[Sequence[float]] = None
    fp: Sequence[float] = (0.0, 0.0, 0.0)
    mp: Sequence[float] = (0.0, 0.0, 0.0)
    harmonic: Optional[Tuple[float, float]] = None
    table: Optional[Sequence[Sequence[float]]] = None
    t_end: float = 1.0
    dt: float = 1e-3
    stepper: str = "rk8pd"
    atol: float = 1e-10
    rtol: float = 1e-10
    h0: float = 1e-4
    max_steps: int = 0


Sample = collections.namedtuple("Sample", "t q qd qdd d lambda_ T V")
Sample.__doc__ = """One sample handed to simulate's on_sample callback: time
(s), q, qd, qdd, slider heights d, reactions lambda_ (NaN unless
reactions=True), kinetic and potential energy T, V (J). Plain tuples."""


class Trajectory:
    """The samples of a simulation, at t = 0, dt, 2 dt, ..., t_end.

    Attributes (lists of per-sample values, or NumPy arrays of shape (n,)
    and (n, k) for a model with numpy=True): t, q, qd, qdd, d, T, V, and
    lambda_ (per-sample reactions; None unless simulate(reactions=True)).
    t_stop: the time of the last sample; stopped: True when on_sample
    stopped the run. len() is the number of samples.
    """

    def __init__(self, model, raw, nrows, reactions, stopped):
        t, out = model.lib.types, model._out
        flat = memoryview(raw).cast("d")
        for name, (start, count) in t.sample_columns.items():
            value = out.columns(flat, t.sample_width, start, count, nrows)
            setattr(self, "lambda_" if name == "lambda" else name, value)
        if not reactions:
            self.lambda_ = None
        self.t_stop = self.t[-1] if nrows else None
        self.stopped = stopped
        self._n = nrows

    def __len__(self):
        return self._n

    def __repr__(self):
        return "<prru.Trajectory %d samples, t_stop %s>" % (self._n, self.t_stop)


def _scenario_from_c(model, s):
    """A Scenario from the library's prru_scenario."""
    n = model.nact
    harmonic = (s.loads.amp, s.loads.omega) if s.loads.kind == _lib.LOAD_HARMONIC else None
    table = None
    if s.loads.kind == _lib.LOAD_TABLE:
        w = n + 7
        table = tuple(tuple(s.loads.rows[r * w + k] for k in range(w))
                      for r in range(s.loads.nrows))
    o = s.opt
    return Scenario(q0=tuple(s.q0), qd0=tuple(s.qd0), fd=tuple(s.loads.base.fd[:n]),
                    fp=tuple(s.loads.base.fp), mp=tuple(s.loads.base.mp), harmonic=harmonic,
                    table=table, t_end=o.t_end, dt=o.dt_out, stepper=_lib.STEPPERS[o.stepper],
                    atol=o.abs_tol, rtol=o.rel_tol, h0=o.h0, max_steps=o.max_steps)


def paper_scenario(self):
    """The paper's section 4.3 study as a Scenario: q0 = (0, pi/6, -0.8),
    fd = (50, 40, 25) N (a fourth actuator gets limb 3's 25 N), the
    harmonic platform force 50 (sin 4 pi t, -cos 4 pi t, 0) N, 1 s sampled
    every 1 ms, rk8pd at 1e-10 (read from the library)."""
    g = self.lib.types.GuardedScenario()
    self.lib.scenario_paper(ctypes.byref(g.s))
    try:
        return _scenario_from_c(self, g.s)
    finally:
        self.lib.scenario_free(ctypes.byref(g.s))


def read_scenario(self, path):
    """A scenario file (key = value lines: q0 qd0 fd fp mp harmonic loads
    t_end dt stepper atol rtol h0 max_steps; a loads CSV is read relative
    to the file) as a Scenario. Raises ParseError or PrruIOError with the
    library's message (file:line: reason)."""
    g = self.lib.types.GuardedScenario()
    msg = ctypes.create_string_buffer(512)
    st = self.lib.scenario_read(ctypes.byref(self._m), ctypes.byref(g.s), os.fsencode(path), msg,
                                len(msg))
    try:
        if st != errors.OK:
            raise errors.make_error(st, msg.value.decode("utf-8", "replace")
                                    or "%s: %s" % (path, self.lib.status_text(st)))
        return _scenario_from_c(self, g.s)
    finally:
        self.lib.scenario_free(ctypes.byref(g.s))


def _table_rows(rows, nact):
    """Table rows as one flat ctypes array of nrows * (nact + 7) doubles."""
    w = nact + 7
    layout = "(t, fd1..fd%d[, fp1..3[, mp1..3]])" % nact
    rows = _convert.ordered("table", rows, "a sequence of rows " + layout, ndim=2)
    if len(rows) == 0:
        raise ValueError("table must be a non-empty sequence of rows " + layout)
    flat = (ctypes.c_double * (w * len(rows)))()
    prev = -math.inf
    for r, row in enumerate(rows):
        row = _convert.ordered("table[%d]" % r, row, "a sequence of numbers " + layout)
        n = len(row)
        if n not in (1 + nact, 4 + nact, w):
            raise ValueError("table[%d] must have %d, %d or %d numbers %s, got %d"
                             % (r, 1 + nact, 4 + nact, w, layout, n))
        v = vector("table[%d]" % r, row, n)
        if not v[0] > prev:
            raise ValueError("table[%d]: times must increase strictly (t = %r after %r)"
                             % (r, v[0], prev))
        prev = v[0]
        flat[r * w:r * w + n] = list(v)
    return flat


def _schedule(model, sc):
    t = model.lib.types
    s = t.Schedule()
    s.base.fd[:model.nact] = list(optional_vector("fd", sc.fd, model.nact))
    s.base.fp[:] = list(optional_vector("fp", sc.fp, 3))
    s.base.mp[:] = list(optional_vector("mp", sc.mp, 3))
    s.kind, keep = _lib.LOAD_CONSTANT, None
    if sc.harmonic is not None and sc.table is not None:
        raise ValueError("harmonic and table loads cannot be combined")
    if sc.harmonic is not None:
        amp, omega = vector("harmonic", sc.harmonic, 2)
        s.kind, s.amp, s.omega = _lib.LOAD_HARMONIC, amp, omega
    elif sc.table is not None:
        keep = _table_rows(sc.table, model.nact)
        s.kind, s.nact, s.nrows = _lib.LOAD_TABLE, model.nact, len(sc.table)
        s.rows = ctypes.cast(keep, _lib.c_double_p)
    return s, keep


def _options(model, sc, schedule, reactions):
    t = model.lib.types
    o = t.SimOptions()
    model.lib.sim_options_default(ctypes.byref(o))
    if sc.stepper not in _lib.STEPPERS:
        raise ValueError("stepper must be one of %s, got %r" % (", ".join(_lib.STEPPERS),
                                                                sc.stepper))
    o.stepper = _lib.STEPPERS.index(sc.stepper)
    o.t_end = _convert.scalar("t_end", sc.t_end, positive=True, allow_zero=False)
    o.dt_out = _convert.scalar("dt", sc.dt, positive=True, allow_zero=False)
    o.abs_tol = _convert.scalar("atol", sc.atol, positive=True)
    o.rel_tol = _convert.scalar("rtol", sc.rtol, positive=True)
    o.h0 = _convert.scalar("h0", sc.h0, positive=True, allow_zero=False)
    o.max_steps = _convert.integer("max_steps", sc.max_steps, 0)
    o.reactions = 1 if reactions else 0
    o.loads = ctypes.pointer(schedule)
    return o


class _Collector:
    """The sample consumer: copies every sample's bytes, checks the first
    against the initial state (the layout of prru_sample), calls the
    user's callback and stops the run when it asks or raises."""

    def __init__(self, model, q0, qd0, on_sample, reactions):
        self.model, self.q0, self.qd0 = model, list(q0), list(qd0)
        self.on_sample, self.reactions = on_sample, reactions
        self.size = ctypes.sizeof(model.lib.types.Sample)
        self.chunks, self.stopped, self.error = [], False, None
        self.fn = model.lib.types.SampleFn(self._consume)

    def _first_ok(self, s):
        T, V = self.model.energy(self.q0, self.qd0)
        d, _ = self.model.ik(self.q0)
        return (s.t == 0.0 and list(s.q) == self.q0 and list(s.qd) == self.qd0
                and s.d[:self.model.nact] == list(d) and s.T == T and s.V == V)

    def _consume(self, ptr, ctx):
        try:
            s = ptr.contents
            if not self.chunks and not self._first_ok(s):
                raise self.model.lib._layout_error("prru_sample")
            self.chunks.append(ctypes.string_at(ptr, self.size))
            if self.on_sample is not None:
                lam = tuple(s.lambda_[:self.model.nlambda]) if self.reactions else None
                if self.on_sample(Sample(s.t, tuple(s.q), tuple(s.qd), tuple(s.qdd),
                                         tuple(s.d[:self.model.nact]), lam, s.T, s.V)):
                    self.stopped = True
                    return 1
            return 0
        except BaseException as e:  # stop; simulate re-raises it after the call
            self.error = e
            return 1


def simulate(self, q0=None, qd0=None, *, scenario=None, reactions=False, on_sample=None,
             **settings):
    """Integrates the equations of motion; returns a Trajectory.

    simulate(q0, qd0=None, *, scenario=None, reactions=False,
             on_sample=None, **settings)

    scenario: a Scenario (model.paper_scenario(), model.read_scenario(path))
    or "paper"; default Scenario(). q0, qd0 and the keyword settings
    (fd, fp, mp, harmonic, table, t_end, dt, stepper, atol, rtol, h0,
    max_steps; see Scenario) replace the scenario's.
    reactions: also compute the joint reactions of every sample (lambda_).
    on_sample(sample): called with every Sample as it is computed; a true
    return value stops the run (the Trajectory then has stopped = True);
    an exception it raises stops the run and is re-raised. Ctrl-C stops
    the run at once, also in the middle of a long sample interval (the
    library polls a flag inside every right-hand-side evaluation), with
    KeyboardInterrupt (or whatever a program's own SIGINT handler raises).
    Either exception carries .trajectory, the samples delivered until then,
    and .t_stop, the time of the last one. Called from the main thread,
    the integration and on_sample run in a worker thread while the main
    thread waits, where Python can run its SIGINT handler.

    When the state leaves the workspace or the integrator fails, raises
    Unreachable, Singular or NoConvergence with the library's message;
    the exception's .trajectory holds every sample computed until then.
    """
    if scenario is None:
        scenario = Scenario()
    elif isinstance(scenario, str) and scenario == "paper":
        scenario = self.paper_scenario()
    elif not isinstance(scenario, Scenario):
        raise TypeError("scenario must be a prru.Scenario or \"paper\", got %s"
                        % type(scenario).__name__)
    fields = {f.name for f in dataclasses.fields(Scenario)}
    unknown = sorted(set(settings) - fields)
    if unknown:
        raise TypeError("simulate: unknown setting(s) %s (settings: %s)"
                        % (", ".join(unknown), ", ".join(sorted(fields - {"q0", "qd0"}))))
    if q0 is not None:
        settings["q0"] = q0
    if qd0 is not None:
        settings["qd0"] = qd0
    sc = dataclasses.replace(scenario, **{k: v for k, v in settings.items() if v is not None})
    if on_sample is not None and not callable(on_sample):
        raise TypeError("on_sample must be callable")
    q0, qd0 = vector("q0", sc.q0, 3), vector("qd0", sc.qd0, 3)
    schedule, keep = _schedule(self, sc)
    opts = _options(self, sc, schedule, reactions)
    col = _Collector(self, q0, qd0, on_sample, reactions)
    opts.on_sample = col.fn
    t_stop, msg = ctypes.c_double(math.nan), ctypes.create_string_buffer(512)
    # Polled by the library inside every right-hand-side evaluation: set
    # on Ctrl-C, it stops the run in the middle of a long sample interval.
    stop = ctypes.c_int(0)
    opts.interrupt = ctypes.pointer(stop)
    st, interrupt = _interrupt.call_in_worker(
        lambda: self.lib.simulate(ctypes.byref(self._m), q0, qd0, ctypes.byref(opts),
                                  ctypes.byref(t_stop), msg, len(msg)),
        stop, "prru simulate")
    del keep  # the table rows stayed alive for the call
    traj = Trajectory(self, b"".join(col.chunks), len(col.chunks), reactions, col.stopped)
    if interrupt is not None and col.error is None:
        col.error = interrupt
    if col.error is not None:
        try:
            col.error.trajectory, col.error.t_stop = traj, traj.t_stop
        except AttributeError:
            pass
        raise col.error
    if st != errors.OK and not col.stopped:
        err = errors.make_error(st, "simulate: " + (msg.value.decode("utf-8", "replace")
                                                    or self.lib.status_text(st)))
        err.trajectory, err.t_stop = traj, traj.t_stop
        raise err
    return traj
