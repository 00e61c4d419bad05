"""Model: the mechanism libprru.so was built for, and its dynamics calls."""

import collections
import ctypes
import os
import threading
from math import isfinite

from . import _convert, _lib, errors
from ._convert import optional_vector, vector

Joint = collections.namedtuple(
    "Joint", "name type limb proximal distal lambda_offset lambda_count")
Joint.__doc__ = """One joint: type 'U', 'R' or 'P'; limb 0-based; proximal and
distal body indexes (proximal -1 for the rail); its reaction coordinates are
lambda[lambda_offset : lambda_offset + lambda_count]."""

Dme = collections.namedtuple(
    "Dme", "w_R jd_rcond sigma semi_axis axis_dir sigma_T half_length_T dir_T Mt JtR JtT")
Dme.__doc__ = """Dynamic manipulability at one pose (see prru_dme.h):
w_R = sigma[0] / sigma[1] >= 1; sigma (N s^2/rad) and semi_axis = 1/sigma
(rad/s^2 per N, [minor, major]) of the rotational ellipse, axis_dir its unit
axis directions in {S}; sigma_T, half_length_T and dir_T of the
translational segment; Mt (nact x nact), JtR and JtT (3 x nact)."""

Linearization = collections.namedtuple(
    "Linearization", "qdd dqdd_dq dqdd_dqd dqdd_dfd dqdd_dfp dqdd_dmp A B dt Ad Bd")
Linearization.__doc__ = """The dynamics linearised at one state (prru_linearize.h):
qdd; dqdd_dq, dqdd_dqd (3x3), dqdd_dfd (3 x nact), dqdd_dfp, dqdd_dmp (3x3),
row i = qdd_i, column k = the k-th variable; A (6x6), B (6 x nact) of
x' = A x + B u, x = (q, qd), u = fd; with dt, the zero-order-hold pair
Ad, Bd (None without)."""


def _fmt(v):
    return "(" + ", ".join("%.17g" % x for x in v) + ")"


def _finite(*outputs):
    """Every number of outputs (ctypes arrays, or floats) finite. (A slice
    of a ctypes array is a list, read much faster than the array itself.)"""
    for o in outputs:
        if not (isfinite(o) if isinstance(o, float) else all(map(isfinite, o[:]))):
            return False
    return True


