"""Design optimisation: the mechanism's numbers that maximise the dynamic
manipulability over a workspace rectangle (prru_design.h), as `prru
optimize` computes them. A method of Model."""

import collections
import ctypes

from . import _convert, _interrupt, _lib, errors, maps
from .identification import write_model_text
from .motion import _c_limits

class Design(collections.namedtuple(
        "Design", "text name variables start best iterations evaluations converged limits")):
    """Model.optimize's result: text (the optimised model file, format 2;
    None when no feasible design was found), name, variables (per
    variable: name, before, after, lo, hi), start and best (dicts: index,
    index_log, objective, singular_fraction, w_max, stroke_violation,
    feasible: the grid's evaluation at the start and at the best design),
    iterations, evaluations, converged (the last run stopped at the
    simplex tolerance) and the limits whose stroke applied. write(path)
    writes the model file, renamed into place."""

    __slots__ = ()

    def write(self, path):
        if self.text is None:
            raise ValueError("no model to write: no feasible design was found")
        write_model_text(self.text, path)


def _eval_dict(ev):
    s = ev.sum
    return {"index": s.index, "index_log": s.index_log, "objective": ev.objective,
            "singular_fraction": s.singular_fraction, "w_max": s.w_max,
            "stroke_violation": ev.stroke_violation, "feasible": bool(ev.feasible)}


def _range(name, value):
    lo, hi, n = _convert.ordered(name, value, "(lo, hi, n)")
    lo, hi = _convert.scalar(name + " lo", lo), _convert.scalar(name + " hi", hi)
    return lo, hi, _convert.integer(name + " n", n, 1)


