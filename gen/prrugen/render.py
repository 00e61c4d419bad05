"""Filling the C templates: file headers, kernels, mechanism descriptor."""

import math
import os
import re
from string import Template

from . import batch, cgen, hoist, params, regressor
from .ctext import c_comment, c_string
from .kernels import derivative_kernels, kernels, lambda_labels
from .model import ACTUATOR_KEYS, c_double

GENERATOR = "gen/prru_gen.py"


def _template(templates_dir, name):
    with open(os.path.join(templates_dir, name), encoding="utf-8") as f:
        return Template(f.read())


def _wrap_list(items, indent="  "):
    lines, line = [], indent
    for i, item in enumerate(items):
        piece = item + ("," if i < len(items) - 1 else "")
        if len(line) + len(piece) + 1 > 78 and line.strip():
            lines.append(line.rstrip())
            line = indent
        line += piece + " "
    lines.append(line.rstrip())
    return " \\\n".join(lines)


def _safe_name(name):
    """A file name as the generated files record it: anything outside a
    portable file-name alphabet becomes '_' (it still goes through c_string
    or c_comment like every other text)."""
    return re.sub(r"[^A-Za-z0-9._+-]", "_", name)[:120]


def _tensor3(entries):
    from fractions import Fraction
    xx, yy, zz, xy, xz, yz = entries
    return [[Fraction(xx), xy, xz], [xy, Fraction(yy), yz], [xz, yz, zz]]


def _inverse3(m):
    """Exact inverse of a 3x3 of Fractions (the model checked it regular)."""
    c = [[m[(j + 1) % 3][(i + 1) % 3] * m[(j + 2) % 3][(i + 2) % 3]
          - m[(j + 1) % 3][(i + 2) % 3] * m[(j + 2) % 3][(i + 1) % 3]
          for j in range(3)] for i in range(3)]
    det = sum(m[0][k] * c[k][0] for k in range(3))
    return [[c[i][j] / det for j in range(3)] for i in range(3)]


def _block(values, indent="    "):
    """{a, b, ...} wrapped at 78 columns, continuation lines indented."""
    lines, line = [], "{"
    for i, v in enumerate(values):
        piece = v + (", " if i < len(values) - 1 else "}")
        if len(line) + len(piece.rstrip()) > 74 and line.strip("{"):
            lines.append(line.rstrip())
            line = indent
        line += piece
    lines.append(line)
    return "\n".join(lines)


def _limit(x):
    """A limit in rail units as C: an infinity where the model sets none
    (HUGE_VAL, a double; INFINITY is a float, which -Wdouble-promotion
    refuses to widen)."""
    return ("HUGE_VAL" if x > 0 else "-HUGE_VAL") if math.isinf(x) \
        else c_double(x)


def _designated(fields):
    """A struct initializer from (member, C text) pairs in member order,
    each designated through PRRU_DESIGNATE (DESIGNATE_MACRO): C99 and
    C++20 check every name; older C++ has no designators and reads the
    same list by position."""
    return ",\n".join("  PRRU_DESIGNATE(%s) %s" % f for f in fields)


# Defined and undefined around each initializer by the templates (the
# name is the same for every model: it never leaves its .c file).
DESIGNATE_MACRO = """/* Designated initializers (C99; C++20 in member order); positional in
 * older C++, which has none: the order is the struct's either way. */
#if defined(__cplusplus) && __cplusplus < 202002L
#define PRRU_DESIGNATE(member)
#else
#define PRRU_DESIGNATE(member) .member =
#endif"""