class Model:
    """The robot model compiled into one libprru.so.

    Model(lib=None, *, model=None, numpy=False, jd_rcond_min=None)
    Model("robot.json", ...)

    lib: a path to libprru.so or to a build directory, or a Library from
    load_library(); None searches $PRRU_LIB, beside the package, the source
    tree's build/runtime/ and the system's library path (load_library).
    model: a model file (format 1 or 2) read at run time by the library
    (prru_model_load), with the same validation and messages as the
    generator; a first argument ending in ".json" is taken as model, of
    3 or 4 limbs whatever the library's own. The kernels: "specialised"
    (the library's constant-folded ones) when its numbers are the
    library's model's, else "parameter" (the attribute kernels says
    which). None: the library's own model.
    numpy: return NumPy arrays (matrices 2-D) instead of lists (matrices as
    lists of rows). Inputs are ordered sequences of numbers (list, tuple,
    array.array, 1-D NumPy arrays, ...) either way; dicts, sets, strings
    and iterators are refused (TypeError naming the argument).
    jd_rcond_min: the reciprocal condition number of the scaled J_d below
    which a pose counts as singular (library default 1e-8).

    Sizes and the model's identity and numbers come from the library's
    descriptor: nact actuators (3, or 4 for the redundant robot), nbody
    bodies named body_names, nlambda reaction coordinates named
    lambda_labels. Calls are serialised per Model (each Model owns the
    library's per-call workspace), so a Model may be shared by threads;
    use one Model per thread for parallel calls.

    Failures raise PrruError subclasses carrying the library's message:
    Unreachable, Singular, NoConvergence, InputError (also a ValueError).
    No method returns a non-finite number: such a result raises InputError
    naming the rate or load arguments that make it overflow (dynamics with
    a huge qd), or Singular where J_d itself is not finite (the edge of the
    workspace, accepted by the reachability check).
    """

    def __init__(self, lib=None, *, model=None, numpy=False, jd_rcond_min=None):
        # Model("robot.json"): a model file, read with the library found as
        # for lib=None.
        if model is None and isinstance(lib, (str, bytes, os.PathLike)) and \
                os.fsdecode(lib).endswith(".json"):
            model, lib = lib, None
        self.lib = lib if isinstance(lib, _lib.Library) else _lib.load_library(lib)
        self._out = _convert.Output(numpy)
        if jd_rcond_min is not None:
            jd_rcond_min = _convert.scalar("jd_rcond_min", jd_rcond_min, positive=True)
        self._m = self.lib.new_model(jd_rcond_min, model)
        self._g = self.lib.new_data()
        self._lock = threading.Lock()
        self._read_descriptor()

    def __del__(self):
        m = getattr(self, "_m", None)
        if m is not None and m.own:
            self.lib.model_free(ctypes.byref(m))

    # ---- the descriptor ----
    def _read_descriptor(self):
        me, out = self.lib.mechanism(self._m), self._out
        self.kernels = ctypes.cast(self._m.kernels, ctypes.POINTER(ctypes.c_char_p))[0].decode()
        s = lambda b: b.decode("utf-8", "replace")
        self.name, self.description = s(me.name), s(me.description)
        self.model_file, self.sha256, self.format = s(me.model_file), s(me.sha256), me.format
        self.nq, self.nact, self.nlimb = me.nq, me.nact, me.nlimb
        self.nbody, self.nlambda, self.njoint = me.nbody, me.nlambda, me.njoint
        nb, nl, na = me.nbody, me.nlimb, me.nact
        self.body_names = tuple(s(me.body_names[i]) for i in range(nb))
        self.body_limb = tuple(me.body_limb[:nb])
        self.platform = me.platform
        self.lower, self.upper = tuple(me.lower[:nl]), tuple(me.upper[:nl])
        self.slider = tuple(me.slider[:nl])
        self.gravity = out.vec(me.gravity)
        self.mass, self.total_mass = out.vec(me.mass, nb), me.total_mass
        self.com = [out.vec(me.com[b]) for b in range(nb)]
        self.inertia = [out.mat(me.inertia[b], 3, 3) for b in range(nb)]
        self.b, self.l1, self.l2, self.a = (out.vec(me.b, nl), out.vec(me.l1, nl),
                                            out.vec(me.l2, nl), out.vec(me.a, nl))
        self.armature, self.damping = out.vec(me.armature, na), out.vec(me.damping, na)
        self.coulomb, self.coulomb_velocity = out.vec(me.coulomb, na), me.coulomb_velocity
        # spec 13: lead 0 and torque_constant 0 mean none; limits in rail
        # units, inf (-inf for d_min) where the model sets none
        self.lead, self.gear = out.vec(me.lead, na), out.vec(me.gear, na)
        self.torque_constant = out.vec(me.torque_constant, na)
        self.force_max, self.speed_max = out.vec(me.force_max, na), out.vec(me.speed_max, na)
        self.d_min, self.d_max = out.vec(me.d_min, na), out.vec(me.d_max, na)
        self.joints = tuple(Joint(s(j.name), s(j.type), j.limb, j.proximal, j.distal,
                                  j.lambda_offset, j.lambda_count) for j in me.joint[:me.njoint])
        self.lambda_labels = tuple(s(me.lambda_labels[i]) for i in range(me.nlambda))
        self.npreload = self.nact - 3
        self.nreaction_null = self.nlambda - (6 * self.nbody - 3)

    @property
    def jd_rcond_min(self):
        return self._m.jd_rcond_min

    @property
    def numpy(self):
        return self._out.np is not None

    def __repr__(self):
        return "<prru.Model %s (%s, sha256 %s): %d actuators, library %s>" % (
            self.name, self.model_file, self.sha256[:12], self.nact, self.lib.path)

    # ---- helpers ----
    def _fail(self, status, what, rates=None):
        """what: the call's description, or a function making it (built
        only on failure: formatting costs more than the call). rates: a
        function giving the (name, values) of the arguments besides q,
        named for PRRU_EINPUT (NaN, infinite or out of range: the library
        does not say which; q is checked finite before the call, so it is
        one of them, or a result they make overflow)."""
        what = what() if callable(what) else what
        if status == errors.EINPUT and rates is not None:
            what += "".join(", %s = %s" % (name, _fmt(v)) for name, v in rates())
        raise errors.make_error(status, "%s: %s" % (what, self.lib.status_text(status)))

    def _call(self, what, fn, *args, rates=None):
        with self._lock:
            st = fn(ctypes.byref(self._m), ctypes.byref(self._g.s), *args)
        if st != errors.OK:
            self._fail(st, what, rates)

    def _loads(self, fd, fp, mp):
        l = self.lib.types.Loads(fp=optional_vector("fp", fp, 3), mp=optional_vector("mp", mp, 3))
        l.fd[:self.nact] = list(optional_vector("fd", fd, self.nact))
        return l

    def _reachable(self, what, q):
        self._call(lambda: "%s: q = %s" % (what, _fmt(q)), self.lib.check_reachable, q)

    def _require_finite(self, what, q, outputs, rates=()):
        """Raises unless every number of outputs is finite: a result that is
        not finite cannot be used, so it is an error, never returned.
        Where J_d is not finite (the edge of the workspace, where a sqrt
        of the inverse kinematics reaches 0 while check_reachable still
        accepts q) the library's forward dynamics reports Singular, and so
        does this; otherwise the rate and load arguments rates ((name,
        values) pairs, or a function giving them) are too large for the
        result to be represented: InputError naming them, as the library's
        status-checked calls report."""
        if _finite(*outputs):
            return
        n = self.nact
        d, jd = (ctypes.c_double * n)(), (ctypes.c_double * (3 * n))()
        self.lib.model_ik_jd(ctypes.byref(self._m), q, d, jd)
        if not _finite(d, jd):
            raise errors.Singular("%s: q = %s: %s: J_d is not finite there (the edge of the "
                                  "workspace)" % (what, _fmt(q),
                                                  self.lib.status_text(errors.ESINGULAR)),
                                  errors.ESINGULAR)
        rates = rates() if callable(rates) else rates
        given = "".join(", %s = %s" % (name, _fmt(v)) for name, v in rates)
        cause = (" or ".join(name for name, _ in rates) + " too large") if rates else \
            "not finite at this q"
        raise errors.InputError("%s: q = %s%s: %s: the result is not finite (%s)"
                                % (what, _fmt(q), given,
                                   self.lib.status_text(errors.EINPUT), cause),
                                errors.EINPUT)

    # ---- kinematics ----
    def check(self, q):
        """The scaled reciprocal condition number of J_d at q (1 / (|J|_1 |J^+|_1),
        J = J_d diag(1/L, 1/L, 1), L the mean upper-link length); raises
        Unreachable, or Singular below jd_rcond_min."""
        q = vector("q", q, 3)
        rc = ctypes.c_double()
        self._call(lambda: "check: q = %s" % _fmt(q), self.lib.check_regular, q,
                   ctypes.byref(rc))
        self._require_finite("check", q, (rc.value,))
        return rc.value

    def ik(self, q):
        """Inverse kinematics: (d, Jd), the slider heights (m, nact) and
        J_d = dd/dq (nact x 3). Raises Unreachable."""
        q = vector("q", q, 3)
        self._reachable("ik", q)
        n = self.nact
        d, jd = (ctypes.c_double * n)(), (ctypes.c_double * (3 * n))()
        self.lib.model_ik_jd(ctypes.byref(self._m), q, d, jd)
        self._require_finite("ik", q, (d, jd))
        return self._out.vec(d), self._out.mat(jd, n, 3)

    def _fk_seed(self, act, seed):
        if seed is not None:
            return vector("seed", seed, 3)
        s = (ctypes.c_double * 3)()
        self.lib.fk_default_seed(ctypes.byref(self._m), act, s)
        return s

    def fk(self, d, seed=None):
        """Forward kinematics: q with d(q) = d, from seed (default q1 = q2 = 0
        and the height matching the mean of d). Three sliders: Newton's
        method; four: least squares that refuses inconsistent sliders.
        Raises NoConvergence (out of reach, inconsistent, or a singularity
        on the way) or Singular."""
        act = vector("d", d, self.nact)
        seed = self._fk_seed(act, seed)
        q = (ctypes.c_double * 3)()
        self._call(lambda: "fk: d = %s from seed %s" % (_fmt(act), _fmt(seed)),
                   self.lib.forward_kinematics, act, seed, q)
        self._require_finite("fk: d = %s from seed %s" % (_fmt(act), _fmt(seed)), q, (q,))
        return self._out.vec(q)

    def fk_lsq(self, d, seed=None):
        """Least-squares forward kinematics: (q, residual), q minimizing
        |d(q) - d|_2 and residual = max_i |d_i(q) - d_i| (m), whatever the
        residual (measured sliders); the caller judges it."""
        act = vector("d", d, self.nact)
        seed = self._fk_seed(act, seed)
        q, res = (ctypes.c_double * 3)(), ctypes.c_double()
        self._call(lambda: "fk_lsq: d = %s from seed %s" % (_fmt(act), _fmt(seed)),
                   self.lib.forward_kinematics_lsq, act, seed, q, ctypes.byref(res))
        self._require_finite("fk_lsq: d = %s from seed %s" % (_fmt(act), _fmt(seed)), q,
                             (q, res.value))
        return self._out.vec(q), res.value

    def platform_jacobian(self, q):
        """(J_R,P, J_T,O'): the platform's angular velocity and the velocity
        of O' are J qd (3x3 each, {S}). Raises Unreachable."""
        q = vector("q", q, 3)
        self._reachable("platform_jacobian", q)
        jp = (ctypes.c_double * 18)()
        self.lib.model_platform_jacobian(ctypes.byref(self._m), q, jp)
        self._require_finite("platform_jacobian", q, (jp,))
        return self._out.mat(jp, 3, 3), self._out.mat(jp[9:], 3, 3)

    def poses(self, q):
        """(R, p): each body's rotation (3x3) and centre (3) in {S}, in
        body_names order. Raises Unreachable."""
        q = vector("q", q, 3)
        self._reachable("poses", q)
        nb = self.nbody
        r, p = (ctypes.c_double * (9 * nb))(), (ctypes.c_double * (3 * nb))()
        self.lib.model_poses(ctypes.byref(self._m), q, r, p)
        self._require_finite("poses", q, (r, p))
        return ([self._out.mat(r[9 * b:9 * b + 9], 3, 3) for b in range(nb)],
                [self._out.vec(p[3 * b:3 * b + 3]) for b in range(nb)])

    # ---- dynamics ----
    def dynamics(self, q, qd=None):
        """(M, h, G): M(q) qdd + h(q, qd) = G(q) + J_d^T fd + ... (M 3x3 with
        the drives' armature; h without their damping and friction, see
        passive). qd defaults to 0. Raises Unreachable."""
        q, qd = vector("q", q, 3), optional_vector("qd", qd, 3)
        self._reachable("dynamics", q)
        M, h, G = (ctypes.c_double * 9)(), (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        self.lib.model_dynamics(ctypes.byref(self._m), q, qd, M, h, G)
        self._require_finite("dynamics", q, (M, G))
        self._require_finite("dynamics", q, (h,), (("qd", qd),))
        return self._out.mat(M, 3, 3), self._out.vec(h), self._out.vec(G)

    def passive(self, q, qd):
        """The drives' viscous damping and smoothed Coulomb friction as
        generalized forces (3; zero for a model without drives)."""
        q, qd = vector("q", q, 3), vector("qd", qd, 3)
        self._reachable("passive", q)
        out = (ctypes.c_double * 3)()
        self.lib.model_passive(ctypes.byref(self._m), q, qd, out)
        self._require_finite("passive", q, (out,), (("qd", qd),))
        return self._out.vec(out)

    def forward_dynamics(self, q, qd=None, fd=None, fp=None, mp=None):
        """qdd from M qdd = G + J_d^T fd + J_T,P^T fp + J_R,P^T mp + passive - h:
        fd actuator forces (N, nact), fp force (N) and mp moment (N m) on the
        platform at O' in {S}; all default to 0. Raises Unreachable."""
        q, qd = vector("q", q, 3), optional_vector("qd", qd, 3)
        l = self._loads(fd, fp, mp)
        qdd = (ctypes.c_double * 3)()
        rates = lambda: (("qd", qd), ("fd", l.fd[:self.nact]), ("fp", l.fp), ("mp", l.mp))
        self._call(lambda: "forward_dynamics: q = %s" % _fmt(q), self.lib.forward_dynamics,
                   q, qd, ctypes.byref(l), qdd, rates=rates)
        self._require_finite("forward_dynamics", q, (qdd,), rates)
        return self._out.vec(qdd)

    def linearize(self, q, qd, fd, fp=None, mp=None, dt=None):
        """The closed-form derivatives of forward dynamics at (q, qd) under fd,
        fp, mp (fp, mp default to 0) and the state-space pair, with dt (s,
        > 0) the zero-order-hold discrete pair: a Linearization, the numbers
        `prru linearize` prints. Raises as forward_dynamics where qdd is not
        trusted."""
        q, qd = vector("q", q, 3), vector("qd", qd, 3)
        vector("fd", fd, self.nact)  # required, unlike forward_dynamics's
        l = self._loads(fd, fp, mp)
        if dt is not None:
            dt = _convert.scalar("dt", dt, positive=True, allow_zero=False)
        o, msg = self.lib.types.Linearization(), ctypes.create_string_buffer(600)
        with self._lock:
            st = self.lib.linearize_why(ctypes.byref(self._m), ctypes.byref(self._g.s), q, qd,
                                        ctypes.byref(l), dt or 0.0, ctypes.byref(o), msg,
                                        len(msg))
        if st != errors.OK:
            raise errors.make_error(st, "linearize: %s" % msg.value.decode("utf-8", "replace"))
        n, mat = self.nact, self._out.mat
        return Linearization(self._out.vec(o.qdd), mat(o.dqdd_dq, 3, 3), mat(o.dqdd_dqd, 3, 3),
                             mat(o.dqdd_dfd, 3, n), mat(o.dqdd_dfp, 3, 3),
                             mat(o.dqdd_dmp, 3, 3), mat(o.A, 6, 6), mat(o.B, 6, n),
                             dt, mat(o.Ad, 6, 6) if dt else None,
                             mat(o.Bd, 6, n) if dt else None)

    def linearize_batch(self, states, dt=None):
        """linearize at many states in one call, through the batched
        derivative kernel (prru_linearize_batch): states is a sequence of
        (q, qd, fd) or (q, qd, fd, fp, mp). Returns a list with, per state,
        its Linearization (the numbers linearize gives, within a few ulp
        where the build's vector sin and cos take part), or where the state
        is not trusted the exception linearize would raise there, returned
        and not raised, so that the other states stand."""
        states = _convert.ordered("states", states, "a sequence of (q, qd, fd[, fp, mp])")
        n, t = len(states), self.lib.types
        if dt is not None:
            dt = _convert.scalar("dt", dt, positive=True, allow_zero=False)
        q, qd, loads = (ctypes.c_double * (3 * n))(), (ctypes.c_double * (3 * n))(), (t.Loads * n)()
        for k, s in enumerate(states):
            s = _convert.ordered("states[%d]" % k, s, "(q, qd, fd[, fp, mp])")
            if len(s) not in (3, 5):
                raise ValueError("states[%d] must be (q, qd, fd) or (q, qd, fd, fp, mp), got %d items"
                                 % (k, len(s)))
            q[3 * k:3 * k + 3] = list(vector("states[%d] q" % k, s[0], 3))
            qd[3 * k:3 * k + 3] = list(vector("states[%d] qd" % k, s[1], 3))
            vector("states[%d] fd" % k, s[2], self.nact)  # required, as for linearize
            loads[k] = self._loads(s[2], *(s[3:] or (None, None)))
        out, status = (t.Linearization * n)(), (ctypes.c_int * n)()
        self.lib.linearize_batch(ctypes.byref(self._m), n, q, qd, loads, dt or 0.0, out, status)
        na, mat, result = self.nact, self._out.mat, []
        for k in range(n):
            if status[k] != errors.OK:
                result.append(errors.make_error(status[k], "linearize_batch: state %d, q = %s: %s" % (
                    k, _fmt(q[3 * k:3 * k + 3]), self.lib.status_text(status[k]))))
                continue
            o = out[k]
            result.append(Linearization(
                self._out.vec(o.qdd), mat(o.dqdd_dq, 3, 3), mat(o.dqdd_dqd, 3, 3),
                mat(o.dqdd_dfd, 3, na), mat(o.dqdd_dfp, 3, 3), mat(o.dqdd_dmp, 3, 3),
                mat(o.A, 6, 6), mat(o.B, 6, na), dt, mat(o.Ad, 6, 6) if dt else None,
                mat(o.Bd, 6, na) if dt else None))
        return result

    def inverse_dynamics(self, q, qd, qdd, fp=None, mp=None, preload=0.0):
        """Actuator forces fd (N, nact) producing qdd under fp, mp: the
        least-norm solution of J_d^T fd = tau, plus preload (N) along the
        actuator null vector for a redundant robot (InputError for a
        non-zero preload with three actuators). Raises Unreachable, Singular."""
        q, qd, qdd = vector("q", q, 3), vector("qd", qd, 3), vector("qdd", qdd, 3)
        preload = _convert.scalar("preload", preload)
        l = self._loads(None, fp, mp)
        fd = (ctypes.c_double * self.nact)()
        rates = lambda: (("qd", qd), ("qdd", qdd), ("fp", l.fp), ("mp", l.mp),
                         ("preload", (preload,)))
        self._call(lambda: "inverse_dynamics: q = %s" % _fmt(q),
                   self.lib.inverse_dynamics_preload, q, qd, qdd, ctypes.byref(l), preload, fd,
                   rates=rates)
        self._require_finite("inverse_dynamics", q, (fd,), rates)
        return self._out.vec(fd)

    def actuator_null(self, q):
        """n: the unit actuator-force pattern in equilibrium by itself
        (J_d^T n = 0); only for a redundant robot (InputError otherwise)."""
        q = vector("q", q, 3)
        if self.npreload == 0:
            raise errors.InputError("actuator_null: this model has %d actuators for 3 "
                                    "coordinates, no actuator null vector" % self.nact,
                                    errors.EINPUT)
        n = (ctypes.c_double * self.nact)()
        self._call(lambda: "actuator_null: q = %s" % _fmt(q), self.lib.actuator_null, q, n)
        self._require_finite("actuator_null", q, (n,))
        return self._out.vec(n)

    def reactions(self, q, qd=None, fd=None, fp=None, mp=None, labelled=False):
        """The nlambda joint reaction coordinates (N, N m) at the state's
        accelerations, in lambda_labels order (a dict label -> value when
        labelled); for a redundant robot the least-norm solution. Raises
        Unreachable, Singular."""
        q, qd = vector("q", q, 3), optional_vector("qd", qd, 3)
        l = self._loads(fd, fp, mp)
        lam = (ctypes.c_double * self.nlambda)()
        rates = lambda: (("qd", qd), ("fd", l.fd[:self.nact]), ("fp", l.fp), ("mp", l.mp))
        self._call(lambda: "reactions: q = %s" % _fmt(q), self.lib.reactions, q, qd,
                   ctypes.byref(l), lam, rates=rates)
        self._require_finite("reactions", q, (lam,), rates)
        if labelled:
            return dict(zip(self.lambda_labels, lam))
        return self._out.vec(lam)

    def reaction_null(self, q):
        """z: the unit reaction pattern that loads no body (Q z = 0); only for
        a model with one (the 4-PRRU; InputError otherwise)."""
        q = vector("q", q, 3)
        if self.nreaction_null == 0:
            raise errors.InputError("reaction_null: this model's reactions are determined, "
                                    "no null vector", errors.EINPUT)
        z = (ctypes.c_double * self.nlambda)()
        self._call(lambda: "reaction_null: q = %s" % _fmt(q), self.lib.reaction_null, q, z)
        self._require_finite("reaction_null", q, (z,))
        return self._out.vec(z)

    def energy(self, q, qd=None):
        """(T, V): kinetic (with the armature) and potential energy (J)."""
        q, qd = vector("q", q, 3), optional_vector("qd", qd, 3)
        T, V = ctypes.c_double(), ctypes.c_double()
        st = self.lib.energies(ctypes.byref(self._m), q, qd, ctypes.byref(T), ctypes.byref(V))
        if st != errors.OK:
            self._fail(st, "energy: q = %s, qd = %s" % (_fmt(q), _fmt(qd)))
        self._require_finite("energy", q, (T.value, V.value), (("qd", qd),))
        return T.value, V.value

    def power(self, q, qd=None, fd=None, fp=None, mp=None):
        """(load, passive) (W): the power of the loads, fd . d' + fp . v_O' +
        mp . w_P, and of the drives' damping and friction, passive . qd;
        d/dt (T + V) is their sum. Raises Unreachable."""
        q, qd = vector("q", q, 3), optional_vector("qd", qd, 3)
        l = self._loads(fd, fp, mp)
        self._reachable("power", q)
        load, passive = ctypes.c_double(), ctypes.c_double()
        self.lib.power(ctypes.byref(self._m), q, qd, ctypes.byref(l), ctypes.byref(load),
                       ctypes.byref(passive))
        self._require_finite("power", q, (load.value, passive.value),
                             (("qd", qd), ("fd", l.fd[:self.nact]), ("fp", l.fp), ("mp", l.mp)))
        return load.value, passive.value

    # ---- manipulability ----
    def dme(self, q):
        """The dynamic manipulability at q (a Dme). Raises Unreachable or
        Singular (w_R is not defined there)."""
        q = vector("q", q, 3)
        g = self.lib.types.GuardedDme()
        self._call(lambda: "dme: q = %s" % _fmt(q), self.lib.dme_eval, q, ctypes.byref(g.s))
        o, out, n = g.s, self._out, self.nact
        self._require_finite("dme", q, (o.w_R, o.jd_rcond, o.sigma, o.semi_axis, o.axis_dir[0],
                                        o.axis_dir[1], o.sigma_T, o.half_length_T, o.dir_T,
                                        o.Mt[:n * n], o.JtR[:3 * n], o.JtT[:3 * n]))
        return Dme(o.w_R, o.jd_rcond, out.vec(o.sigma), out.vec(o.semi_axis),
                   [out.vec(o.axis_dir[0]), out.vec(o.axis_dir[1])], o.sigma_T,
                   o.half_length_T, out.vec(o.dir_T), out.mat(o.Mt, n, n),
                   out.mat(o.JtR, 3, n), out.mat(o.JtT, 3, n))

    def w_R(self, q):
        """The rotational dynamic-manipulability index at q (>= 1)."""
        return self.dme(q).w_R

    # Simulation and maps live in their own modules.
    from .simulation import simulate, paper_scenario, read_scenario  # noqa: E402
    from .maps import map  # noqa: E402
    from .measurements import measure  # noqa: E402
    from .motion import limits, quintic, time_optimal, track  # noqa: E402
    from .identification import excite, identify  # noqa: E402
    from .design import optimize  # noqa: E402
