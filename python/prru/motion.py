"""Motion: the drives' limits, point-to-point quintics, time-optimal
profiles under the limits (TOPP-RA) and computed-torque tracking, as the
library plans and checks them (prru_traj.h, prru_control.h). Methods of
Model, like `prru traj` and `prru track` on the command line."""

import collections
import ctypes
import math
import numbers
import re

from . import _convert, _interrupt, _lib, errors

Limits = collections.namedtuple("Limits", "force_max speed_max stroke")
Limits.__doc__ = """The drives' limits, per actuator: rail force |fd_i| <=
force_max[i] (N), slider speed |dd_i| <= speed_max[i] (m/s), slider
position stroke[i][0] <= d_i <= stroke[i][1] (m); math.inf (and -math.inf
for a stroke's lower end) where there is none. Tuples."""

Motion = collections.namedtuple("Motion", "t q qd qdd d dd fd")
Motion.__doc__ = """A planned motion sampled in time: t (s); q, qd, qdd
(rows of 3); the sliders' positions d and speeds dd and the actuator
forces fd of inverse dynamics without platform loads (rows of nact;
minimum-norm forces with four actuators)."""

TimeOptimal = collections.namedtuple(
    "TimeOptimal", "motion duration active_fraction iterations quintic_durations limits grid")
TimeOptimal.__doc__ = """Model.time_optimal's result: motion (a Motion, every
row checked against the limits), duration (s), active_fraction (the share
of grid intervals with a limit within 1e-3 of its bound), iterations (the
planner's passes), quintic_durations (per segment, the fastest uniformly
time-scaled quintic within the same limits: the baseline), limits (the
Limits applied) and grid (intervals per segment)."""

TrackRun = collections.namedtuple(
    "TrackRun", "t q_ref q e qd fd fd_cmd saturated d qdd dd summary")
TrackRun.__doc__ = """Model.track's result, one row per sample: t; the
reference q_ref, the plant's q, the error e = q_ref - q, qd (rows of 3);
the applied forces fd, the controller's unclipped fd_cmd, saturated (0/1),
slider positions d and speeds dd (rows of nact); the plant's qdd under fd
(rows of 3: with q, qd and fd exact identification data). summary: a dict
with samples, t_end, rms_error, max_error (per coordinate), max_fd,
saturated_fraction, max_dd (per actuator), any_saturated_fraction,
over_speed_fraction (samples with a slider above its speed_max),
feedforward_peak (the largest |fd| of inverse dynamics along the
reference) and limits."""

