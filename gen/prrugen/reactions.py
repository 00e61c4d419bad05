"""The joint reactions in closed form, limb by limb (docs/model.md section 7).

The equations of reaction Phi H qdd + K = Fbar + Q lambda say, body by body,
that the wrench w_b = Phi_b H_b qdd + K_b - Fbar_b a body needs (known once
qdd is) is what its joints deliver: +W_j from each joint j it is the distal
body of, -W_j from each it is the proximal body of. Along a limb
(rail -P- slider S -A- upper link U -B- lower link L -C- platform) that is

  W_B = w_L + W_C,   W_A = w_U + W_B,   W_P = w_S + W_A

(wrenches about one point), so the limb is known from its U-joint wrench
W_C = (force f, moment mu u at C) alone. Each joint's wrench has no
component along the motion it allows: P none along the rail e3 (the drive
is part of Fbar), A and B no moment about their hinge axis h. Those three
equations fix f across h (two components) and mu, linearly; the force
along h stays free, because a force along h through C does no work on any
joint of the limb (h is parallel to both hinges, normal to the rail, and
passes through the U joint's centre): it is the limb's constraint wrench,
and the platform's balance sum_i W_C,i = w_P fixes its amount s_i.

For the platform three of its six equations are used: the forces along
e1 and e2 and, for the two limbs whose constraint forces (along e1) act at
different points C1, C2, the moment along k = (C2 - C1) x e1. The other
three hold because qdd satisfies the equations of motion (M qdd = b is
exactly H^T of the body equations). Limbs 3 and 4 both carry their
constraint force along e2 through O': only their sum is fixed, and the
difference z (s_3 = 1, s_4 = -1 with no body loaded) is the null direction
of Q; the reactions reported are the particular solution less its
component along z (the least Euclidean norm, as docs/model.md section 13
defines them).

Every lambda coordinate is the joint wrench's component along its basis
vector (the bases are orthonormal and span exactly the directions a joint
transmits), so no dense basis and no linear solve remain: 57 (76)
straight-line expressions, sharing one common-subexpression pass.
"""

from . import sym
from .linalg import vadd, vsub, vscale, dot, cross, matvec

AXES = 3


def _axis_index(e):
    """k when the constant vector e is the unit vector e_k, else None."""
    hits = [k for k in range(AXES) if sym.is_const(e[k], 1)]
    if len(hits) == 1 and all(sym.is_const(e[k], 0)
                              for k in range(AXES) if k != hits[0]):
        return hits[0]
    return None


def _missing_axis(joint, kind):
    """The one world axis of the given kind ('f' or 'm') missing from a
    joint's reaction basis: the direction it leaves free."""
    present = {_axis_index(e) for k, e in joint.basis if k == kind}
    free = [k for k in range(AXES) if k not in present]
    if len(free) != 1:
        raise ValueError("joint %s: expected one free %s axis" %
                         (joint.name, kind))
    return free[0]


def _unit(k):
    return [sym.ONE if i == k else sym.ZERO for i in range(AXES)]


class _Wrench:
    """A moment about point `at` and a force."""

    def __init__(self, moment, force, at):
        self.moment, self.force, self.at = moment, force, at

    def about(self, point):
        """The same wrench as a moment about point: M + (at - point) x F."""
        lever = vsub(self.at, point)
        return _Wrench(vadd(self.moment, cross(lever, self.force)),
                       self.force, point)

    def plus(self, other):
        o = other.about(self.at)
        return _Wrench(vadd(self.moment, o.moment),
                       vadd(self.force, o.force), self.at)

    def scaled(self, k):
        return _Wrench(vscale(k, self.moment), vscale(k, self.force), self.at)


def _zero_wrench(at):
    return _Wrench([sym.ZERO] * 3, [sym.ZERO] * 3, at)


