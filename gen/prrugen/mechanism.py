"""The 3-PRRU mechanism: poses of its ten bodies as closed functions of q.

This is the only place the mechanism's geometry is written down. Everything
else (Jacobians, bias terms, mass matrix, reactions) is derived from it.

Orientation is kept as a chain of elementary rotations [(axis, angle(q))],
R = Rot(axis_1, angle_1) Rot(axis_2, angle_2) ..., so that angular velocity
follows from the chain rule on the angles instead of from R^T dR/dt, whose
entries only cancel to the short form after trigonometric identities.
"""

from fractions import Fraction

from . import sym
from .linalg import vec, vadd, vsub, vscale, matvec, matmul, identity, rot, \
    unit, cross

X, Y, Z = 0, 1, 2


class Body:
    def __init__(self, name, chain, origin, mass, com, inertia):
        self.name = name
        self.chain = chain            # [(axis, angle expression)]
        self.origin = origin          # frame origin of the pose functions
        self.mass = mass              # Fraction
        self.com = com                # centre of mass in the body frame
        self.inertia = inertia        # 3x3 tensor about the centre, body axes
        # p_b = origin_b + R_b com: the centre every Newton-Euler quantity
        # refers to (the origin itself when com = 0).
        if any(com):
            self.centre = vadd(origin, matvec(self.rotation, vec(*com)))
        else:
            self.centre = origin

    @property
    def rotation(self):
        r = identity()
        for axis, angle in self.chain:
            r = matmul(r, rot(axis, angle))
        return r


class Joint:
    """A joint's reaction wrench: basis [(kind 'f' or 'm', unit vector)]."""

    def __init__(self, name, proximal, distal, centre, basis):
        self.name = name
        self.proximal = proximal      # body index, or None for the rails
        self.distal = distal
        self.centre = centre
        self.basis = basis


class Mechanism:
    def __init__(self, q, qd, bodies, joints, actuators, guards, limbs,
                 atoms):
        self.q, self.qd = q, qd
        self.atoms = atoms            # defined angle symbols (see atom())
        self.limbs = limbs            # per limb: joint centres, d, slider
        self.bodies = bodies
        self.joints = joints
        self.actuators = actuators    # d_i(q): slider heights
        self.guards = guards          # acos arguments that must lie in [-1, 1]


def _limb12(s, g, platform_rot, p_platform):
    """Limbs 1 (s = -1) and 2 (s = +1): in the plane x = 0, hinges along e1."""
    c_joint = vadd(p_platform, matvec(platform_rot, vec(0, s * g.a, 0)))
    r_lower = rot(X, sym.sym("q1"))
    b_joint = vadd(c_joint, matvec(r_lower, vec(0, s * g.l2, 0)))
    p_lower = vadd(c_joint, matvec(r_lower, vec(0, s * g.l2 / 2, 0)))
    y_a = s * g.b
    cos_arg = s * (y_a - b_joint[Y]) / g.l1
    alpha = s * sym.acos(cos_arg)
    d = b_joint[Z] + s * g.l1 * sym.sin(alpha)
    a_joint = vec(0, y_a, d)
    p_upper = vscale(Fraction(1, 2), vadd(a_joint, b_joint))
    return dict(c=c_joint, b=b_joint, a=a_joint, d=d, guard=cos_arg,
                lower=([(X, sym.sym("q1"))], p_lower),
                upper=([(X, alpha)], p_upper),
                slider=([], a_joint))


def atom(name, value, q, qd):
    """value(q) as a defined symbol (an atom, see sym.define) whose partial
    derivatives d value / d q_j, rate value' = J qd and rate bias J' qd are
    atoms too: the poses, and whatever is differentiated from them, stay
    polynomials in the atom's sin and cos and these few symbols."""
    dt = sym.TimeDerivative(q, qd)
    partials = {x: sym.define("%s_%s" % (name, x.args[0]), sym.diff(value, x))
                for x in q if not sym.is_const(sym.diff(value, x), 0)}
    used = [(partials[x], v) for x, v in zip(q, qd) if x in partials]
    bias = sym.define(name + "_bias",
                      sym.add(*[sym.mul(dt(p), v) for p, v in used]))
    rate = sym.define(name + "_rate", sym.add(*[sym.mul(p, v) for p, v in used]),
                      rate=bias)
    return sym.define(name, value, partials, rate)


def _gamma(q, qd):
    """The lower links of limbs 3 and 4 turn about e2 by gamma: their axis
    x3 = Ry(gamma) e1 is the direction in the plane y = 0 normal to the
    platform's R_P e3 = (sin q2, -sin q1 cos q2, cos q1 cos q2)."""
    q1, q2 = q[0], q[1]
    return atom("gamma", sym.atan2(sym.sin(q2), sym.cos(q1) * sym.cos(q2)),
                q, qd)