def _limit_values(name, value, n, positive=True):
    """A limit for every actuator (one number) or one each (a sequence of
    n): a tuple of n floats, each > 0 with positive (math.inf: none);
    NaN refused, ValueError/TypeError naming name."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        value = [value] * n
    items = _convert.ordered(name, value, "a number or a sequence of %d numbers" % n)
    if len(items) != n:
        raise ValueError("%s must have %d elements, got %d" % (name, n, len(items)))
    out = []
    for i, v in enumerate(items):
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or math.isnan(v):
            raise (TypeError if not isinstance(v, numbers.Real) or isinstance(v, bool) else ValueError)(
                "%s[%d] must be a number, got %r" % (name, i, v))
        if positive and not v > 0:
            raise ValueError("%s[%d] must be > 0 (math.inf: no limit), got %r" % (name, i, v))
        out.append(float(v))
    return tuple(out)


def limits(self, *, force_max=None, speed_max=None, stroke=None, model_limits=True):
    """The limits a motion applies: the model file's (spec section 13;
    torque_max and motor_speed_max converted to the rail through lead and
    gear), or none with model_limits=False; then each one given replaces
    that kind for every actuator: force_max (N) and speed_max (m/s), one
    number or one per actuator; stroke (m) a pair (lo, hi) or one pair per
    actuator. Returns Limits."""
    n, lib = self.nact, self.lib
    c = lib.types.Limits()
    if model_limits:
        lib.model_limits(ctypes.byref(self._m), ctypes.byref(c))
    else:
        lib.limits_none(ctypes.byref(c))
    f, v = tuple(c.force_max[:n]), tuple(c.speed_max[:n])
    s = tuple(zip(c.d_min[:n], c.d_max[:n]))
    if force_max is not None:
        f = _limit_values("force_max", force_max, n)
    if speed_max is not None:
        v = _limit_values("speed_max", speed_max, n)
    if stroke is not None:
        pairs = _convert.ordered("stroke", stroke, "a pair (lo, hi) or one pair per actuator")
        if len(pairs) == 2 and all(isinstance(x, numbers.Real) for x in pairs):
            pairs = [pairs] * n
        if len(pairs) != n:
            raise ValueError("stroke must be a pair (lo, hi) or %d pairs, got %d items" % (n, len(pairs)))
        s = []
        for i, p in enumerate(pairs):
            lo, hi = _limit_values("stroke[%d]" % i, p, 2, positive=False)
            if not lo < hi:
                raise ValueError("stroke[%d]: slider %d's range [%r, %r] is empty" % (i, i + 1, lo, hi))
            s.append((lo, hi))
        s = tuple(s)
    return Limits(f, v, s)


def _c_limits(model, lim):
    if lim is None:
        lim = model.limits()
    if not isinstance(lim, Limits):
        raise TypeError("limits must be a prru.Limits (Model.limits()), got %s" % type(lim).__name__)
    n, c = model.nact, model.lib.types.Limits()
    c.force_max[:n] = list(_limit_values("limits.force_max", lim.force_max, n))
    c.speed_max[:n] = list(_limit_values("limits.speed_max", lim.speed_max, n))
    if len(lim.stroke) != n:
        raise ValueError("limits.stroke must have %d pairs, got %d" % (n, len(lim.stroke)))
    for i, p in enumerate(lim.stroke):
        c.d_min[i], c.d_max[i] = _limit_values("limits.stroke[%d]" % i, p, 2, positive=False)
    return lim, c


def _waypoints(q):
    rows = _convert.ordered("waypoints", q, "a sequence of poses (q1, q2, q3)", ndim=2)
    if len(rows) < 2:
        raise ValueError("waypoints: at least 2 poses, got %d" % len(rows))
    flat = (ctypes.c_double * (3 * len(rows)))()
    for k, row in enumerate(rows):
        flat[3 * k:3 * k + 3] = list(_convert.vector("waypoints[%d]" % k, row, 3))
    return flat, len(rows)


def _fail(model, st, what, msg):
    return errors.make_error(st, "%s: %s" % (what, msg.value.decode("utf-8", "replace")
                                             or model.lib.status_text(st)))


def _row_times(lib, t0, t1, dt):
    """t0, t0 + dt, ... and t1: the library's rows (prru_row_count,
    prru_row_time), as prru traj writes them."""
    rows = lib.row_count(t0, t1, dt)
    if rows == 0:
        raise ValueError("dt: more than 1e8 rows (span %g s, dt %g s)" % (t1 - t0, dt))
    return [lib.row_time(t0, t1, dt, k, rows) for k in range(rows)]


class _Rows:
    """Motion rows: q, qd, qdd from a time law, the sliders and the forces
    of inverse dynamics from the library, the path's poses checked (usable,
    on one side of the singular set)."""

    def __init__(self, model, what):
        self.model, self.what = model, what
        self.cols = {k: [] for k in Motion._fields}
        self.side = _lib._PathSide()
        model.lib.path_side_init(ctypes.byref(self.side))
        self.none = model.lib.types.Limits()
        model.lib.limits_none(ctypes.byref(self.none))

    def add(self, t, q, qd, qdd):
        """One row of a time law: the pose checked, the sliders' positions
        and speeds, the forces of inverse dynamics."""
        m, lib, n = self.model, self.model.lib, self.model.nact
        g, rc, crossed = m._g, ctypes.c_double(), ctypes.c_int()
        st = lib.path_sample(ctypes.byref(self.side), ctypes.byref(m._m), ctypes.byref(g.s), q,
                             ctypes.byref(rc), ctypes.byref(crossed))
        k = len(self.cols["t"]) + 1
        where = "%s: sample %d (t = %.9g s): q = (%.9g, %.9g, %.9g)" % (self.what, k, t, *q)
        if crossed.value:
            raise errors.make_error(errors.ESINGULAR, where + ": the path crosses a singularity "
                                    "(det J_d changes sign) since the previous sample")
        if st != errors.OK:
            raise errors.make_error(st, "%s: %s" % (where, lib.status_text(st)))
        d = g.s.d[:n]
        fd, dd = (ctypes.c_double * n)(), (ctypes.c_double * n)()
        st = lib.limits_ratio(ctypes.byref(m._m), ctypes.byref(g.s), ctypes.byref(self.none), q, qd, qdd, fd, dd,
                              None, None, None)
        if st != errors.OK:
            raise errors.make_error(st, "%s: inverse dynamics: %s" % (where, lib.status_text(st)))
        # The kernels' slider rates, as prru traj writes them.
        lib.model_actuator_rates(ctypes.byref(m._m), q, qd, dd, (ctypes.c_double * n)())
        self.record(t, q, qd, qdd, d, dd, fd)

    def record(self, t, q, qd, qdd, d, dd, fd):
        for key, v in (("t", t), ("q", list(q)), ("qd", list(qd)), ("qdd", list(qdd)), ("d", list(d)),
                       ("dd", list(dd)), ("fd", list(fd))):
            self.cols[key].append(v)

    def motion(self):
        out, c = self.model._out, self.cols
        n = len(c["t"])
        return Motion(out.vec(c["t"]), *(out.mat([x for r in c[k] for x in r], n, len(c[k][0]))
                                         for k in Motion._fields[1:]))


def quintic(self, waypoints, durations, *, dt=1e-3):
    """The point-to-point quintic trajectory (prru traj): straight lines in
    q from waypoint to waypoint, at rest at each, segment k taking
    durations[k] s with s = 10 u^3 - 15 u^4 + 6 u^5; sampled every dt (the
    last row at the end). Returns a Motion. Raises InputError for bad
    waypoints or durations, Unreachable or Singular naming the first
    sample outside the workspace, at a singularity or across one."""
    q, n = _waypoints(waypoints)
    dur = _convert.vector("durations", _convert.ordered("durations", durations, "a sequence of seconds"),
                          n - 1)
    dt = _convert.scalar("dt", dt, positive=True, allow_zero=False)
    lib, tr, msg = self.lib, _lib._Quintic(), ctypes.create_string_buffer(600)
    st = lib.quintic_waypoints(ctypes.byref(tr), n, q, dur, 0.0, msg, len(msg))
    if st != errors.OK:
        raise _fail(self, st, "quintic", msg)
    try:
        rows = _Rows(self, "quintic")
        a, b, c = (ctypes.c_double * 3)(), (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        with self._lock:
            for t in _row_times(lib, lib.quintic_t_begin(ctypes.byref(tr)), lib.quintic_t_end(ctypes.byref(tr)), dt):
                lib.quintic_eval(ctypes.byref(tr), t, a, b, c)
                rows.add(t, a, b, c)
        return rows.motion()
    finally:
        lib.quintic_free(ctypes.byref(tr))


def time_optimal(self, waypoints, *, limits=None, grid=0, dt=1e-3):
    """The fastest motion along the quintic's path (straight lines in q,
    at rest at every waypoint) within limits (a Limits; default the
    model's own, Model.limits()): reachability analysis (TOPP-RA) on grid
    intervals per segment (0: the library's 400), as prru traj
    --time-optimal. Sampled every dt (the last row at the end), every row
    checked again with the exact inverse dynamics. Returns TimeOptimal.
    Raises InputError naming the first infeasible grid point and limit
    (a static load above force_max, a pose outside the stroke or the
    workspace), NoConvergence if the planner does not settle or a row
    exceeds a limit by more than 1e-6 of it (PRRU_TOPP_ROW_TOL) or leaves
    the stroke."""
    q, n = _waypoints(waypoints)
    lim, c = _c_limits(self, limits)
    grid = _convert.integer("grid", grid, 0)
    dt = _convert.scalar("dt", dt, positive=True, allow_zero=False)
    lib, tp, msg = self.lib, _lib._Topp(), ctypes.create_string_buffer(600)
    with self._lock:
        st = lib.topp_solve(ctypes.byref(tp), ctypes.byref(self._m), n, q, ctypes.byref(c), grid, msg,
                            len(msg))
    if st != errors.OK:
        lib.topp_free(ctypes.byref(tp))
        raise _fail(self, st, "time_optimal", msg)
    try:
        durs = (ctypes.c_double * (n - 1))()
        with self._lock:
            st = lib.quintic_fastest(ctypes.byref(self._m), n, q, ctypes.byref(c), 2000, durs, msg,
                                     len(msg))
        if st != errors.OK:
            raise _fail(self, st, "time_optimal: the fastest scaled quintic", msg)
        rows, n = _Rows(self, "time_optimal"), self.nact
        a, b, cc = (ctypes.c_double * 3)(), (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        fd, dd, g = (ctypes.c_double * n)(), (ctypes.c_double * n)(), self._g
        with self._lock:
            for t in _row_times(lib, 0.0, tp.duration, dt):
                # Each row checked again with the exact inverse dynamics
                # (prru_topp_row, as prru traj --time-optimal's).
                st = lib.topp_row(ctypes.byref(self._m), ctypes.byref(g.s), ctypes.byref(c), ctypes.byref(tp),
                                  t, a, b, cc, fd, dd, msg, len(msg))
                if st != errors.OK:
                    raise _fail(self, st, "time_optimal", msg)
                rows.record(t, a, b, cc, g.s.d[:n], dd, fd)
        return TimeOptimal(rows.motion(), tp.duration, tp.active_fraction, tp.iterations,
                           tuple(durs), lim, tp.grid)
    finally:
        lib.topp_free(ctypes.byref(tp))


def _reference(model, ref):
    """A Motion, or (t, q, qd, qdd): the C2 quintic through its rows."""
    if isinstance(ref, Motion):
        t, q, qd, qdd = ref.t, ref.q, ref.qd, ref.qdd
    else:
        parts = _convert.ordered("reference", ref, "a Motion or (t, q, qd, qdd)")
        if len(parts) != 4:
            raise ValueError("reference must be a Motion or (t, q, qd, qdd), got %d items" % len(parts))
        t, q, qd, qdd = parts
    tt = _convert.ordered("reference t", t, "a sequence of times")
    n = len(tt)
    tv = _convert.vector("reference t", tt, n)
    flat = []
    for name, rows in (("q", q), ("qd", qd), ("qdd", qdd)):
        rows = _convert.ordered("reference " + name, rows, "rows of 3", ndim=2)
        if len(rows) != n:
            raise ValueError("reference %s: %d rows for %d times" % (name, len(rows), n))
        a = (ctypes.c_double * (3 * n))()
        for k, r in enumerate(rows):
            a[3 * k:3 * k + 3] = list(_convert.vector("reference %s[%d]" % (name, k), r, 3))
        flat.append(a)
    tr, msg = _lib._Quintic(), ctypes.create_string_buffer(600)
    st = model.lib.quintic_samples(ctypes.byref(tr), n, tv, *flat, msg, len(msg))
    if st != errors.OK:
        raise _fail(model, st, "track: reference", msg)
    return tr


def track(self, reference, *, bandwidth=None, kp=None, kd=None, period=0.0, dt=1e-3, limits=None,
          noise=(0.0, 0.0), seed=1, q0_offset=(0.0, 0.0, 0.0), plant=None, mismatch=None,
          atol=1e-12, rtol=1e-12, controller="ct", lqr_q=None, lqr_r=None):
    """Computed-torque tracking of reference (a Motion, e.g. from quintic or
    time_optimal, or (t, q, qd, qdd) rows), simulated in closed loop, as
    prru track: fd = J_d^-T (M qdd_c + h - G - passive) with qdd_c =
    qdd_ref + Kd (qd_ref - qd) + Kp (q_ref - q), each force clipped to its
    force_max. Gains: bandwidth W (rad/s, default the library's 20) gives
    Kp = W^2, Kd = 2 W; kp, kd (3 each) replace them. period 0: continuous control, rows every dt;
    period > 0: a digital controller with zero-order hold, a row per
    tick, noise = (std on q, std on qd) from a generator seeded by seed.
    limits: a Limits (default the model's): forces clipped to force_max,
    the reference and the plant kept in the stroke, speeds reported
    against speed_max. plant: a Model file path or Model with this
    library's limbs (the robot the controller does not know exactly),
    default this model; mismatch: {key: factor} scaling the plant's mass,
    inertia, armature, damping, coulomb or gravity. controller "lqr"
    (needs period > 0) is prru track --controller lqr: a time-varying
    discrete LQR from the backward Riccati recursion along the reference
    (prru_control.h), fd = u_ff - K_k (x - x_ref), with the diagonal
    weights lqr_q (6: q then qd, >= 0) and lqr_r (one per actuator, > 0),
    each left out or all 0 Bryson's rule (prru_lqr_default_weights;
    the summary's lqr_q, lqr_r give the weights used). Returns TrackRun.
    Raises InputError for a reference outside the workspace, across a
    singularity or outside the stroke (naming the sample) and for bad
    options; Unreachable when the plant leaves its stroke or the
    workspace, Singular when the controller meets a singular pose,
    NoConvergence for the integrator (each with .run, the rows so far)."""
    lib, t = self.lib, self.lib.types
    lim, c = _c_limits(self, limits)
    g = t.GuardedTrackOptions()
    _lib.fill_guard(g)
    lib.track_options_default(ctypes.byref(self._m), ctypes.byref(g.s))
    o = g.s
    if bandwidth is not None:
        w = _convert.scalar("bandwidth", bandwidth, positive=True, allow_zero=False)
        if lib.track_gains_bandwidth(w, ctypes.byref(o)) != errors.OK:
            raise ValueError("bandwidth %r rad/s gives no finite gains" % (bandwidth,))
    if kp is not None:
        o.kp[:] = list(_convert.vector("kp", kp, 3))
    if kd is not None:
        o.kd[:] = list(_convert.vector("kd", kd, 3))
    o.control_period = _convert.scalar("period", period, positive=True)
    o.dt_out = _convert.scalar("dt", dt, positive=True, allow_zero=False)
    o.f_max[:], o.speed_max[:] = c.force_max[:], c.speed_max[:]
    o.d_min[:], o.d_max[:] = c.d_min[:], c.d_max[:]
    o.noise_q, o.noise_qd = _convert.vector("noise", noise, 2)
    o.seed = _convert.integer("seed", seed, 0)
    if o.seed != seed:
        raise ValueError("seed must fit this platform's unsigned long, got %d" % seed)
    o.q0_offset[:] = list(_convert.vector("q0_offset", q0_offset, 3))
    o.abs_tol = _convert.scalar("atol", atol, positive=True)
    o.rel_tol = _convert.scalar("rtol", rtol, positive=True)
    if plant is None:
        plant_model = self
    elif isinstance(plant, type(self)):
        plant_model = plant
    else:
        plant_model = type(self)(self.lib, model=plant)
    if plant_model.lib is not self.lib:
        raise ValueError("plant must use this model's library (%s)" % self.lib.path)
    if plant_model.nlimb != self.nlimb:
        raise ValueError("plant: a model with %d limbs; this model has %d (the plant's numbers "
                         "are read in the controller's topology)" % (plant_model.nlimb, self.nlimb))
    _track_controller(self, o, controller, lqr_q, lqr_r)
    _track_options_check(self, o)
    lib.model_params(ctypes.byref(plant_model._m), ctypes.byref(o.plant))
    for key, f in (mismatch or {}).items():
        f = _convert.scalar("mismatch[%r]" % key, f, positive=True, allow_zero=False)
        if lib.params_scale(ctypes.byref(o.plant), str(key).encode(), f) != errors.OK:
            raise ValueError("mismatch: unknown key %r (keys: mass, inertia, armature, damping, "
                             "coulomb, gravity)" % key)
    tr = _reference(self, reference)
    try:
        return _track_run(self, tr, o, lim, g)
    finally:
        lib.quintic_free(ctypes.byref(tr))


def _track_controller(model, o, controller, lqr_q, lqr_r):
    """The controller choice and the LQR's weights into o (their rules:
    _track_options_check)."""
    if controller not in ("ct", "lqr"):
        raise ValueError("controller must be 'ct' (computed torque) or 'lqr', got %r" % (controller,))
    if controller == "ct":
        if lqr_q is not None or lqr_r is not None:
            raise ValueError("lqr_q and lqr_r belong to controller='lqr'")
        return
    o.controller = 1  # PRRU_TRACK_LQR
    if lqr_q is not None:
        o.lqr_q[:] = list(_convert.vector("lqr_q", lqr_q, 6))
    if lqr_r is not None:
        o.lqr_r[:model.nact] = list(_convert.vector("lqr_r", lqr_r, model.nact))


# The library names the options by prru_track_options' members; these are
# track's keywords for them (the others are spelt alike).
_TRACK_OPTION_NAMES = {"controller PRRU_TRACK_LQR": "controller 'lqr'", "control period": "period",
                       "sensor noise": "noise", "dt_out": "dt", "abs_tol": "atol", "rel_tol": "rtol"}
_TRACK_OPTION_RE = re.compile(r"(?<![\w-])(%s)(?!\w)" % "|".join(map(re.escape, _TRACK_OPTION_NAMES)))


def _track_options_check(model, o):
    """prru_track_options_check: InputError in track's words."""
    msg = ctypes.create_string_buffer(600)
    st = model.lib.track_options_check(ctypes.byref(model._m), ctypes.byref(o), msg, len(msg))
    if st != errors.OK:
        text = _TRACK_OPTION_RE.sub(lambda m: _TRACK_OPTION_NAMES[m.group(1)],
                                    msg.value.decode("utf-8", "replace"))
        raise errors.make_error(st, "track: " + text)


def _lqr_default_weights(model, tr, o):
    """The library's default weights into the groups of o left all 0, so
    that the summary gives the weights used."""
    lib, n, msg = model.lib, model.nact, ctypes.create_string_buffer(600)
    q, r = (ctypes.c_double * 6)(), (ctypes.c_double * n)()
    with model._lock:
        st = lib.lqr_default_weights(ctypes.byref(model._m), ctypes.byref(tr), o.control_period, q, r, msg,
                                     len(msg))
    if st != errors.OK:
        raise _fail(model, st, "track: LQR default weights", msg)
    if not any(o.lqr_q):
        o.lqr_q[:] = list(q)
    if not any(o.lqr_r):
        o.lqr_r[:n] = list(r)


def _track_run(model, tr, o, lim, guard):
    lib, msg = model.lib, ctypes.create_string_buffer(600)
    step = o.control_period if o.control_period > 0 else o.dt_out
    ff = ctypes.c_double()
    with model._lock:
        st = lib.track_check_reference(ctypes.byref(model._m), ctypes.byref(tr), ctypes.byref(o), step,
                                       ctypes.byref(ff), msg, len(msg))
    if st != errors.OK:
        raise _fail(model, st, "track", msg)
    if o.controller == 1:
        _lqr_default_weights(model, tr, o)
    names = ("t", "q_ref", "q", "e", "qd", "fd", "fd_cmd", "saturated", "d", "qdd", "dd")
    cols = {k: [] for k in names}
    failure = []

    per_actuator, n = ("fd", "fd_cmd", "saturated", "d", "dd"), model.nact

    def consume(ptr, ctx):
        try:
            s = ptr.contents
            for k in names:
                v = getattr(s, k)
                cols[k].append(v if k == "t" else v[:n] if k in per_actuator else list(v))
            return 0
        except BaseException as e:  # stop; re-raised after the call
            failure.append(e)
            return 1
    fn = lib.types.TrackFn(consume)
    o.on_sample = fn
    stop = ctypes.c_int(0)
    o.interrupt = ctypes.pointer(stop)
    summary = lib.types.TrackSummary()
    with model._lock:
        st, interrupt = _interrupt.call_in_worker(
            lambda: lib.track(ctypes.byref(model._m), ctypes.byref(tr), ctypes.byref(o),
                              ctypes.byref(summary), msg, len(msg)), stop, "prru track")
    if not _lib.guard_intact(guard):
        raise lib._layout_error("sizeof(prru_track_options)")
    out, rows = model._out, len(cols["t"])
    mat = {k: out.mat([x for r in cols[k] for x in r], rows, len(cols[k][0])) if rows else []
           for k in names[1:]}
    samples = summary.samples
    summ = {"samples": samples, "t_end": summary.t_end, "rms_error": tuple(summary.rms_e),
            "max_error": tuple(summary.max_e), "max_fd": tuple(summary.max_fd[:model.nact]),
            "saturated_fraction": tuple(x / samples if samples else 0.0 for x in summary.saturated[:model.nact]),
            "any_saturated_fraction": summary.any_saturated / samples if samples else 0.0,
            "max_dd": tuple(summary.max_dd[:model.nact]),
            "over_speed_fraction": summary.over_speed / samples if samples else 0.0,
            "feedforward_peak": ff.value, "limits": lim,
            "status": "complete" if st == errors.OK else msg.value.decode("utf-8", "replace")}
    # The controller and its own gains, as `prru track --summary` names them.
    if o.controller == 1:
        summ.update(controller="lqr", lqr_q=tuple(o.lqr_q), lqr_r=tuple(o.lqr_r[:model.nact]))
    else:
        summ.update(controller="computed_torque", kp=tuple(o.kp), kd=tuple(o.kd))
    run = TrackRun(out.vec(cols["t"]), *(mat[k] for k in names[1:]), summ)
    err = failure[0] if failure else interrupt
    if err is None and st != errors.OK:
        err = _fail(model, st, "track", msg)
    if err is not None:
        try:
            err.run = run
        except AttributeError:
            pass
        raise err
    return run
