#!/usr/bin/env python3
"""Generate the C dynamics kernels of a 3-PRRU model file.

usage: python3 gen/prru_gen.py MODEL.json --out DIR [--prefix NAME]
           [--derivatives] [--regressor] [--quiet]
       python3 gen/prru_gen.py MODEL.json --precision float --out DIR [...]
       python3 gen/prru_gen.py --topology {3,4} [--structure simple] --out DIR

Writes DIR/<prefix>_kernels.{h,c} (the kernels), DIR/<prefix>_mechanism.{h,c}
(the mechanism descriptor) and DIR/<prefix>_param_kernels.{h,c} (the kernels
with the model's numbers as a run-time argument), where <prefix> is the
model's "name" unless --prefix says otherwise. Two sets more on request:
--derivatives writes DIR/<prefix>_derivs.{h,c} (the closed-form derivatives
of forward and inverse dynamics), --regressor DIR/<prefix>_regressor.{h,c}
(the dynamics as a linear function of the inertial and drive parameters, for
identification); the library's build asks for both. With --topology N
instead of a model file, writes DIR/prru_pN_kernels.{h,c}: every kernel
with every number of the model read from a prru_paramsN argument, derived
from the structure of the N-limb machine alone (--structure simple:
DIR/prru_pNs_kernels.{h,c}, the variant for models with no centre-of-mass
offsets, products of inertia or drives and gravity along -z; the same
files whatever model a build uses; the library of
every build carries both). With --precision float instead, writes only
DIR/<prefix>_f_kernels.{h,c}: the controller kernels (render.CONTROLLER_KERNELS)
in single precision, named <prefix>_f_*, so that they link beside the double
set. Nothing in DIR changes unless generation succeeds.
"""

import argparse
import os
import re
import sys
import time

sys.setrecursionlimit(20000)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from prrugen import model as model_mod  # noqa: E402
from prrugen import cgen, mechanism, dynamics, output, params, regressor, \
    render, sym  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEMPLATES = os.path.join(ROOT, "templates")
# The program's name in messages: main's prog ("prru gen" when `prru gen`
# runs it, cli/cmd_gen.c).
_NAME = "prru_gen"


# The opt-in sets of a model's double generation (--derivatives,
# --regressor): what the library's build asks for, and most of the
# generator's time (the default set is the drop-in controller's).
SETS = ("derivatives", "regressor")


def generate(model_path, templates_dir=TEMPLATES, prefix=None, sets=(),
             types_header=None):
    """(files {name: text}, emitted kernels) for a model file."""
    return generate_model(model_mod.load(model_path), templates_dir, prefix,
                          sets, types_header)


def generate_model(model, templates_dir=TEMPLATES, prefix=None, sets=(),
                   types_header=None):
    """(files {name: text}, emitted kernels) for a loaded model: the
    constant kernels, the mechanism descriptor and the runtime-parameter
    kernels' names (the topology kernels', render.render_params); and the
    sets of SETS that sets names: the derivative kernels, the regressor.
    Each set's files are the same whichever others are asked for.
    types_header: the descriptor's and parameters' types come from this
    header (render.render, render.render_params)."""
    unknown = set(sets) - set(SETS)
    if unknown:
        raise ValueError("unknown kernel sets %s" % sorted(unknown))
    sym.reset()
    deriv = dynamics.Derivation(mechanism.build(model), model)
    files, emitted = render.render(model, deriv, templates_dir, prefix,
                                   types_header)
    # The parameter kernels are the topology's (--topology N), named
    # after the model: nothing to derive.
    files.update(render.render_params(model, templates_dir, prefix,
                                      types_header))
    if "derivatives" in sets:
        dfiles, demitted = render.render_derivs(model, deriv, templates_dir,
                                                prefix)
        files.update(dfiles)
        emitted = emitted + demitted
    if "regressor" not in sets:
        return files, emitted
    # A fresh start, so the regressor never depends on the constant
    # kernels' creation order.
    sym.reset()
    rmodel = regressor.RegressorModel(model)
    rderiv = dynamics.Derivation(mechanism.build(rmodel), rmodel)
    rfiles, remitted = render.render_regressor(model, rmodel, rderiv,
                                               templates_dir, prefix)
    files.update(rfiles)
    return files, emitted + remitted


