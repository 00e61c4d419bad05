"""Runtime-parameter kernels: the model's numbers as symbols.

The mechanism (mechanism.py) and the derivation (dynamics.py) read every
number of a model from one place, the Model's fields. A ParamModel has the
same fields, but holding symbols named after the C struct member that will
carry them at run time (`b[0]`, `inertia[3][5]`, ...), so the same
derivation yields expressions in q, qd and the parameters. Only the
structure stays fixed by the model: the number of limbs, and a = 0 for
limbs 3 and 4 (their U joint is O' itself). Every value is a symbol, so no
simplification that depends on a value (a zero centre of mass, zero
products of inertia, no drives, gravity along -z, b1 = b2 in format 1) is
taken: the kernels are right for any parameter values.
"""

import re
from fractions import Fraction

from . import sym
from .cgen import Kernel, ParamsArg
from .kernels import kernels
from .model import Limb, body_names, c_double

# Kernels generated in the parameter form, in header order: those an
# optimizer or a sensitivity study evaluates (kinematics, dynamics, energy),
# not the per-body layout tables (poses, jacobians, reaction_basis, ...).
PARAM_KERNELS = ("ik", "jd", "ik_jd", "mass", "bias", "gravity", "dynamics",
                 "eom", "platform_jacobian", "energy", "actuator_rates",
                 "passive")

# Symbol names carry this prefix so that they can never meet an input's
# name (q1, qd2, fd3, ...).
_PREFIX = "p->"


def member(name):
    """The parameter symbol of the struct member `name`, e.g. 'com[2][0]'."""
    return sym.sym(_PREFIX + name)


def local_name(symbol_name):
    """C local that holds a parameter inside a kernel: 'p->com[2][0]' ->
    'p_com_2_0'."""
    return "p_" + re.sub(r"[^A-Za-z0-9]+", "_",
                         symbol_name[len(_PREFIX):]).strip("_")


class Topology:
    """What ParamModel reads of a model, the structure alone: the number of
    limbs (and so the bodies). The topology kernels are derived from it, so
    no model file's numbers can reach them."""

    def __init__(self, nlimb):
        self.nlimb = nlimb
        self.body_names = body_names(nlimb)


# The model file whose numbers initialise prru_p<n>_params_reference, per
# topology (relative to the source tree): a valid model of that topology
# for tests and examples; the kernels do not depend on it.
TOPOLOGY_REFERENCE = {3: "models/3prru_paper.json", 4: "models/4prru.json"}


# The structures a topology's kernels are generated for: general (every
# number a parameter) and simple, the structural variant of models with
# no centre-of-mass offsets, principal-axis inertias (no products of
# inertia), no drives and gravity along -z (the paper's model and its
# 4-limb variant): those numbers are zero in its kernels, not read, and the
# runtime chooses it at load when a model's numbers are exactly so
# (prru_param_structure_simple).
STRUCTURES = ("general", "simple")


class ParamModel:
    """The fields of a Model that the derivation reads, as symbols; with
    structure "simple", the numbers STRUCTURES says are zero are zero."""

    def __init__(self, model, structure="general"):
        if structure not in STRUCTURES:
            raise ValueError("unknown structure %r" % structure)
        simple = structure == "simple"
        zero = Fraction(0)
        n, nb = model.nlimb, len(model.body_names)
        vec = lambda key: tuple(member("%s[%d]" % (key, i))  # noqa: E731
                                for i in range(n))
        b, l1, l2, a = vec("b"), vec("l1"), vec("l2"), vec("a")
        self.limbs = tuple(Limb(b[i], l1[i], l2[i],
                                a[i] if i < 2 else Fraction(0))
                           for i in range(n))
        self.gravity = tuple(zero if simple and k < 2 else
                             member("gravity[%d]" % k) for k in range(3))
        self.masses = tuple(member("mass[%d]" % j) for j in range(nb))
        self.coms = tuple(tuple(zero if simple else
                                member("com[%d][%d]" % (j, k))
                                for k in range(3)) for j in range(nb))
        self.inertias = tuple(tuple(zero if simple and k >= 3 else
                                    member("inertia[%d][%d]" % (j, k))
                                    for k in range(6)) for j in range(nb))
        drive = (lambda key: (zero,) * n) if simple else vec  # noqa: E731
        self.armature = drive("armature")
        self.damping = drive("damping")
        self.coulomb = drive("coulomb")
        self.coulomb_velocity = member("coulomb_velocity")
        self.body_names = model.body_names
        self.nlimb = n
        self.structure = structure
        self.order = [x.args[0] for x in
                      b + l1 + l2 + a + self.gravity + self.masses
                      + sum(self.coms, ()) + sum(self.inertias, ())
                      + self.armature + self.damping + self.coulomb
                      + (self.coulomb_velocity,)
                      if not isinstance(x, Fraction)]


