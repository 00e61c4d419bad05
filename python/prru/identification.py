"""Identification: excitation trajectories and the physically consistent
model identified from measured motion and forces (prru_ident.h), as
`prru excite` and `prru identify` compute them. Methods of Model."""

import collections
import ctypes
import os
import tempfile

from . import _convert, _interrupt, _lib, errors
from .motion import Motion, _c_limits

def write_model_text(text, path):
    """A model file's text to path: a temporary file in the same
    directory, renamed into place (an existing file stays whole on
    failure)."""
    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".prru-", suffix=".json", dir=d)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


Excitation = collections.namedtuple(
    "Excitation", "motion period harmonics centre a b cond cond_start fd_peak rcond_worst evals shrunk "
                  "nbase limits")
Excitation.__doc__ = """Model.excite's result: motion (a Motion sampled every
dt over the periods; its fd is this model's inverse dynamics, to be
replaced by measured forces), the Fourier series (period s, harmonics L,
centre, a and b: 3 rows of L sine and cosine amplitudes), cond (the
condition number of the column-scaled base regressor it was optimised
for; cond_start the start's, inf if infeasible), fd_peak (N per actuator),
rcond_worst (J_d along it), evals, shrunk (times scaled by 0.95 to pass
the dense check), nbase and the limits kept."""

Parameter = collections.namedtuple("Parameter", "name estimate se prior model t")
Parameter.__doc__ = """One base parameter: its own standard parameter's
name, the least-squares estimate and standard error, the prior's value
(the model's numbers), the written model's value, and t = (model -
estimate) / se."""


class Identification:
    """Model.identify's result.

    Attributes: text (the identified model file, format 2; None when the
    data contradict physics), name, nsamples, nbase, sigma (residual
    standard deviation, N), cond (condition number of the column-scaled
    regressor), inflation (residual variance inflation, Newey-West),
    consistent ("exact": a consistent robot has the estimate's base
    parameters; "covariance": the consistent set nearest them), d2 and
    d2_max (the Mahalanobis distance^2 of the model's base parameters to
    the estimate and the chi^2 quantile that refuses), parameters (a list
    of Parameter). write(path) writes the model file.
    """

    def __init__(self, **kw):
        self.__dict__.update(kw)

    def write(self, path):
        """Writes the model file to path (write_model_text)."""
        if self.text is None:
            raise ValueError("no model to write: the data contradict physics")
        write_model_text(self.text, path)

    def __repr__(self):
        return "<prru.Identification %s: %d base parameters from %d samples, sigma %.4g N, %s>" % (
            self.name, self.nbase, self.nsamples, self.sigma, self.consistent)


def _base(model, vs, m=None):
    """The base parameters of model (or of m, a prru_model of its library:
    excite's, with the run's stroke) as prru identify and excite compute
    them: random states from seed 1, vs the model's by default."""
    lib, b = model.lib, model.lib.types.Base()
    m = model._m if m is None else m
    if vs is None:
        vs = lib.ident_default_vs(ctypes.byref(m))
    vs = _convert.scalar("coulomb_velocity", vs, positive=True, allow_zero=False)
    with model._lock:
        st = lib.base_compute(ctypes.byref(m), vs, 0, 1, ctypes.byref(b))
    if st != errors.OK:
        raise errors.make_error(st, "base parameters: %s" % lib.status_text(st))
    return b


