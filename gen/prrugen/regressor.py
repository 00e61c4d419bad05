"""Regressor kernels: the dynamics as a linear function of the inertial and
drive parameters, for identification.

With no platform loads, the actuator forces fd balance

  J_d^T fd = M qdd + h - G - passive = Y(q, qd, qdd) pi

and the right-hand side is linear in the standard parameters pi of every
body b, in body order,

  m_b, m_b c_b (3: the first moment, c_b the centre of mass in the body
  frame), I_O,b (6: Ixx Iyy Izz Ixy Ixz Iyz of the inertia tensor about the
  body-frame origin, body axes),

followed by the armature k_i, viscous damping c_i and Coulomb force f_i of
every actuator (f_i for the model's or a given smoothing velocity v_s,
which enters non-linearly and is an input). The model file's inertia is
about the centre of mass, I_c; about the origin it is
I_O = I_c + m (|c|^2 E - c c^T), the one choice that keeps the dynamics
linear in pi.

No second derivation: the runtime-parameter machinery (params.py) already
derives the dynamics with every model number a symbol. Here geometry and
gravity stay the model's numbers and the inertial and drive parameters are
symbols (m, c, I_c, k, c, f), and column j of Y is the derivative of the
dynamics with respect to parameter j, at m = 1, c = 0, I_c = 0 (so that
I_O = I_c): writing tau(m, c, I_c) = L(m, m c, I_c + m(|c|^2 E - c c^T))
with L linear, d tau/dm = L(1, 0, 0), d tau/dc_k = m L(0, e_k, 0) and
d tau/dI_c = L(0, 0, E_j) at that point, and the drive terms are linear
already. The expressions, once substituted, hold for every pi because tau
is linear in it.
"""

from fractions import Fraction

from . import sym
from .cgen import Kernel
from .model import c_double
from .params import ParamModel

BODY_PARAMS = ("m", "mcx", "mcy", "mcz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz",
               "Iyz")
DRIVE_PARAMS = ("armature", "damping", "coulomb")


def param_names(model):
    """Names of the standard parameters in Y's column order, e.g. 'P.m',
    'L1.mcx', 'S3.Iyz', 'armature1'."""
    names = ["%s.%s" % (b, p) for b in model.body_names for p in BODY_PARAMS]
    for p in DRIVE_PARAMS:
        names += ["%s%d" % (p, i + 1) for i in range(model.nlimb)]
    return names


class RegressorModel(ParamModel):
    """The model's geometry and gravity as numbers, its inertial and drive
    parameters as symbols, and the Coulomb smoothing velocity as the
    kernel input vs1."""

    def __init__(self, model):
        super().__init__(model)
        self.limbs = model.limbs
        self.gravity = tuple(model.gravity)
        self.coulomb_velocity = sym.sym("vs1")


def substitute(exprs, values):
    """exprs with the symbols named in values (name -> Fraction) replaced
    by those numbers, rebuilt through the engine's simplifying
    constructors."""
    memo = {}

    def sub(e):
        e = sym.as_expr(e)
        hit = memo.get(e.id)
        if hit is not None:
            return hit
        op = e.op
        if op == "const":
            r = e
        elif op == "sym":
            v = values.get(e.args[0])
            r = e if v is None else sym.const(v)
        elif op == "add":
            c, terms = e.args
            r = sym.add(c, *[sym.mul(k, sub(t)) for k, t in terms])
        elif op == "mul":
            coef, factors = e.args
            r = sym.mul(coef, *[sym.power(sub(b), x) for b, x in factors])
        else:
            r = getattr(sym, op)(*[sub(a) for a in e.args])
        memo[e.id] = r
        return r

    return [sub(e) for e in exprs]


def _columns(rmodel, deriv, qdd):
    """Y (3 x np, row-major) from a derivation of RegressorModel rmodel."""
    m, h, g = deriv.mass(), deriv.bias(), deriv.gravity_force()
    passive = deriv.passive()
    tau = [sym.add(*([sym.mul(m[3 * i + j], qdd[j]) for j in range(3)]
                     + [h[i], -g[i], -passive[i]])) for i in range(3)]
    unknowns = []
    for b in range(len(rmodel.masses)):
        unknowns += [rmodel.masses[b]] + list(rmodel.coms[b]) \
            + list(rmodel.inertias[b])
    unknowns += list(rmodel.armature) + list(rmodel.damping) \
        + list(rmodel.coulomb)
    point = {}
    for b in range(len(rmodel.masses)):
        point[rmodel.masses[b].args[0]] = Fraction(1)
        for x in rmodel.coms[b] + rmodel.inertias[b]:
            point[x.args[0]] = Fraction(0)
    rows = [[sym.diff(t, u) for u in unknowns] for t in tau]
    flat = [x for r in rows for x in r]
    return substitute(flat, point), len(unknowns)


_MOTION = [("q", ["q1", "q2", "q3"]), ("qd", ["qd1", "qd2", "qd3"]),
           ("qdd", ["qdd1", "qdd2", "qdd3"])]


def _kernel(deriv, rmodel, doc_tail, extra_inputs):
    """The Kernel `regressor` of derivation deriv of rmodel (whose
    inertial and drive numbers are symbols); doc_tail ends its comment."""
    qdd = [sym.sym("qdd%d" % (i + 1)) for i in range(3)]
    y, npar = _columns(rmodel, deriv, qdd)
    doc = ("Regressor Y (3x%d, row-major) with J_d^T fd = M qdd + h - G - "
           "passive = Y pi, pi the standard parameters %s" % (npar, doc_tail))
    return Kernel("regressor", doc, _MOTION + extra_inputs, [("Y", y)],
                  deriv.mech.guards)


def regressor_kernel(model, deriv, rmodel):
    """The Kernel `regressor` of the derivation deriv of
    RegressorModel(model)."""
    return _kernel(deriv, rmodel, "(see PRRU_REGRESSOR_NAMES); vs[0] is the "
                   "Coulomb smoothing velocity v_s (m/s, > 0).",
                   [("vs", ["vs1"])])


def topology_regressor_kernel(deriv, pmodel):
    """The Kernel `regressor` of the topology derivation deriv of
    params.ParamModel pmodel: geometry, gravity and the Coulomb smoothing
    velocity are its parameters (p->b[i], ..., p->coulomb_velocity), the
    inertial and drive parameters differentiated away as above, so that a
    model of any numbers loaded at run time is identified with the same
    regressor as its own build's (whose numbers are constants there)."""
    return _kernel(deriv, pmodel, "(prru_regressor.h's order); geometry, "
                   "gravity and the Coulomb smoothing velocity from *p, its "
                   "inertial and drive numbers unused.", [])


def model_standard(model):
    """The model's standard parameters in column order, exact: m, m c and
    the inertia about the body-frame origin, then the drives."""
    out = []
    for m, c, i in zip(model.masses, model.coms, model.inertias):
        xx, yy, zz, xy, xz, yz = (Fraction(v) for v in i)
        cx, cy, cz = (Fraction(v) for v in c)
        m = Fraction(m)
        s = cx * cx + cy * cy + cz * cz
        out += [m, m * cx, m * cy, m * cz,
                xx + m * (s - cx * cx), yy + m * (s - cy * cy),
                zz + m * (s - cz * cz),
                xy - m * cx * cy, xz - m * cx * cz, yz - m * cy * cz]
    for group in (model.armature, model.damping, model.coulomb):
        out += [Fraction(v) for v in group]
    return out


def model_values(model):
    """C literals of model_standard(model)."""
    return [c_double(v) for v in model_standard(model)]