class Reactions:
    """The reaction coordinates of one derivation as expressions of q, qd,
    qdd and the loads (fd, fp, mp symbols given by the caller)."""

    def __init__(self, deriv, qdd, fd, fp, mp):
        self.deriv = deriv
        self.mech = deriv.mech
        self.qdd, self.fd, self.fp, self.mp = qdd, fd, fp, mp
        self.nlimb = len(self.mech.limbs)
        self.joint = {j.name: j for j in self.mech.joints}

    # -- the wrench each body needs -------------------------------------
    def _inertial(self, b):
        """Phi_b H_b qdd + K_b - m_b g: the body's rate of change of
        momentum less its weight, about its centre. The rotational part is
        formed in body axes, where the inertia is constant, and rotated."""
        t = self.deriv.terms[b]
        m = t.body.mass
        jr_qdd = matvec(t.jr_b, self.qdd)
        moment = matvec(t.rotation, vadd(matvec(t.inertia, jr_qdd),
                                         t.gyro_b()))
        accel = vadd(matvec(t.jt, self.qdd), t.mu)
        force = [sym.mul(m, a) - sym.mul(m, g)
                 for a, g in zip(accel, self.deriv.gravity)]
        return _Wrench(moment, force, t.body.centre)

    def _slider_force(self, i):
        """What drive i delivers to its slider along e3: fd_i less the
        armature's k_i d_i'', the damping c_i d_i' and the Coulomb
        friction f_i tanh(d_i' / v_s) (as in Derivation.passive)."""
        d = self.deriv
        dd = d.actuator_rates[i]
        acc = sym.add(d.actuator_bias[i], dot(d._jd[i], self.qdd))
        terms = [self.fd[i], sym.mul(-d.armature[i], acc),
                 sym.mul(-d.damping[i], dd)]
        if d.coulomb[i]:
            terms.append(sym.mul(-d.coulomb[i], sym.tanh(sym.mul(
                1 / d.coulomb_velocity, dd))))
        return sym.add(*terms)

    def body_wrench(self, b):
        """w_b = Phi_b H_b qdd + K_b - Fbar_b."""
        w = self._inertial(b)
        mech = self.mech
        n = self.nlimb
        if b == 0:
            origin = self.deriv.terms[0].body.origin
            applied = _Wrench(list(self.mp), list(self.fp), origin)
            w = w.plus(applied.scaled(-1))
        elif b >= 1 + 2 * n:
            i = b - 1 - 2 * n
            f = self._slider_force(i)
            w = w.plus(_Wrench([sym.ZERO] * 3, [sym.ZERO, sym.ZERO, -f],
                               mech.bodies[b].centre))
        return w

    # -- one limb --------------------------------------------------------
    def _limb_joints(self, i):
        return [self.joint["%s%d" % (k, i + 1)] for k in "CBAP"]

    def limb_constraint_axis(self, i):
        """h: the hinge axis of limb i (its A and B joints share it)."""
        _, jb, ja, _ = self._limb_joints(i)
        h = _missing_axis(jb, "m")
        if _missing_axis(ja, "m") != h:
            raise ValueError("limb %d: hinges A and B not parallel" % (i + 1))
        return h

    def limb_particular(self, i):
        """(W_C with no force along h, the limb's body wrenches L, U, S)."""
        jc, jb, ja, jp = self._limb_joints(i)
        n = self.nlimb
        w_l, w_u, w_s = (self.body_wrench(1 + i), self.body_wrench(1 + n + i),
                         self.body_wrench(1 + 2 * n + i))
        h = self.limb_constraint_axis(i)
        rail = _missing_axis(jp, "f")
        if rail == h:
            raise ValueError("limb %d: rail along the hinges" % (i + 1))
        across = 3 - h - rail
        hv, gv, rv = _unit(h), _unit(across), _unit(rail)
        u = [e for kind, e in jc.basis if kind == "m"][0]
        c = jc.centre
        # P: no force along the rail.
        f_rail = -(w_s.force[rail] + w_u.force[rail] + w_l.force[rail])
        # A and B: no moment about h, a_X f_g + b mu = c_X.
        known_b = w_l.about(jb.centre)
        known_a = w_u.plus(w_l).about(ja.centre)

        def coefficients(point, known):
            r = vsub(c, point)
            a = dot(hv, cross(r, gv))
            e = dot(hv, cross(r, rv))
            return a, -(dot(hv, known.moment) + sym.mul(e, f_rail))

        a_a, c_a = coefficients(ja.centre, known_a)
        a_b, c_b = coefficients(jb.centre, known_b)
        det = dot(hv, cross(vsub(jb.centre, ja.centre), gv))  # a_A - a_B
        f_across = sym.mul(c_a - c_b, sym.power(det, -1))
        mu = sym.mul(c_b - sym.mul(a_b, f_across),
                     sym.power(dot(hv, u), -1))
        force = vadd(vscale(f_across, gv), vscale(f_rail, rv))
        w_c = _Wrench(vscale(mu, u), force, c)
        return w_c, mu, (w_l, w_u, w_s)

    def limb_lambda(self, i, w_c, mu, bodies):
        """The limb's lambda coordinates (C, B, A, P) from its U-joint
        wrench W_C = (force, mu u at C) and body wrenches (None: unloaded)."""
        jc, jb, ja, jp = self._limb_joints(i)
        out = {jc.name: list(w_c.force) + [mu]}
        total = w_c
        for joint, body in zip((jb, ja, jp), bodies or (None,) * 3):
            if body is not None:
                total = total.plus(body)
            at = total.about(joint.centre)
            out[joint.name] = [dot(e, at.force if kind == "f" else at.moment)
                               for kind, e in joint.basis]
        return out

    # -- the platform ------------------------------------------------------
    def solve(self):
        """(lambda, z): the reaction coordinates in joint-table order and
        the unit null direction (None without one)."""
        n = self.nlimb
        origin = self.deriv.terms[0].body.origin
        parts = [self.limb_particular(i) for i in range(n)]
        rho = self.body_wrench(0).about(origin)
        for w_c, _, _ in parts:
            rho = rho.plus(w_c.scaled(-1))
        groups = {}
        for i in range(n):
            groups.setdefault(self.limb_constraint_axis(i), []).append(i)
        s = [sym.ZERO] * n
        nulls = []
        for h, limbs in sorted(groups.items()):
            hv = _unit(h)
            total = rho.force[h]
            centres = [self.joint["C%d" % (i + 1)].centre for i in limbs]
            if all(cc == centres[0] for cc in centres):
                # Concurrent at one point: only the sum is determined; the
                # first limb takes it, the rest are null directions.
                if any(x != y for x, y in zip(centres[0], origin)):
                    raise ValueError("concurrent constraint forces off O'")
                s[limbs[0]] = total
                nulls += [(limbs[0], other) for other in limbs[1:]]
            elif len(limbs) == 2:
                c1, c2 = centres
                k = cross(vsub(c2, c1), hv)
                lever1 = dot(k, cross(vsub(c1, origin), hv))
                s2 = sym.mul(dot(k, rho.moment) - sym.mul(lever1, total),
                             sym.power(dot(k, k), -1))
                s[limbs[1]] = s2
                s[limbs[0]] = total - s2
            else:
                raise ValueError("no closed form for this limb arrangement")
        if len(nulls) > 1:
            raise ValueError("more than one redundant reaction direction")
        lam = {}
        for i, (w_c, mu, bodies) in enumerate(parts):
            zeta = _Wrench([sym.ZERO] * 3, vscale(s[i], _unit(
                self.limb_constraint_axis(i))), w_c.at)
            lam.update(self.limb_lambda(i, w_c.plus(zeta), mu, bodies))
        order = [j.name for j in self.mech.joints]
        flat = [x for name in order for x in lam[name]]
        if not nulls:
            return flat, None
        z = self._null_direction(*nulls[0])
        zz = dot(z, z)
        along = sym.mul(dot(flat, z), sym.power(zz, -1))
        flat = [x - sym.mul(along, zi) for x, zi in zip(flat, z)]
        scale = sym.power(zz, sym.Fraction(-1, 2))
        return flat, [sym.mul(scale, zi) for zi in z]

    def _null_direction(self, first, other):
        """lambda of s_first = 1, s_other = -1 with no body loaded."""
        lam = {}
        for i in range(self.nlimb):
            c = self.joint["C%d" % (i + 1)].centre
            k = 1 if i == first else -1 if i == other else 0
            force = vscale(k, _unit(self.limb_constraint_axis(i)))
            lam.update(self.limb_lambda(i, _Wrench([sym.ZERO] * 3, force, c),
                                        sym.ZERO, None))
        return [x for j in self.mech.joints for x in lam[j.name]]


def null_direction(deriv):
    """The unit null direction of Q (None for three limbs), C3's force along
    e2 positive, as an expression of q."""
    zero = [sym.ZERO] * 3
    r = Reactions(deriv, zero, [sym.ZERO] * len(deriv.mech.limbs), zero, zero)
    return r.solve()[1]
