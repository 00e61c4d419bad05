#!/usr/bin/env python3
"""Generate the C dynamics kernels of a 3-PRRU model file.

usage: python3 gen/prru_gen.py MODEL.json --out DIR [--quiet]

Writes DIR/<name>_kernels.h and DIR/<name>_kernels.c, where <name> is the
model's "name". Nothing in DIR changes unless generation succeeds.
"""

import argparse
import os
import sys
import time

sys.setrecursionlimit(20000)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from prrugen import model as model_mod  # noqa: E402
from prrugen import mechanism, dynamics, output, render  # noqa: E402

TEMPLATES = os.path.join(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))), "templates")


def generate(model_path, templates_dir=TEMPLATES):
    """(files {name: text}, emitted kernels) for a model file."""
    model = model_mod.load(model_path)
    deriv = dynamics.Derivation(mechanism.build(model), model.gravity)
    return render.render(model, deriv, templates_dir)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="prru_gen.py",
        description="Generate C dynamics kernels (prefix = the model's name) "
                    "from a 3-PRRU model file.")
    parser.add_argument("model", help="model file (JSON), e.g. "
                        "models/3prru_paper.json")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="output directory (created if missing)")
    parser.add_argument("--quiet", action="store_true",
                        help="print nothing on success")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    try:
        files, emitted = generate(args.model)
    except model_mod.ModelError as exc:
        print("prru_gen: error: %s" % exc, file=sys.stderr)
        return 1
    try:
        output.write_files_atomically(args.out, files)
    except OSError as exc:
        print("prru_gen: error: %s: cannot write: %s"
              % (args.out, exc.strerror), file=sys.stderr)
        return 1
    if not args.quiet:
        for e in emitted:
            print("%-18s %s" % (e.name, e.summary()))
        print("wrote %s in %.2f s" % (", ".join(os.path.join(args.out, n)
                                                for n in sorted(files)),
                                       time.perf_counter() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