def optimize(self, vars, *, q1, q2, q3=0.0, range=20.0, objective="mean", rcond_min=None, limits=None,
             penalty=None, max_iter=None, threads=2, name=None, precision="double"):
    """The design whose variables maximise w_R over the grid q1 = (lo, hi,
    n) x q2 = (lo, hi, n) at q3 (prru optimize): vars, a sequence of
    variable names (prru optimize --help's grammar: "l2", "b12", "m_P",
    ...) each within range % of its start value on every tied limb, or
    (name, lo, hi) with its own bounds; objective "mean", "max" or "log";
    every grid point regular (rcond >= rcond_min, default 4e-3) and every
    slider within the limits' stroke (a Limits, default the model's). The
    start is this model's numbers. Returns Design (design.write(path)
    writes the model file). Raises
    InputError for bad variables, bounds or options and when no grid point
    is regular at the start; NoConvergence when no feasible design is
    found (the exception's .design holds the best one). precision "float":
    each evaluation's w_R from the single-precision batched kernels (prru
    optimize --precision float; statuses and penalties still double's)."""
    if not isinstance(precision, str) or precision not in maps.PRECISIONS:
        raise ValueError("precision must be 'double' or 'float', got %r" % (precision,))
    lib, T = self.lib, self.lib.types
    grid = _lib._MapGrid()
    grid.q1_lo, grid.q1_hi, grid.n1 = _range("q1", q1)
    grid.q2_lo, grid.q2_hi, grid.n2 = _range("q2", q2)
    grid.q3 = _convert.scalar("q3", q3)
    pr, msg = _lib._DesignProblem(), ctypes.create_string_buffer(600)
    lib.design_problem_default(ctypes.byref(self._m), ctypes.byref(pr), ctypes.byref(grid))
    if rcond_min is not None:
        pr.rcond_min = _convert.scalar("rcond_min", rcond_min, positive=True, allow_zero=False)
    if penalty is not None:
        pr.penalty_weight = _convert.scalar("penalty", penalty, positive=True, allow_zero=False)
    obj = ctypes.c_int()
    if lib.objective_parse(str(objective).encode(), ctypes.byref(obj)) != errors.OK:
        raise ValueError("objective must be one of mean, max, log, got %r" % (objective,))
    pr.objective = obj.value
    lim, c = _c_limits(self, limits)
    if lib.design_problem_stroke(ctypes.byref(pr), ctypes.byref(c), msg, len(msg)) != errors.OK:
        raise errors.make_error(errors.EINPUT, "optimize: " + msg.value.decode())
    if lib.design_problem_check(ctypes.byref(pr), msg, len(msg)) != errors.OK:
        raise errors.make_error(errors.EINPUT, "optimize: " + msg.value.decode())
    pct = _convert.scalar("range", range, positive=True, allow_zero=False)
    if not pct < 100:
        raise ValueError("range must be a percentage in (0, 100), got %r" % range)
    start = T.Params()
    lib.model_params(ctypes.byref(self._m), ctypes.byref(start))
    if lib.design_check(ctypes.byref(self._m), ctypes.byref(start), msg, len(msg)) != errors.OK:
        raise errors.make_error(errors.EINPUT, "optimize: the start design is not a buildable robot: "
                                + msg.value.decode())
    items = _convert.ordered("vars", vars, "a sequence of variable names or (name, lo, hi)")
    if not 1 <= len(items) <= _lib.DESIGN_MAX_VARS:
        raise ValueError("vars: 1 to %d variables, got %d" % (_lib.DESIGN_MAX_VARS, len(items)))
    cv = (T.DesignVar * len(items))()
    for k, item in enumerate(items):
        bounds = None
        if not isinstance(item, str):
            item = _convert.ordered("vars[%d]" % k, item, "a name or (name, lo, hi)")
            if len(item) != 3 or not isinstance(item[0], str):
                raise ValueError("vars[%d] must be a name or (name, lo, hi), got %r" % (k, item))
            bounds = (_convert.scalar("vars[%d] lo" % k, item[1]), _convert.scalar("vars[%d] hi" % k, item[2]))
            item = item[0]
        if lib.design_var_parse(ctypes.byref(self._m), item.encode(), ctypes.byref(cv[k]), msg,
                                len(msg)) != errors.OK:
            raise ValueError("vars[%d]: %s" % (k, msg.value.decode()))
        if bounds is None:
            lib.design_var_bounds(ctypes.byref(self._m), ctypes.byref(start), ctypes.byref(cv[k]), pct)
        else:
            cv[k].lo, cv[k].hi = bounds
        x = lib.design_get(ctypes.byref(start), ctypes.byref(cv[k]))
        if not cv[k].lo <= x <= cv[k].hi:
            raise ValueError("vars[%d] %s: the start value %r is outside the bounds [%r, %r]"
                             % (k, item, x, cv[k].lo, cv[k].hi))
    o = T.DesignOptions()
    lib.design_options_default(ctypes.byref(o))
    if max_iter is not None:
        o.max_iter = _convert.integer("max_iter", max_iter, 1)
    o.nthreads = _convert.integer("threads", threads, 1)
    o.precision = maps.PRECISIONS[precision]
    stop = ctypes.c_int(0)
    progress = T.DesignProgress(lambda it, ev, best, size, ctx: stop.value)
    o.progress = progress
    r = T.DesignResult()
    with self._lock:
        st, interrupt = _interrupt.call_in_worker(
            lambda: lib.design_optimize(ctypes.byref(pr), ctypes.byref(start), cv, len(items), ctypes.byref(o),
                                        ctypes.byref(r), msg, len(msg)), stop, "prru optimize")
    if interrupt is not None:
        raise interrupt
    if st != errors.OK:
        raise errors.make_error(st, "optimize: " + (msg.value.decode("utf-8", "replace") or lib.status_text(st)))
    s0 = r.start_eval.sum
    if s0.n_ok == 0:
        raise errors.make_error(errors.EINPUT, "optimize: no grid point of the workspace is regular (%d singular, "
                                "%d in the other assembly mode, %d unreachable, of %d): the objective is not "
                                "defined there" % (s0.n_singular - r.start_eval.n_other_mode,
                                                   r.start_eval.n_other_mode, s0.n_unreachable, s0.n_points))
    if name is None:
        name = _convert.derived_name(self.lib, self.name, "_opt")  # as prru optimize
    desc = "%s optimised by prru.Model.optimize (%s of w_R over q1 in [%.4g, %.4g], q2 in [%.4g, %.4g], q3 = %.4g; " \
           "variables %s)" % (self.name, objective, grid.q1_lo, grid.q1_hi, grid.q2_lo, grid.q2_hi, grid.q3,
                              " ".join(v.name.decode() for v in cv))
    variables = tuple((v.name.decode(), r.x0[k], r.x[k], v.lo, v.hi) for k, v in enumerate(cv))
    design = Design(None, name, variables, _eval_dict(r.start_eval), _eval_dict(r.best_eval), r.iterations,
                    r.evaluations, bool(r.converged), lim)
    if not r.best_eval.feasible:
        err = errors.make_error(errors.ENOCONV, "optimize: no feasible design found: the best has %.4g %% of the "
                                "grid singular, unreachable or in the other assembly mode and a stroke violation "
                                "of %.3g (widen the bounds, shrink the rectangle or loosen rcond_min / the stroke)"
                                % (100 * r.best_eval.sum.singular_fraction, r.best_eval.stroke_violation))
        err.design = design
        raise err
    text = ctypes.c_void_p()
    st = lib.model_file_text(ctypes.byref(self._m), ctypes.byref(r.best), name.encode(), desc.encode(),
                             ctypes.byref(text), msg, len(msg))
    if st != errors.OK:
        raise errors.make_error(st, "optimize: " + msg.value.decode("utf-8", "replace"))
    try:
        return design._replace(text=ctypes.string_at(text).decode("utf-8"))
    finally:
        lib.free(text)