def excite(self, *, period=None, harmonics=None, periods=None, dt=None, centre=None, amplitude=None,
           limits=None, rcond_min=None, evals=None, samples=None, seed=None, coulomb_velocity=None):
    """An excitation trajectory for identification (prru excite): each
    coordinate a Fourier series of harmonics harmonics about centre with
    the given period (s), its coefficients chosen (Nelder-Mead, seeded)
    for the smallest condition number of the base regressor over samples
    points a period, within amplitude (|q_k - c_k|; default 0.25 rad, 0.25
    rad, 0.1 L), J_d's rcond >= rcond_min, and the limits (a Limits;
    default the model's, with 500 N where it has no force limit), then
    checked at 20 times as many points. Sampled every dt over periods
    periods. An option left None is the library's default
    (prru_fourier_default, prru_excite_options_default: period 10 s, 5
    harmonics, centre 0, rcond_min 1e-2, 3000 evals, 100 samples, seed 1,
    dt 0.01 s, 1 period). Returns Excitation. Raises InputError for bad
    options or centre, NoConvergence when no feasible trajectory is
    found."""
    lib, t = self.lib, self.lib.types
    lim, c = _c_limits(self, limits)
    o = t.ExciteOptions()
    lib.excite_options_default(ctypes.byref(o))
    lib.excite_options_limits(ctypes.byref(o), ctypes.byref(c))
    f = _lib._Fourier()
    lib.fourier_default(ctypes.byref(f))
    if period is not None:
        f.period = _convert.scalar("period", period, positive=True, allow_zero=False)
    if harmonics is not None:
        f.harmonics = _convert.integer("harmonics", harmonics, 1)
    if f.harmonics > _lib.EXCITE_MAX_HARMONICS:
        raise ValueError("harmonics must be at most %d, got %d" % (_lib.EXCITE_MAX_HARMONICS, harmonics))
    if centre is not None:
        f.centre[:] = list(_convert.vector("centre", centre, 3))
    if amplitude is not None:
        amp = list(_convert.vector("amplitude", amplitude, 3))
        if not all(a > 0 for a in amp):
            raise ValueError("amplitude must be positive, got %r" % amp)
        o.amplitude_max[:] = amp
    if rcond_min is not None:
        o.rcond_min = _convert.scalar("rcond_min", rcond_min, positive=True, allow_zero=False)
    if not o.rcond_min < 1:
        raise ValueError("rcond_min must lie between 0 and 1, got %r" % rcond_min)
    if evals is not None:
        o.max_evals = _convert.integer("evals", evals, 1)
    if samples is not None:
        o.samples = _convert.integer("samples", samples, 1)
    if seed is not None:
        o.seed = _convert.integer("seed", seed, 0)
    if periods is not None:
        o.periods = _convert.integer("periods", periods, 1)
    if dt is not None:
        o.dt = _convert.scalar("dt", dt, positive=True, allow_zero=False)
    rows = lib.excite_rows(ctypes.byref(f), ctypes.byref(o))
    if rows == 0:
        run = f.period * o.periods
        raise ValueError("dt %g s is longer than the run (%g s)" % (o.dt, run) if o.dt > run
                         else "dt %g s gives more than 1e15 rows over the run (%g s)" % (o.dt, run))
    # The run's model: its stroke bounds the reach.
    m = _lib._Model()
    if lib.model_with_limits(ctypes.byref(m), ctypes.byref(self._m), ctypes.byref(c)) != errors.OK:
        raise errors.make_error(errors.ENOMEM, "excite: out of memory")
    try:
        b = _base(self, coulomb_velocity, m)
        r, msg, stop = t.ExciteResult(), ctypes.create_string_buffer(600), ctypes.c_int(0)
        with self._lock:
            st, interrupt = _interrupt.call_in_worker(
                lambda: lib.excite(ctypes.byref(m), ctypes.byref(b), ctypes.byref(o), ctypes.byref(stop),
                                   ctypes.byref(f), ctypes.byref(r), msg, len(msg)), stop, "prru excite")
        if interrupt is not None:
            raise interrupt
        if st != errors.OK:
            raise errors.make_error(st, "excite: " + (msg.value.decode("utf-8", "replace")
                                                      or lib.status_text(st)))
        motion = _excite_rows(self, m, f, rows, o.dt)
    finally:
        lib.model_free(ctypes.byref(m))
    L = f.harmonics
    return Excitation(motion, f.period, L, tuple(f.centre), tuple(tuple(f.a[k][:L]) for k in range(3)),
                      tuple(tuple(f.b[k][:L]) for k in range(3)), r.cond, r.cond_start, tuple(r.fd_peak[:self.nact]),
                      r.rcond_worst, r.evals, r.shrunk, b.nbase, lim)


