"""Exceptions: one class per prru_status, all subclasses of PrruError.

The library reports failures as a prru_status code; each call here turns a
non-zero code into the matching exception, whose message is the library's
own description (prru_strerror) preceded by what was being computed.
"""

# prru_status codes of runtime/include/prru_dynamics.h.
OK = 0
EINPUT = 1
EUNREACHABLE = 2
ESINGULAR = 3
ENOCONV = 4
EINTERRUPTED = 5
EIO = 6
ENOMEM = 7
EPARSE = 8
ESTROKE = 9


class PrruError(Exception):
    """A prru library call failed; .status is its prru_status code.

    Raised by Model.simulate, it also carries .trajectory (every sample
    computed before the run stopped) and .t_stop (the time of the last one).
    """

    status = None
    trajectory = None
    t_stop = None

    def __init__(self, message, status=None):
        super().__init__(message)
        if status is not None:
            self.status = status


class InputError(PrruError, ValueError):
    """PRRU_EINPUT: an argument is NaN/inf or out of its range."""

    status = EINPUT


class Unreachable(PrruError):
    """PRRU_EUNREACHABLE: the pose has no inverse kinematics."""

    status = EUNREACHABLE


class OutOfStroke(Unreachable):
    """PRRU_ESTROKE: a slider lies outside its stroke (the model's
    actuators.stroke): the stroke ends bound the workspace as the reach does,
    so this is an Unreachable."""

    status = ESTROKE


class Singular(PrruError):
    """PRRU_ESINGULAR: J_d is singular (rank-deficient) to the model's tolerance,
    or the state is too near the workspace boundary to trust the dynamics (the
    mass matrix's conditioning: the model's mass_rcond_min)."""

    status = ESINGULAR


class NoConvergence(PrruError):
    """PRRU_ENOCONV: Newton's method or the integrator failed."""

    status = ENOCONV


class Interrupted(PrruError):
    """PRRU_EINTERRUPTED: the run was stopped on request."""

    status = EINTERRUPTED


class PrruIOError(PrruError, OSError):
    """PRRU_EIO: a file could not be read or written."""

    status = EIO


class PrruMemoryError(PrruError, MemoryError):
    """PRRU_ENOMEM: the library could not allocate."""

    status = ENOMEM


class ParseError(PrruError, ValueError):
    """PRRU_EPARSE: a malformed number, list, CSV table or scenario file."""

    status = EPARSE


class LibraryNotFound(PrruError, OSError):
    """libprru.so was not found, or did not load; the message lists every path tried."""


class LayoutError(PrruError):
    """The loaded libprru.so does not match this package's mirror of prru.h."""


_BY_STATUS = {
    EINPUT: InputError,
    EUNREACHABLE: Unreachable,
    ESINGULAR: Singular,
    ENOCONV: NoConvergence,
    EINTERRUPTED: Interrupted,
    EIO: PrruIOError,
    ENOMEM: PrruMemoryError,
    EPARSE: ParseError,
    ESTROKE: OutOfStroke,
}


def error_class(status):
    """The exception class of a non-zero prru_status."""
    return _BY_STATUS.get(status, PrruError)


def make_error(status, message):
    """An exception instance for status carrying message."""
    return error_class(status)(message, status)
