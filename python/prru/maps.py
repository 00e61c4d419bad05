"""w_R over a (q1, q2) grid (prru_map_eval): a method of Model."""

import collections
import ctypes

from . import _convert, _interrupt, _lib, errors


MapResult = collections.namedtuple("MapResult", "q1 q2 q3 w_R status summary")
MapResult.__doc__ = """A w_R map: axes q1 (n1 values) and q2 (n2), the height q3;
w_R[i][j] at (q1[i], q2[j]) (NaN where not ok; a NumPy array (n1, n2) for a
model with numpy=True); status[i][j] "ok", "singular", "unreachable",
"out_of_stroke" (a slider beyond its stroke) or "other_mode" (regular, but
det J_d has the opposite sign to the home pose's (0, 0, q3): beyond the
singular locus, out of reach of the robot assembled at home; three
actuators only), the library's names (prru_dme_status_name); summary: a dict with n_points, n_ok,
n_singular (counting the other_mode points too), n_unreachable,
n_other_mode, index (mean of w_R - 1 over the ok points, the paper's global
index), index_log (mean of ln w_R), singular_fraction, w_min, w_max and
their (q1, q2) w_min_q, w_max_q, and precision ("double" or "float"). Without an ok point these six are None
(no number: a mean or extreme of nothing is not defined), not NaN."""


def _axis(name, value):
    value = _convert.ordered(name, value, "(start, stop, count)")
    if len(value) != 3:
        raise ValueError("%s must be (start, stop, count), got %r" % (name, value))
    lo = _convert.scalar(name + " start", value[0])
    hi = _convert.scalar(name + " stop", value[1])
    n = _convert.integer(name + " count", value[2], 2)
    if not lo < hi:
        raise ValueError("%s: start must be below stop, got %r and %r" % (name, lo, hi))
    return lo, hi, n


# prru_map_options.precision (prru_dme.h).
PRECISIONS = {"double": 0, "float": 1}


def precision_code(model, precision):
    """The C code of precision ("double" or "float") for model: ValueError
    for another value, PrruInputError where model has no float kernels
    (only the build's model has them, not a model file of other numbers)."""
    if not isinstance(precision, str) or precision not in PRECISIONS:
        raise ValueError("precision must be 'double' or 'float', got %r" % (precision,))
    code = PRECISIONS[precision]
    if model.lib.precision_available(ctypes.byref(model._m), code) != errors.OK:
        raise errors.make_error(errors.EINPUT, "precision='float': this model (%s kernels) has no "
                                "single-precision kernels: only the build's own model is generated "
                                "in float" % model.kernels)
    return code


def map(self, q1, q2, q3=0.0, *, threads=2, jd_rcond_min=None, precision="double"):
    """w_R at every point of a grid: q1 = (start, stop, count) gives count
    equally spaced values from start to stop (rad, count >= 2), q2 alike,
    at height q3 (m). jd_rcond_min overrides the model's singularity
    tolerance for this map (e.g. 4e-3 for a practical-singularity band, so
    that the global index converges with the resolution); threads: worker
    threads (the C library's, outside the GIL); precision "float" computes
    w_R with the single-precision batched kernels (prru map --precision
    float: statuses still double's; only the build's model), and the
    summary's "precision" says which. Returns a MapResult.
    Ctrl-C stops the map between grid rows (KeyboardInterrupt)."""
    code = precision_code(self, precision)
    lo1, hi1, n1 = _axis("q1", q1)
    lo2, hi2, n2 = _axis("q2", q2)
    g = _lib._MapGrid(lo1, hi1, lo2, hi2, _convert.scalar("q3", q3), n1, n2)
    threads = _convert.integer("threads", threads, 1)
    m = self._m
    if jd_rcond_min is not None:
        m = self.lib.new_model(_convert.scalar("jd_rcond_min", jd_rcond_min, positive=True))
    o = _lib._MapOptions()
    self.lib.map_options_default(ctypes.byref(o))
    o.nthreads = threads
    o.precision = code
    # The progress report runs Python in the calling thread now and then,
    # which is when a SIGINT handler can run (see _interrupt).
    o.progress = _lib.MAP_PROGRESS_FN(lambda done, total, ctx: 0)
    w = (ctypes.c_double * (n1 * n2))()
    st = (ctypes.c_ubyte * (n1 * n2))()
    s = _lib._MapSummary()
    with _interrupt.SigintFlag() as sigint:
        o.interrupt = sigint.pointer
        rc = self.lib.map_eval(ctypes.byref(m), ctypes.byref(g), ctypes.byref(o), w, st,
                               ctypes.byref(s))
    if sigint.raised:
        raise KeyboardInterrupt()
    if rc != errors.OK:
        raise errors.make_error(rc, "map: %s" % self.lib.status_text(rc))
    axis1 = [self.lib.map_axis(lo1, hi1, n1, i) for i in range(n1)]
    axis2 = [self.lib.map_axis(lo2, hi2, n2, j) for j in range(n2)]
    # The library's names (prru_dme_status_name), once per status seen.
    known = {v: self.lib.dme_status_name(v).decode() for v in set(st)}
    names = [known[v] for v in st]
    summary = {k: getattr(s, k) for k in ("n_points", "n_ok", "n_singular", "n_unreachable",
                                          "n_other_mode", "index", "index_log",
                                          "singular_fraction", "w_min", "w_max")}
    summary["w_min_q"], summary["w_max_q"] = tuple(s.w_min_q), tuple(s.w_max_q)
    summary["precision"] = precision
    if s.n_ok == 0:  # the library's NaN: over the ok points, of which there are none
        for k in ("index", "index_log", "w_min", "w_max", "w_min_q", "w_max_q"):
            summary[k] = None
    out = self._out
    return MapResult(out.vec(axis1), out.vec(axis2), g.q3, out.mat(w, n1, n2),
                     [names[i * n2:(i + 1) * n2] for i in range(n1)], summary)