def generate_float(model, templates_dir=TEMPLATES, prefix=None):
    """(files {name: text}, emitted kernels) of the single-precision
    controller kernels of a loaded model (render.render_float): the same
    derivation as generate_model's, spelled in float. ModelError naming
    the model file if a constant of the kernels is finite and nonzero as a
    double but overflows or underflows a float."""
    sym.reset()
    deriv = dynamics.Derivation(mechanism.build(model), model)
    try:
        return render.render_float(model, deriv, templates_dir, prefix)
    except cgen.RangeError as exc:
        raise _range_error(model, exc) from None


def _range_error(model, exc):
    """The ModelError of a constant out of float's range, naming the key of
    the file's number most likely to blame: the largest magnitude for an
    overflow, the smallest nonzero one for an underflow (the kernels'
    constants are products and quotients of the file's numbers)."""
    numbers = [(k, abs(v)) for k, v in model.numbers if v != 0]
    over = abs(exc.value) > 1
    key = None
    if numbers:
        key, value = (max if over else min)(numbers, key=lambda kv: kv[1])
        blame = "; the file's %s number is this one, %s" % (
            "largest" if over else "smallest nonzero", repr(float(value)))
    else:
        blame = ""
    return model_mod.ModelError(
        model.path, key, "cannot be generated in single precision: a constant "
        "of kernel %s derived from the model's numbers, %r, %s%s (rescale "
        "the model's units, or use the double kernels)"
        % (exc.kernel, exc.value, exc.reason, blame))


def generate_topology(nlimb, templates_dir=TEMPLATES, structure="general"):
    """(files {name: text}, emitted kernels) of the topology kernels of
    nlimb limbs (params.Topology): from the structure alone; the reference
    model (params.TOPOLOGY_REFERENCE) supplies only the initializer of
    prru_p<n>_params_reference. structure "simple": the structural variant
    prru_p<n>s (params.STRUCTURES)."""
    reference = model_mod.load(os.path.join(
        ROOT, params.TOPOLOGY_REFERENCE[nlimb]))
    if reference.nlimb != nlimb:
        raise model_mod.ModelError(reference.path, "geometry",
                                   "has %d limbs, the topology %d"
                                   % (reference.nlimb, nlimb))
    sym.reset()
    pmodel = params.ParamModel(params.Topology(nlimb), structure)
    deriv = dynamics.Derivation(mechanism.build(pmodel), pmodel)
    return render.render_topology(reference, pmodel, deriv, templates_dir)


def _prefix(text):
    if not re.fullmatch(r"[a-z][a-z0-9_]{0,15}", text):
        raise argparse.ArgumentTypeError("must be a lower-case C identifier "
                                         "of at most 16 characters")
    return text