def _excite_rows(model, m, f, rows, dt):
    """rows rows every dt (prru_excite_rows): q, qd, qdd of the series, d,
    dd and fd of the run's model (inverse dynamics, no loads)."""
    lib, n = model.lib, model.nact
    g = model.lib.new_data()
    cols = {k: [] for k in Motion._fields}
    q, qd, qdd = (ctypes.c_double * 3)(), (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
    fd, dd, ddb = (ctypes.c_double * n)(), (ctypes.c_double * n)(), (ctypes.c_double * n)()
    loads = lib.types.Loads()
    with model._lock:
        for i in range(rows):
            t = i * dt
            lib.fourier_eval(ctypes.byref(f), t, q, qd, qdd)
            st = lib.inverse_dynamics_preload(ctypes.byref(m), ctypes.byref(g.s), q, qd, qdd, ctypes.byref(loads),
                                              0.0, fd)
            if st != errors.OK:
                raise errors.make_error(st, "excite: t = %.9g s: %s" % (t, lib.status_text(st)))
            lib.model_actuator_rates(ctypes.byref(m), q, qd, dd, ddb)
            for key, v in (("t", t), ("q", list(q)), ("qd", list(qd)), ("qdd", list(qdd)),
                           ("d", g.s.d[:n]), ("dd", list(dd)), ("fd", list(fd))):
                cols[key].append(v)
    out, rows = model._out, len(cols["t"])
    return Motion(out.vec(cols["t"]), *(out.mat([x for r in cols[k] for x in r], rows, len(cols[k][0]))
                                         for k in Motion._fields[1:]))


def _rows(name, rows, n, width):
    rows = _convert.ordered(name, rows, "rows of %d numbers" % width, ndim=2)
    if len(rows) != n:
        raise ValueError("%s: %d rows for %d samples" % (name, len(rows), n))
    a = (ctypes.c_double * (width * max(n, 1)))()
    for k, r in enumerate(rows):
        a[width * k:width * k + width] = list(_convert.vector("%s[%d]" % (name, k), r, width))
    return a


def identify(self, t, q, qd, qdd, fd, *, name=None, coulomb_velocity=None):
    """The physically consistent model identified from n samples of
    measured motion and actuator forces (prru identify on exact rates): t
    (s), q, qd, qdd (rows of 3), fd (rows of nact, N). Least squares of
    the base parameters, then the standard parameters nearest this model's
    (the prior) among the physically consistent ones with the estimate's
    base parameters, or, where none has them, the consistent set nearest
    the estimate within its covariance. name: the model's name (default
    this model's name + "_id"). Returns Identification. Raises InputError
    naming the sample that is unreachable or singular or for too few
    samples; Singular when the motion does
    not excite every base parameter, or when the data contradict physics
    (no consistent robot within the covariance: a force sign, a gear
    ratio, a unit; .result then holds the fit without a model)."""
    lib, T = self.lib, self.lib.types
    tt = _convert.ordered("t", t, "a sequence of times")
    n = len(tt)
    tv = _convert.vector("t", tt, n)
    qa, qda, qdda = _rows("q", q, n, 3), _rows("qd", qd, n, 3), _rows("qdd", qdd, n, 3)
    fda = _rows("fd", fd, n, self.nact)
    if name is None:
        name = _convert.derived_name(self.lib, self.name, "_id")  # as prru identify
    b = _base(self, coulomb_velocity)
    out = T.Identification()
    desc = "Identified by prru.Model.identify from %d samples (prior: model %s)" % (n, self.name)
    with self._lock:
        st = lib.identify_model(ctypes.byref(self._m), ctypes.byref(b), n, qa, qda, qdda, fda, name.encode(),
                                desc.encode(), ctypes.byref(out))
    try:
        msg = "identify: " + out.msg.decode("utf-8", "replace")
        if st != errors.OK and out.stage == _lib.IDENTIFY_FIT:
            if out.bad >= 0:  # the time, which the library does not know
                msg = "identify: sample %d (t = %g): %s" % (out.bad + 1, tv[out.bad], lib.status_text(st))
            raise errors.make_error(errors.EINPUT if out.bad >= 0 else st, msg)
        if st != errors.OK and out.stage == _lib.IDENTIFY_CONSISTENT:
            raise errors.make_error(st, msg)
        r, c = out.fit, out.consistent
        params = [Parameter(lib.base_param_name(ctypes.byref(b), b.col[i]).decode(), r.beta[i], r.se[i],
                            out.prior[i], c.beta[i], c.t[i]) for i in range(b.nbase)]
        result = Identification(text=None, name=name, nsamples=r.nsamples, nbase=b.nbase, sigma=r.sigma,
                                cond=r.cond, inflation=r.inflation,
                                consistent="exact" if c.how == _lib.CONSISTENT_EXACT else "covariance",
                                d2=c.d2, d2_max=c.d2_max, parameters=params)
        if st != errors.OK:
            err = errors.make_error(st, msg)
            if out.stage == _lib.IDENTIFY_PHYSICS:
                err.result = result
            raise err
        result.text = ctypes.string_at(out.text).decode("utf-8")
    finally:
        lib.free(out.text)
    return result