def _descriptor(model, mech, prefix, labels):
    """Initializer fields of the mechanism descriptor, in struct order."""
    nb, nl = len(mech.bodies), len(mech.limbs)
    body_limb = [-1] + [i % nl for i in range(nb - 1)]
    joints = []
    offset = 0
    for j in mech.joints:
        kind = {"C": "U", "B": "R", "A": "R", "P": "P"}[j.name[0]]
        n = len(j.basis)
        joints.append("{%s, '%s', %d, %d, %d, %d, %d}"
                      % (c_string(j.name), kind, int(j.name[1:]) - 1,
                         -1 if j.proximal is None else j.proximal, j.distal,
                         offset, n))
        offset += n
    inertia = [_tensor3(i) for i in model.inertias]
    num = lambda v: c_double(v)  # noqa: E731
    dr = model.drives
    fields = [
        ("name", c_string(model.name)),
        ("description", c_string(model.description)),
        ("model_file", c_string(_safe_name(os.path.basename(model.path)))),
        ("sha256", c_string(model.sha256)),
        ("format", str(model.format)),
        ("nq", "%s_NQ" % prefix.upper()), ("nact", "%s_NACT" % prefix.upper()),
        ("nlimb", "%s_NLIMB" % prefix.upper()),
        ("nbody", "%s_NBODY" % prefix.upper()),
        ("nlambda", "%s_NLAMBDA" % prefix.upper()),
        ("njoint", "%s_NJOINT" % prefix.upper()),
        ("body_names", _block([c_string(b.name) for b in mech.bodies])),
        ("body_limb", _block([str(x) for x in body_limb])),
        ("platform", "0"),
        ("lower", _block([str(1 + i) for i in range(nl)])),
        ("upper", _block([str(1 + nl + i) for i in range(nl)])),
        ("slider", _block([str(1 + 2 * nl + i) for i in range(nl)])),
        ("gravity", _block([num(g) for g in model.gravity])),
        ("mass", _block([num(m) for m in model.masses])),
        ("total_mass", num(model.total_mass)),
        ("com", _block([_block([num(x) for x in c], "      ")
                        for c in model.coms])),
        ("inertia", _block([_block([num(x) for r in t for x in r], "      ")
                            for t in inertia])),
        ("inertia_inv", _block([_block([num(x) for r in _inverse3(t)
                                        for x in r], "      ")
                                for t in inertia])),
        ("b", _block([num(l.b) for l in model.limbs])),
        ("l1", _block([num(l.l1) for l in model.limbs])),
        ("l2", _block([num(l.l2) for l in model.limbs])),
        ("a", _block([num(l.a) for l in model.limbs])),
        ("armature", _block([num(x) for x in model.armature])),
        ("damping", _block([num(x) for x in model.damping])),
        ("coulomb", _block([num(x) for x in model.coulomb])),
        ("coulomb_velocity", num(model.coulomb_velocity or 0)),
        ("joint", "{\n      " + ",\n      ".join(joints) + "}"),
        ("lambda_labels", _block([c_string(l) for l in labels])),
        ("lead", _block([num(x or 0) for x in dr.lead])),
        ("gear", _block([num(x) for x in dr.gear])),
        ("torque_constant", _block([num(x or 0) for x in dr.torque_constant])),
        ("force_max", _block([_limit(dr.force_limit(i)) for i in range(nl)])),
        ("speed_max", _block([_limit(dr.speed_limit(i)) for i in range(nl)])),
        ("d_min", _block([_limit(dr.stroke_limits(i)[0]) for i in range(nl)])),
        ("d_max", _block([_limit(dr.stroke_limits(i)[1]) for i in range(nl)])),
        ("drive_keys", "%du" % sum(1 << k for k, key in enumerate(
            ACTUATOR_KEYS[4:]) if key in dr.keys)),
        ("rotor_inertia", _block([num(x or 0) for x in dr.rotor_inertia])),
        ("torque_max", _block([num(x or 0) for x in dr.torque_max])),
        ("motor_speed_max", _block([num(x or 0) for x in dr.motor_speed_max])),
    ]
    return _designated(fields)


def _head(model, precision=None, option=""):
    """The files' opening comment; precision (a name) only where the
    command line gave --precision, option the set's own option
    (" --derivatives") where one wrote the file."""
    model_file = c_comment(_safe_name(os.path.basename(model.path)))
    what = ", in %s precision" % precision if precision else ""
    option = (" --precision %s" % precision if precision else "") + option
    return ("/* GENERATED FILE: DO NOT EDIT.\n"
            " * Generated by `python3 %s %s%s --out <dir>` from the model file\n"
            " * %s (sha256 %s)%s:\n * %s\n"
            " * Edit the model file or the generator and regenerate instead.\n"
            % (GENERATOR, model_file, option, model_file, model.sha256, what,
               c_comment(model.description)))