def main(argv=None, prog="prru_gen.py"):
    global _NAME
    _NAME = prog[:-3] if prog.endswith(".py") else prog
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Generate C dynamics kernels (prefix = the model's name) "
                    "from a 3-PRRU model file.")
    parser.add_argument("model", nargs="?", help="model file (JSON), e.g. "
                        "models/3prru_paper.json")
    parser.add_argument("--topology", type=int, choices=(3, 4),
                        help="instead of a model file: the kernels of every "
                        "model with this many limbs, the numbers a run-time "
                        "argument (writes prru_p<N>_kernels.{h,c})")
    parser.add_argument("--structure", choices=params.STRUCTURES,
                        default="general",
                        help="with --topology: general (default), every "
                        "number read at run time; simple, the variant for "
                        "models with no centre-of-mass offsets, no products "
                        "of inertia, no drives and gravity along -z (writes "
                        "prru_p<N>s_kernels.{h,c})")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="output directory (created if missing)")
    parser.add_argument("--prefix", metavar="NAME", type=_prefix,
                        help="C prefix of the generated functions and types "
                        "(default: the model's name)")
    parser.add_argument("--precision", choices=("double", "float"),
                        default="double",
                        help="double (default): the kernels, the descriptor "
                        "and the runtime-parameter kernels' names (with "
                        "--derivatives, --regressor their sets); "
                        "float: only the controller kernels in single "
                        "precision, named <prefix>_f_* (writes "
                        "<prefix>_f_kernels.{h,c})")
    parser.add_argument("--derivatives", action="store_true",
                        help="also write <prefix>_derivs.{h,c}: the "
                        "closed-form derivatives of forward and inverse "
                        "dynamics (a model file, double precision)")
    parser.add_argument("--regressor", action="store_true",
                        help="also write <prefix>_regressor.{h,c}: the "
                        "dynamics linear in the inertial and drive "
                        "parameters, for identification (a model file, "
                        "double precision)")
    parser.add_argument("--types", metavar="HEADER",
                        help="include HEADER for the types <prefix>_mechanism, "
                        "<prefix>_joint_info and <prefix>_params instead of "
                        "defining them (the runtime library's build: "
                        "--prefix prru --types prru_descriptor.h, one type "
                        "for every model)")
    parser.add_argument("--quiet", action="store_true",
                        help="print nothing on success")
    args = parser.parse_args(argv)
    if (args.model is None) == (args.topology is None):
        parser.error("give a model file or --topology, not %s"
                     % ("both" if args.model else "neither"))
    if args.topology is not None and args.precision != "double":
        parser.error("--precision float applies to a model file's kernels "
                     "only (the topology kernels are double)")
    sets = tuple(name for name in SETS if getattr(args, name))
    if sets and (args.topology is not None or args.precision != "double"):
        parser.error("--%s applies to a model file's double kernels only "
                     "(the topology kernels carry every set)" % sets[0])
    args.sets = sets
    if args.topology is None and args.structure != "general":
        parser.error("--structure applies to --topology only")
    if args.types and (args.model is None or args.precision != "double"):
        parser.error("--types applies to a model file's double kernels only")
    if args.types and not re.fullmatch(r"[A-Za-z0-9_./-]+\.h", args.types):
        parser.error("--types: %r is not a header name of letters, digits, "
                     "_ . / - ending in .h" % args.types)
    if args.topology is not None and args.prefix:
        parser.error("--prefix applies to a model file's kernels only "
                     "(the topology kernels are prru_p<N>_*)")
    return output.run_stoppable("prru_gen", args.out, lambda: _run(args))


def _run(args):
    start = time.perf_counter()
    try:
        if args.topology is not None:
            files, emitted = generate_topology(args.topology,
                                               structure=args.structure)
        else:
            model = model_mod.load(args.model)
    except model_mod.ModelError as exc:
        print("%s: error: %s" % (_NAME, exc), file=sys.stderr)
        return 1
    if args.topology is None:
        for warning in model.warnings():
            print("%s: warning: %s: %s" % (_NAME, args.model, warning),
                  file=sys.stderr)
        try:
            if args.precision == "float":
                files, emitted = generate_float(model, prefix=args.prefix)
            else:
                files, emitted = generate_model(model, prefix=args.prefix,
                                                sets=args.sets,
                                                types_header=args.types)
        except model_mod.ModelError as exc:
            print("%s: error: %s" % (_NAME, exc), file=sys.stderr)
            return 1
    try:
        output.write_files_atomically(args.out, files)
    except OSError as exc:
        print("%s: error: %s: cannot write: %s"
              % (_NAME, args.out, exc.strerror), file=sys.stderr)
        return 1
    if not args.quiet:
        width = max(18, max(len(e.name) for e in emitted))
        for e in emitted:
            print("%-*s %s" % (width, e.name, e.summary()))
        print("wrote %s in %.2f s" % (", ".join(os.path.join(args.out, n)
                                                for n in sorted(files)),
                                       time.perf_counter() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
