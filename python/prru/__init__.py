"""prru: dynamics of the 3-PRRU parallel manipulator from Python.

A ctypes binding of libprru.so (the prru runtime as a shared library, CMake
target prru_shared, built as BUILD/runtime/libprru.so), standard library
only; NumPy arrays are accepted as inputs and, with numpy=True, returned.

    import prru
    m = prru.Model()                        # or Model("build/runtime/libprru.so")
    d, Jd = m.ik([0, 0.2, -0.8])            # slider heights, J_d
    M, h, G = m.dynamics([0, 0.2, -0.8], [0.3, -0.4, 0.5])
    qdd = m.forward_dynamics([0, 0.2, -0.8], fd=[50, 40, 25])
    run = m.simulate(scenario="paper")      # the paper's 1 s study
    print(run.q[-1])                        # q at t = 1 s

The library is found from, in order: Model's lib argument, $PRRU_LIB,
libprru.so beside this package, build/runtime/libprru.so of the source
tree, the system's library path. The model (sizes, bodies, numbers) is the
one the library was built from: Model.name, .nact, .body_names,
.lambda_labels, ...; a library built for the 4-PRRU gives four actuators.

Failures raise PrruError subclasses with the library's message:
InputError (also ValueError), Unreachable (OutOfStroke: a slider outside
its stroke), Singular, NoConvergence,
Interrupted, PrruIOError, ParseError; wrong argument lengths and NaN raise
ValueError naming the argument, and a vector given as anything but an
ordered sequence of numbers (a dict, set, string, iterator, ...) TypeError
naming it. No call returns NaN or an infinity: a result that is not finite
raises (InputError naming the arguments too large for it, or Singular at
the edge of the workspace, where J_d is not finite). Ctrl-C stops
simulate at once, also inside a long sample interval (KeyboardInterrupt).
"""

from .errors import (InputError, Interrupted, LayoutError, LibraryNotFound, NoConvergence,
                     OutOfStroke, ParseError, PrruError, PrruIOError, PrruMemoryError,
                     Singular, Unreachable)
from ._lib import Library, load_library
from .model import Dme, Joint, Linearization, Model
from .simulation import Sample, Scenario, Trajectory
from .maps import MapResult
from .measurements import Measurement
from .motion import Limits, Motion, TimeOptimal, TrackRun
from .identification import Excitation, Identification, Parameter, write_model_text
from .design import Design

__version__ = "0.6.0"

__all__ = ["Model", "Scenario", "Trajectory", "Sample", "Dme", "Joint", "Linearization", "MapResult",
           "Measurement", "Limits", "Motion", "TimeOptimal", "TrackRun", "Excitation", "Identification", "Parameter",
           "Design", "write_model_text",
           "Library", "load_library", "PrruError", "InputError", "Unreachable", "OutOfStroke", "Singular",
           "NoConvergence", "Interrupted", "PrruIOError", "PrruMemoryError", "ParseError",
           "LibraryNotFound", "LayoutError"]