def _op_macros(upper, emitted):
    """PREFIX_ARITH_NAME (the count) and PREFIX_OPS_NAME (the summary
    text) of every emitted kernel: what the bench and the docs quote."""
    return (["#define %s_ARITH_%s %d /* arithmetic operations */"
             % (upper, e.name.upper(), e.arithmetic) for e in emitted] +
            ['#define %s_OPS_%s %s' % (upper, e.name.upper(), c_string(e.summary()))
             for e in emitted])


def _banner(head, emitted):
    op_table = "\n".join(" *   %-18s %s" % (e.name, c_comment(e.summary()))
                         for e in emitted)
    return head + (" *\n * Operation counts per kernel:\n%s\n */" % op_table)


def _initializer(model):
    """Fields of <prefix>_params_model, in struct order."""
    rows = []
    for name, value in params.model_values(model):
        if isinstance(value, str):
            text = value
        elif value and isinstance(value[0], list):
            text = _block([_block(v, "      ") for v in value])
        else:
            text = _block(value)
        rows.append((name, text))
    return _designated(rows)


def param_kernel_names():
    """Every runtime-parameter kernel a model's <prefix>_param_kernels.h
    names (each the topology kernel of the same name): the scalar ones,
    their batched variants and the float batch."""
    names = list(params.PARAM_KERNELS)
    scalar = set(names)
    names += ["batch_" + n for n in batch.BATCH_KERNELS if n in scalar]
    names += ["batch_" + f[0] for f in batch.FUSED]
    names += ["f_batch_" + f[0] for f in batch.FLOAT_FUSED]
    return names


def _types_include(header, names):
    """The include that replaces the generated type definitions when they
    come from the library's public header."""
    return "#include \"%s\" /* %s: one type for every model */" % (header, names)