def _limb34(s, g, p_platform, gamma):
    """Limb 3 (s = +1) and its mirror, the redundant limb 4 (s = -1, spec
    section 12): in the plane y = 0, hinges along e2, U joint centre O',
    rail at x = s b, lower link along s x3."""
    x3 = matvec(rot(Y, gamma), unit(X))
    outward = x3 if s > 0 else [-x for x in x3]
    b_joint = vadd(p_platform, vscale(s * g.l2, x3))
    p_lower = vadd(p_platform, vscale(s * g.l2 / 2, x3))
    cos_arg = (b_joint[X] - s * g.b) / g.l1
    alpha = sym.acos(cos_arg)
    d = b_joint[Z] + g.l1 * sym.sin(alpha)
    a_joint = vec(s * g.b, 0, d)
    p_upper = vscale(Fraction(1, 2), vadd(a_joint, b_joint))
    return dict(c=p_platform, b=b_joint, a=a_joint, d=d, guard=cos_arg,
                x3=outward, lower=([(Y, gamma)], p_lower),
                upper=([(Y, alpha)], p_upper),
                slider=([], a_joint))


def build(model):
    """The mechanism of a validated model (see model.py)."""
    g = model.limbs
    q = [sym.sym("q1"), sym.sym("q2"), sym.sym("q3")]
    qd = [sym.sym("qd1"), sym.sym("qd2"), sym.sym("qd3")]
    platform_chain = [(X, q[0]), (Y, q[1])]
    p_platform = vec(0, 0, q[2])
    platform_rot = matmul(rot(X, q[0]), rot(Y, q[1]))
    gamma = _gamma(q, qd)
    limbs = [_limb12(-1, g[0], platform_rot, p_platform),
             _limb12(+1, g[1], platform_rot, p_platform),
             _limb34(+1, g[2], p_platform, gamma)]
    if len(g) == 4:
        limbs.append(_limb34(-1, g[3], p_platform, gamma))

    parts = [(platform_chain, p_platform)]
    parts += [limb["lower"] for limb in limbs]
    parts += [limb["upper"] for limb in limbs]
    parts += [limb["slider"] for limb in limbs]
    bodies = [Body(name, chain, origin, model.masses[i], model.coms[i],
                   _tensor(model.inertias[i]))
              for i, (name, (chain, origin)) in
              enumerate(zip(model.body_names, parts))]

    joints = _joints(limbs, platform_rot)
    guards = []
    for limb in limbs:
        if limb["guard"] not in guards:
            guards.append(limb["guard"])
    return Mechanism(q, qd, bodies, joints, [l["d"] for l in limbs], guards,
                     limbs, [gamma])


def _tensor(entries):
    """(Ixx, Iyy, Izz, Ixy, Ixz, Iyz) -> symmetric 3x3 of constants (or of
    parameter symbols, for the runtime-parameter kernels)."""
    xx, yy, zz, xy, xz, yz = (sym.as_expr(v) for v in entries)
    return [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]


def _force_basis():
    return [("f", unit(X)), ("f", unit(Y)), ("f", unit(Z))]


def _joints(limbs, platform_rot):
    """The joint table, in lambda order: every limb's C, then B, A, P."""
    n = len(limbs)
    P_, L_, U_, S_ = 0, 1, 1 + n, 1 + 2 * n     # first body of each group
    u = [row[X] for row in platform_rot]          # R_P e1
    w = [row[Z] for row in platform_rot]          # R_P e3
    joints = []
    for i, limb in enumerate(limbs):
        axis = u if i < 2 else cross(w, limb["x3"])
        joints.append(Joint("C%d" % (i + 1), L_ + i, P_, limb["c"],
                            _force_basis() + [("m", axis)]))
    for name, prox, dist, key in (("B", U_, L_, "b"), ("A", S_, U_, "a")):
        for i, limb in enumerate(limbs):
            hinge = X if i < 2 else Y
            moments = [("m", unit(k)) for k in (X, Y, Z) if k != hinge]
            joints.append(Joint("%s%d" % (name, i + 1), prox + i, dist + i,
                                limb[key], _force_basis() + moments))
    for i, limb in enumerate(limbs):
        # The prismatic joint's moment is taken about the slider centre A_i.
        joints.append(Joint("P%d" % (i + 1), None, S_ + i, limb["a"],
                            [("f", unit(X)), ("f", unit(Y))]
                            + [("m", unit(k)) for k in (X, Y, Z)]))
    return joints