def is_param(name):
    return name.startswith(_PREFIX)


def model_values(model):
    """The model's own numbers in struct order, as (member, C literal) rows
    of the initializer of <prefix>_params_model. A model without Coulomb
    friction has no smoothing velocity; 1 m/s stands in for it, so that
    f tanh(dd / v_s) is 0, not 0 * NaN, at f = 0."""
    num = lambda v: c_double(v)  # noqa: E731
    limbs = model.limbs
    vs = model.coulomb_velocity if model.coulomb_velocity else Fraction(1)
    return [
        ("b", [num(l.b) for l in limbs]),
        ("l1", [num(l.l1) for l in limbs]),
        ("l2", [num(l.l2) for l in limbs]),
        ("a", [num(l.a) for l in limbs]),
        ("gravity", [num(g) for g in model.gravity]),
        ("mass", [num(m) for m in model.masses]),
        ("com", [[num(x) for x in c] for c in model.coms]),
        ("inertia", [[num(x) for x in i] for i in model.inertias]),
        ("armature", [num(x) for x in model.armature]),
        ("damping", [num(x) for x in model.damping]),
        ("coulomb", [num(x) for x in model.coulomb]),
        ("coulomb_velocity", num(vs)),
    ]


def _access(symbol_name):
    return symbol_name.replace(_PREFIX, "p->", 1)


def param_kernels(deriv, pmodel, prefix):
    """The PARAM_KERNELS of deriv, the derivation of ParamModel pmodel, each
    with the leading `const <prefix>_params *p` argument."""
    arg = ParamsArg("%s_params" % prefix, pmodel.order, local_name, _access)
    return [Kernel(k.name, k.doc, k.inputs, k.outputs, k.guards, arg)
            for k in kernels(deriv) if k.name in PARAM_KERNELS]


def _derived_access(symbol_name):
    """A member of the derived numbers (<prefix>_derived): the parameters
    as given are its member params, the slots its h."""
    if symbol_name.startswith(_PREFIX + "h["):
        return _access(symbol_name)
    return symbol_name.replace(_PREFIX, "p->params.", 1)


def derive_kernel(pmodel, ctype, hoisted):
    """The kernel that computes the slots of hoisted (hoist.Hoisted) from
    the parameters, `const <ctype> *p`: the output h of
    <prefix>_derive."""
    arg = ParamsArg(ctype, pmodel.order, local_name, _access)
    return Kernel("hoisted", "The derived numbers h of the topology kernels "
                  "(hoisted subexpressions of the parameters alone) from *p.",
                  [], [("h", list(hoisted.exprs))], (), arg)


def topology_kernels(deriv, pmodel, ctype, extra=(), hoisted=None):
    """Every kernel of deriv, the derivation of ParamModel pmodel, and the
    kernels extra of the same derivation, each with the leading `const
    <ctype> *p` argument: the topology kernels. With hoisted (a
    hoist.Hoisted), ctype is the derived numbers' struct and every
    parameter-only subexpression is read from its slots."""
    if hoisted is None:
        arg = ParamsArg(ctype, pmodel.order, local_name, _access)
    else:
        arg = ParamsArg(ctype, pmodel.order, local_name, _derived_access, hoisted)
    return [Kernel(k.name, k.doc, k.inputs,
                   [("pos" if arr == "p" else arr, x) for arr, x in k.outputs],
                   k.guards, arg, k.witnesses, k.pattern)
            for k in list(kernels(deriv)) + list(extra)]


def plain_kernel(k, pmodel, ctype):
    """Kernel k with the leading `const <ctype> *p` argument of the
    parameters as given, nothing hoisted: for a kernel whose caller changes
    a parameter at every call (the regressor's smoothing velocity)."""
    arg = ParamsArg(ctype, pmodel.order, local_name, _access)
    return Kernel(k.name, k.doc, k.inputs, k.outputs, k.guards, arg,
                  k.witnesses, k.pattern)