def render_params(model, templates_dir, prefix=None, types_header=None):
    """{file name: text} for model's runtime-parameter kernels: the
    topology kernels of its number of limbs (generated once per topology,
    prru_pN_kernels.h), under the names <prefix>_param_<kernel> and the
    type <prefix>_params, with <prefix>_params_model, the model's numbers.
    Nothing is derived: a model's regeneration no longer pays for them.
    types_header: a header defining <prefix>_params (render's), included
    instead of the typedef to the topology's type; the caller then converts
    its parameters to the topology's type before <prefix>_param_derive."""
    prefix = prefix or model.name
    upper = prefix.upper()
    n = len(model.limbs)
    tprefix = topology_prefix(n)
    tupper = tprefix.upper()
    names = param_kernel_names()
    macros = ["#define %s_param_%s %s_%s" % (prefix, k, tprefix, k) for k in names]
    macros.append("#define %s_param_derive %s_derive" % (prefix, tprefix))
    macros += ["#define %s_PARAM_ARITH_%s %s_ARITH_%s" % (upper, k.upper(), tupper, k.upper())
               for k in params.PARAM_KERNELS]
    macros += ["#define %s_PARAM_OPS_%s %s_OPS_%s" % (upper, k.upper(), tupper, k.upper())
               for k in params.PARAM_KERNELS]
    values = dict(banner=_head(model) + " */", prefix=prefix, PREFIX=upper,
                  tprefix=tprefix, ctype=topology_ctype(n), nlimb=n,
                  macros="\n".join(macros), designate=DESIGNATE_MACRO,
                  initializer=_initializer(model))
    values["params_type"] = (_types_include(types_header, "%s_params" % prefix) if types_header else
                             "typedef %s %s_params;" % (values["ctype"], prefix))
    values["params_is"] = ("%s_params (%s's, converted to %s by the caller)"
                           % (prefix, types_header, values["ctype"]) if types_header else
                           "%s_params\n * is %s" % (prefix, values["ctype"]))
    files = {}
    for tmpl, out in (("param_kernels.h.in", "%s_param_kernels.h" % prefix),
                      ("param_kernels.c.in", "%s_param_kernels.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files


def _topology_head(nlimb, reference, structure="general"):
    ref_file = c_comment(_safe_name(os.path.basename(reference.path)))
    option = "" if structure == "general" else " --structure %s" % structure
    return ("/* GENERATED FILE: DO NOT EDIT.\n"
            " * Generated by `python3 %s --topology %d%s --out <dir>` from the\n"
            " * structure of the %d-limb machine (gen/prrugen/mechanism.py),\n"
            " * whatever model a build uses; only %s_params_reference comes from\n"
            " * a model file, %s (sha256 %s).\n"
            " * Edit the generator and regenerate instead.\n"
            % (GENERATOR, nlimb, option, nlimb, topology_prefix(nlimb), ref_file,
               reference.sha256))


def topology_prefix(nlimb, structure="general"):
    """C prefix of the topology kernels of nlimb limbs: prru_p3, prru_p4;
    of their simple structural variant (params.STRUCTURES) prru_p3s,
    prru_p4s."""
    return "prru_p%d%s" % (nlimb, "s" if structure == "simple" else "")


def topology_ctype(nlimb):
    """Their parameter struct: prru_params3, prru_params4."""
    return "prru_params%d" % nlimb


def topology_derived_ctype(nlimb, structure="general"):
    """The struct their kernels read: prru_p3_derived, prru_p4_derived
    (prru_p3s_derived, ...)."""
    return "%s_derived" % topology_prefix(nlimb, structure)


# The simple variant's header says what it leaves out.
_SIMPLE_NOTE = """
 *
 * Except this: these are the simple structural variant, which takes the
 * decisions above that four kinds of zero allow. They are the kernels of every model of this
 * topology whose centres of mass are at the body frames' origins (com 0),
 * whose inertia tensors are principal in body axes (Ixy = Ixz = Iyz = 0),
 * with no drives (armature, damping and Coulomb force 0) and gravity along
 * -z (gravity[0] = gravity[1] = 0): those members are not read, and the
 * terms they would scale are gone. The runtime evaluates a model with
 * them at load when its numbers are exactly so; for any other model these
 * kernels are wrong. The parameters are %s's."""


def render_topology(reference, pmodel, deriv, templates_dir):
    """{file name: text} for the topology kernels of pmodel =
    params.ParamModel(params.Topology(n)), whose derivation is deriv, and
    the emitted kernels; reference is the model whose numbers initialise
    <prefix>_params_reference."""
    n, structure = pmodel.nlimb, pmodel.structure
    general = structure == "general"
    prefix, ctype = topology_prefix(n, structure), topology_ctype(n)
    dtype = topology_derived_ctype(n, structure)
    upper = prefix.upper()
    hoisted = hoist.Hoisted(pmodel.order)
    derivs = derivative_kernels(deriv)
    kernel_list = params.topology_kernels(deriv, pmodel, dtype, derivs, hoisted)
    # The regressor after the kernels of the constant set, as before the
    # derivatives; it reads the parameters as given (its caller sets the
    # smoothing velocity at every call). Only the general set has one: the
    # regressor's columns are every parameter, whatever a model's values.
    nbase = len(kernel_list) - len(derivs)
    if general:
        kernel_list.insert(nbase, params.plain_kernel(
            regressor.topology_regressor_kernel(deriv, pmodel), pmodel, ctype))
    emitted = [cgen.emit(k, prefix) for k in kernel_list]
    macros = _op_macros(upper, emitted)
    decls, bodies = _sources(emitted, kernel_list, upper, prefix, macros,
                             " Numbers from *p.")
    # The optimiser's and the maps' --precision float: the fused dme_terms
    # in float, <prefix>_f_batch_dme_terms (the numbers converted once);
    # they evaluate designs, whose structure is the general one.
    if general:
        fdecls, fbodies = _float_param_batch(kernel_list, prefix, prefix + "_f")
        decls += "\n\n" + fdecls
        bodies += "\n\n" + fbodies
    # Last, when every kernel has named its slots: the slots from the
    # parameters, once per model.
    derive = cgen.emit(params.derive_kernel(pmodel, ctype, hoisted), prefix)
    macros.insert(0, "#define %s_NDERIVED %d /* slots h of %s */"
                  % (upper, len(hoisted.exprs), dtype))
    macros.insert(1, "#define %s_ARITH_DERIVE %d /* arithmetic operations of "
                  "%s_derive */" % (upper, derive.arithmetic, prefix))
    derive_body = "static %s\n{\n%s\n}" % (derive.signature, derive.body)
    banner = _banner(_topology_head(n, reference, structure), emitted + [derive])
    mech = deriv.mech
    labels = lambda_labels(mech)
    general_header = "%s_kernels.h" % topology_prefix(n)
    values = dict(banner=banner, prefix=prefix, PREFIX=upper, ctype=ctype,
                  dtype=dtype, derive=derive_body, nlimb=n, nbody=len(mech.bodies),
                  njoint=len(mech.joints),
                  nlambda=len(labels),
                  bodies=" ".join(b.name for b in mech.bodies),
                  a3=", a[3]" if n == 4 else "",
                  reference_file=c_comment(_safe_name(os.path.basename(
                      reference.path))),
                  macros="\n".join(macros), declarations=decls,
                  functions=bodies, designate=DESIGNATE_MACRO,
                  initializer=_initializer(reference),
                  labels=_block([c_string(l) for l in labels]),
                  depends="" if general else " and %s" % general_header,
                  structure_note="" if general else _SIMPLE_NOTE % general_header)
    # The parameters' struct, the reference model's numbers and the labels
    # are the general set's; the variant names them from its header.
    if general:
        values["params_block"] = _template(
            templates_dir, "topology_params.h.in").substitute(values)
        values["params_defs"] = _template(
            templates_dir, "topology_params.c.in").substitute(values)
    else:
        values["params_block"] = ('#include "%s" /* %s, %s_params_reference */\n'
                                  % (general_header, ctype, topology_prefix(n)))
        values["params_defs"] = ""
    files = {}
    for tmpl, out in (("topology_kernels.h.in", "%s_kernels.h" % prefix),
                      ("topology_kernels.c.in", "%s_kernels.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files, emitted


def render_regressor(model, rmodel, deriv, templates_dir, prefix=None):
    """{file name: text} for the regressor kernel of model, whose derivation
    deriv was built from rmodel = regressor.RegressorModel(model), and the
    emitted kernels."""
    prefix = prefix or model.name
    upper = prefix.upper()
    emitted = [cgen.emit(regressor.regressor_kernel(model, deriv, rmodel),
                         prefix)]
    names = regressor.param_names(model)
    macros = _op_macros(upper, emitted)
    decls = "\n\n".join("/* %s */\n%s;" % (e.doc, e.signature)
                         for e in emitted)
    bodies = "\n\n".join("%s\n{\n%s\n}" % (e.signature, e.body)
                          for e in emitted)
    values = dict(banner=_banner(_head(model, option=" --regressor"), emitted),
                  prefix=prefix, PREFIX=upper, nreg=len(names), macros="\n".join(macros),
                  declarations=decls, functions=bodies,
                  names=_block([c_string(n) for n in names], "  "),
                  values=_block(regressor.model_values(model), "  "))
    files = {}
    for tmpl, out in (("regressor.h.in", "%s_regressor.h" % prefix),
                      ("regressor.c.in", "%s_regressor.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files, emitted


def _sources(emitted, kernel_list, upper, prefix, macros, doc_suffix):
    """The declarations and the function bodies of a kernel file, scalar
    kernels then batched ones; appends the finiteness-witness and pattern
    macros to macros (in place)."""
    macros += _unseen_macros(kernel_list, upper, prefix)
    patterns = _patterns(kernel_list, upper, prefix)
    macros += [p[0] for p in patterns.values()]
    decls = "\n\n".join("/* %s%s */\n%s;" % (e.doc, doc_suffix, e.signature) +
                        ("\n" + patterns[e.name][1] if e.name in patterns else "")
                        for e in emitted)
    bodies = "\n\n".join((patterns[e.name][2] + "\n\n" if e.name in patterns else "") +
                         "%s\n{\n%s\n}" % (e.signature, e.body)
                         for e in emitted)
    bdecls, bbodies = _batched(kernel_list, prefix, prefix)
    return decls + "\n\n" + bdecls, bodies + "\n\n" + bbodies


def _batched(kernel_list, prefix, file_prefix):
    """(declarations, definitions) of the batched variants of kernel_list's
    kernels (batch.py), named <prefix>_batch_<name>, for the file whose
    macros carry file_prefix."""
    loop = "%s_BATCH_LOOP" % file_prefix.upper()
    targets = "%s_BATCH_TARGETS" % file_prefix.upper()
    vector_trig = "%s_BATCH_%%s" % file_prefix.upper()
    emitted = [batch.emit_batch(k, prefix, loop, vector_trig)
               for k in batch.batch_kernels(kernel_list)]
    decls = "\n\n".join("/* %s */\n%s;" % (e.doc, e.signature)
                        for e in emitted)
    bodies = "\n\n".join("%s %s\n{\n%s\n}" % (targets, e.signature, e.body)
                         for e in emitted)
    return (batch.header_note(prefix) + "\n\n" + decls,
            batch.prologue(file_prefix) + "\n\n" + bodies)


def _unseen_macros(kernel_list, upper, prefix):
    """PREFIX_UNSEEN_FINITE_KERNEL(inputs...): whether the inputs that the
    kernel's witness outputs may not show (cgen.unseen_inputs) are finite,
    for the kernels with witnesses. A macro, so that it costs only its
    tests and the header needs no <math.h>."""
    out = []
    for k in kernel_list:
        if not k.witnesses:
            continue
        unseen = cgen.unseen_inputs(k)
        tests = ["isfinite((%s)[%d])" % (arr, i) for arr, _ in k.inputs
                 for i in unseen[arr]]
        out.append("/* Whether the inputs of %s_%s that may not show in its "
                   "%s are finite:\n   a NaN or an infinity in any other input "
                   "makes one of those outputs NaN or\n   infinite (the "
                   "inputs tested here do not reach them, or reach them only "
                   "through\n   tanh, atan2 or a denominator), so testing "
                   "the outputs tests those inputs (isfinite: <math.h>). */"
                   % (prefix, k.name, " and ".join(k.witnesses)))
        out.append("#define %s_UNSEEN_FINITE_%s(%s) \\\n  (%s)"
                   % (upper, k.name.upper(), ", ".join(arr for arr, _ in k.inputs),
                      " && ".join(tests) if tests else "1"))
    return out


def _patterns(kernel_list, upper, prefix):
    """{kernel name: (macro, declaration, definition)} of the index tables
    of the kernels whose output is sparse (Kernel.pattern)."""
    out = {}
    for k in kernel_list:
        if k.pattern is None:
            continue
        rows, cols, at = k.pattern
        arr = k.outputs[0][0]
        size = "%s_%s_NNZ" % (upper, k.name.upper())
        table = "%s_%s_index" % (prefix, k.name)
        out[k.name] = (
            "#define %s %d /* entries of %s_%s's %s */" % (size, len(at), prefix,
                                                         k.name, arr),
            "/* Row-major positions (row * %d + column) in the dense %dx%d %s "
            "of %s_%s's outputs. */\nextern const int %s[%s];"
            % (cols, rows, cols, arr, prefix, k.name, table, size),
            "const int %s[%s] = {\n%s\n};" % (table, size, "\n".join(
                "  " + ", ".join(str(i) for i in at[r:r + 12]) + ","
                for r in range(0, len(at), 12))))
    return out


def render(model, deriv, templates_dir, prefix=None, types_header=None):
    """{file name: text} for the kernels and mechanism descriptor of model,
    and the emitted kernels. prefix: the C prefix (default: model name).
    types_header: a header that defines <prefix>_joint_info and
    <prefix>_mechanism (the runtime library's prru_descriptor.h, one
    type for every model), included instead of defining them here."""
    prefix = prefix or model.name
    upper = prefix.upper()
    mech = deriv.mech
    kernel_list = kernels(deriv)
    emitted = [cgen.emit(k, prefix) for k in kernel_list]
    labels = lambda_labels(mech)
    head = _head(model)
    banner = _banner(head, emitted)
    macros = ["#define %s_NQ %d" % (upper, len(mech.q)),
              "#define %s_NACT %d" % (upper, len(mech.actuators)),
              "#define %s_NLIMB %d" % (upper, len(mech.limbs)),
              "#define %s_NBODY %d" % (upper, len(mech.bodies)),
              "#define %s_NJOINT %d" % (upper, len(mech.joints)),
              "#define %s_NLAMBDA %d" % (upper, len(labels)),
              "/* Rows of H, Phi, K and the body wrenches (6 per body); the "
              "dimensions of\n   null(J_d^T), actuator forces that move "
              "nothing (an internal preload),\n   and of null(Q), reaction "
              "coordinates no motion or load determines\n   (spec section "
              "12: 0 and 0 with three limbs, 1 and 1 with four). */",
              "#define %s_NH %d" % (upper, 6 * len(mech.bodies)),
              "#define %s_NPRELOAD %d" % (upper, len(mech.actuators) - 3),
              "#define %s_NREACTION_NULL %d"
              % (upper, len(labels) - (6 * len(mech.bodies) - 3)),
              "/* Body order of every array: %s. The model's numbers and "
              "layout tables\n   are in %s_mechanism.h. */"
              % (c_comment(" ".join(b.name for b in mech.bodies)), prefix)]
    macros += _op_macros(upper, emitted)
    decls, bodies = _sources(emitted, kernel_list, upper, prefix, macros, "")
    values = dict(banner=banner, head=head + " */", prefix=prefix,
                  PREFIX=upper, macros="\n".join(macros),
                  declarations=decls, functions=bodies,
                  designate=DESIGNATE_MACRO,
                  descriptor=_descriptor(model, mech, prefix, labels))
    values["types"] = (_types_include(types_header, "%s_joint_info, %s_mechanism" % (prefix, prefix))
                       if types_header else
                       _template(templates_dir, "mechanism_types.h.in").substitute(values))
    files = {}
    for tmpl, out in (("kernels.h.in", "%s_kernels.h" % prefix),
                      ("kernels.c.in", "%s_kernels.c" % prefix),
                      ("mechanism.h.in", "%s_mechanism.h" % prefix),
                      ("mechanism.c.in", "%s_mechanism.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files, emitted


def render_derivs(model, deriv, templates_dir, prefix=None):
    """{file name: text} for the derivative set of model (opt-in,
    --derivatives): the closed-form derivatives of forward and inverse
    dynamics (kernels.derivative_kernels) and their batched variants, in
    <prefix>_derivs.{h,c}, and the emitted kernels. From the same
    derivation as render's kernels, so they agree with them to rounding."""
    prefix = prefix or model.name
    upper = prefix.upper()
    kernel_list = derivative_kernels(deriv)
    emitted = [cgen.emit(k, prefix) for k in kernel_list]
    macros = _op_macros(upper, emitted)
    decls, bodies = _sources(emitted, kernel_list, upper, prefix, macros, "")
    values = dict(banner=_banner(_head(model, option=" --derivatives"), emitted),
                  prefix=prefix, PREFIX=upper, macros="\n".join(macros),
                  declarations=decls, functions=bodies)
    files = {}
    for tmpl, out in (("derivs.h.in", "%s_derivs.h" % prefix),
                      ("derivs.c.in", "%s_derivs.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files, emitted


# The kernels a controller calls (the drop-in set of single precision): the
# kinematics, the dynamics terms, forward and inverse dynamics.
CONTROLLER_KERNELS = ("ik", "jd", "ik_jd", "mass", "bias", "gravity",
                      "dynamics", "eom", "eom_solve", "inverse_terms")


def float_prefix(prefix):
    """The C prefix of the single-precision set: prru -> prru_f."""
    return prefix + "_f"


def render_float(model, deriv, templates_dir, prefix=None):
    """{file name: text} for the single-precision controller kernels of
    model (CONTROLLER_KERNELS, from the same derivation and lowering as the
    double ones, cgen.FLOAT spelling them) named <prefix>_f_*, and the
    emitted kernels. cgen.RangeError (.kernel set) if a constant does not
    fit a float."""
    model_prefix = prefix or model.name
    prefix = float_prefix(model_prefix)
    upper = prefix.upper()
    mech = deriv.mech
    kernel_list = [k for k in kernels(deriv) if k.name in CONTROLLER_KERNELS]
    emitted = []
    for k in kernel_list:
        try:
            emitted.append(cgen.emit(k, prefix, cgen.FLOAT))
        except cgen.RangeError as exc:
            exc.kernel = k.name
            raise
    macros = ["#define %s_NQ %d" % (upper, len(mech.q)),
              "#define %s_NACT %d" % (upper, len(mech.actuators))]
    macros += _op_macros(upper, emitted)
    macros += _unseen_macros(kernel_list, upper, prefix)
    decls = "\n\n".join("/* %s */\n%s;" % (e.doc, e.signature)
                         for e in emitted)
    bodies = "\n\n".join("%s\n{\n%s\n}" % (e.signature, e.body)
                          for e in emitted)
    values = dict(banner=_banner(_head(model, "float"), emitted),
                  prefix=prefix, PREFIX=upper, model_prefix=model_prefix,
                  macros="\n".join(macros), declarations=decls,
                  functions=bodies)
    files = {}
    for tmpl, out in (("float_kernels.h.in", "%s_kernels.h" % prefix),
                      ("float_kernels.c.in", "%s_kernels.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    files.update(_float_batch_files(model, kernels(deriv), templates_dir,
                                    prefix, model_prefix))
    return files, emitted


# FLOAT with FLT_MAX spelled as its value, for a file whose promise is to
# depend on <math.h> alone (the parameter kernels').
FLOAT_NO_FLOAT_H = cgen.Precision("float", cgen.c_float, "f",
                                  cgen.c_float(repr(cgen.FLT_MAX)), "NAN")


def float_batch(kernel_list, prefix, file_prefix=None, precision=cgen.FLOAT):
    """The emitted single-precision batched kernels (batch.FLOAT_FUSED: the
    fused dme_terms) of kernel_list, named <prefix>_batch_<name>, their
    macros carrying file_prefix (default prefix)."""
    upper = (file_prefix or prefix).upper()
    out = []
    for k in batch.batch_kernels(kernel_list, (), batch.FLOAT_FUSED):
        try:
            out.append(batch.emit_batch(k, prefix, "%s_BATCH_LOOP" % upper,
                                        "%s_BATCH_%%s" % upper, precision))
        except cgen.RangeError as exc:
            exc.kernel = k.name
            raise
    return out


def _float_param_batch(kernel_list, prefix, name_prefix):
    """(declarations, definitions) of the float batched kernels of the
    parameter kernels, named <name_prefix>_batch_<name>, their macros
    PREFIX_BATCH_* (the file's)."""
    emitted = float_batch(kernel_list, name_prefix, prefix, FLOAT_NO_FLOAT_H)
    upper = prefix.upper()
    decls = "\n\n".join("/* %s In single precision: %s_f_batch.h's "
                         "conventions, parameters from *p (rounded to float "
                         "once). */\n%s;" % (e.doc, prefix, e.signature)
                         for e in emitted)
    bodies = "\n\n".join("%s_BATCH_TARGETS %s\n{\n%s\n}"
                          % (upper, e.signature, e.body) for e in emitted)
    return decls, batch.float_prologue(prefix) + "\n\n" + bodies


def _float_batch_files(model, kernel_list, templates_dir, prefix,
                       model_prefix):
    """{name: text} of <prefix>_batch.{h,c}: the float batched kernels, in
    files of their own so that a controller's build of <prefix>_kernels.c
    carries none of them."""
    emitted = float_batch(kernel_list, prefix)
    upper = prefix.upper()
    values = dict(banner=_banner(_head(model, "float"), emitted),
                  prefix=prefix, PREFIX=upper, model_prefix=model_prefix,
                  declarations="\n\n".join("/* %s */\n%s;" % (e.doc, e.signature)
                                            for e in emitted),
                  prologue=batch.float_prologue(prefix),
                  functions="\n\n".join("%s_BATCH_TARGETS %s\n{\n%s\n}"
                                         % (upper, e.signature, e.body)
                                         for e in emitted))
    files = {}
    for tmpl, out in (("float_batch.h.in", "%s_batch.h" % prefix),
                      ("float_batch.c.in", "%s_batch.c" % prefix)):
        files[out] = _template(templates_dir, tmpl).substitute(values)
    return files
