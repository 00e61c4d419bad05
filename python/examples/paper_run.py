#!/usr/bin/env python3
"""The paper's simulation study (section 4.3) from Python.

    python3 python/examples/paper_run.py [LIBPRRU]

1 s from q(0) = (0, pi/6, -0.8) under fd = (50, 40, 25) N and the harmonic
platform force 50 (sin 4 pi t, -cos 4 pi t, 0) N; prints q and qd at 1 s,
the change of T + V, and the largest U-joint reaction force. LIBPRRU is
libprru.so or a build directory (default: $PRRU_LIB, else build/ of this
source tree, as `make demo` or `make test` leaves it).
"""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import prru  # noqa: E402


def main(argv):
    model = prru.Model(argv[1] if len(argv) > 1 else None)
    print("model %s (%s), %d actuators" % (model.name, model.model_file, model.nact))
    run = model.simulate(scenario="paper", reactions=True)
    print("q(%g s)  = (%.9f, %.9f, %.9f)" % (run.t[-1], *run.q[-1]))
    print("qd(%g s) = (%.9f, %.9f, %.9f)" % (run.t[-1], *run.qd[-1]))
    energy = [T + V for T, V in zip(run.T, run.V)]
    print("T + V changed by %.5f J in %d samples" % (energy[-1] - energy[0], len(run)))
    # The force of each lower link on the platform at its U joint C_i
    # (the first three reaction coordinates of joint C_i, in {S}).
    for j in model.joints:
        if j.type == "U":
            k = j.lambda_offset
            peak = max(math.sqrt(sum(x * x for x in lam[k:k + 3])) for lam in run.lambda_)
            print("largest |force| at %s: %.3f N" % (j.name, peak))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
