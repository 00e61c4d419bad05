"""Arguments in, results out.

Inputs are ordered sequences of real numbers: a list, a tuple, any other
collections.abc.Sequence (array.array, range, memoryview, ...) or a 1-D
array read through its tolist() (NumPy; NumPy is never imported here for
inputs). Everything else is refused with TypeError naming the argument:
strings and bytes, mappings (a dict's iteration gives its keys, not values
in coordinate order), sets (no order at all), iterators and generators;
so are non-numeric elements. Wrong lengths, NaN and infinities raise
ValueError naming the argument.

Outputs are plain Python lists (matrices as lists of rows) unless the model
was made with numpy=True, in which case they are NumPy arrays (matrices
2-D); NumPy is imported only then.
"""

import collections.abc
import ctypes
import numbers
from math import isfinite


def _check_item(name, i, v):
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError("%s[%d] must be a real number, got %s" % (name, i, type(v).__name__))


def ordered(name, value, what, ndim=1):
    """The elements of value, an ordered sequence (see the module's
    docstring; an array must have ndim dimensions), as a list or tuple;
    TypeError naming name, saying that it must be what, for anything else."""
    kind = type(value)
    if kind is list or kind is tuple:  # the common case, checked without ABCs
        return value
    if (isinstance(value, (str, bytes, bytearray, collections.abc.Mapping,
                           collections.abc.Set, collections.abc.Iterator))
            or not (isinstance(value, collections.abc.Sequence)
                    or (hasattr(value, "tolist") and hasattr(value, "ndim")))):
        raise TypeError("%s must be %s, got %s" % (name, what, kind.__name__))
    if getattr(value, "ndim", ndim) != ndim:
        raise ValueError("%s must be %s (%d-D), got an array of shape %s"
                         % (name, what, ndim, tuple(getattr(value, "shape", ()))))
    return value.tolist() if hasattr(value, "tolist") else list(value)


def vector(name, value, n):
    """value as a ctypes array of n finite doubles; ValueError/TypeError naming name."""
    items = ordered(name, value, "a sequence of %d numbers" % n)
    if len(items) != n:
        raise ValueError("%s must have %d elements, got %d" % (name, n, len(items)))
    for i, v in enumerate(items):
        kind = type(v)
        if kind is not float and kind is not int:
            _check_item(name, i, v)
    try:
        out = (ctypes.c_double * n)(*items)
    except OverflowError:
        raise ValueError("%s must be finite, got an integer beyond the double range" % name) \
            from None
    for i in range(n):
        if not isfinite(out[i]):
            raise ValueError("%s[%d] must be finite, got %r" % (name, i, out[i]))
    return out


def optional_vector(name, value, n):
    """vector(), or n zeros when value is None."""
    return (ctypes.c_double * n)() if value is None else vector(name, value, n)


def scalar(name, value, positive=False, allow_zero=True):
    """value as a finite float; ValueError naming name."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a real number, got %s" % (name, type(value).__name__))
    f = float(value)
    if not isfinite(f):
        raise ValueError("%s must be finite, got %r" % (name, f))
    if positive and not (f > 0 or (allow_zero and f == 0)):
        raise ValueError("%s must be %s, got %r" % (name, "non-negative" if allow_zero
                                                    else "positive", f))
    return f


def integer(name, value, minimum):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError("%s must be an integer, got %s" % (name, type(value).__name__))
    if value < minimum:
        raise ValueError("%s must be at least %d, got %d" % (name, minimum, value))
    return int(value)


class Output:
    """Builds results as lists or NumPy arrays."""

    def __init__(self, use_numpy):
        self.np = None
        if use_numpy:
            try:
                import numpy
            except ImportError:
                raise ImportError("numpy=True needs NumPy, which is not installed "
                                  "(apt-get install python3-numpy); the default "
                                  "numpy=False returns plain lists") from None
            self.np = numpy

    def vec(self, values, n=None):
        items = list(values) if n is None else list(values[:n])
        return self.np.array(items, dtype=float) if self.np else items

    def mat(self, values, rows, cols):
        flat = list(values[:rows * cols])
        if self.np:
            return self.np.array(flat, dtype=float).reshape(rows, cols)
        return [flat[r * cols:(r + 1) * cols] for r in range(rows)]

    def columns(self, flat, width, start, count, nrows):
        """Columns start..start+count of a row-major table of nrows rows of
        width doubles (flat: a memoryview of doubles): a list of rows (a
        list of floats per row, or a plain float per row when count is 1),
        or a NumPy array (nrows,) or (nrows, count)."""
        if self.np:
            a = self.np.frombuffer(flat, dtype=float).reshape(nrows, width)
            block = a[:, start:start + count].copy()
            return block[:, 0] if count == 1 else block
        if count == 1:
            return [flat[r * width + start] for r in range(nrows)]
        return [list(flat[r * width + start:r * width + start + count]) for r in range(nrows)]


def derived_name(lib, base, suffix):
    """The library's name of a model made from the model named base
    (prru_model_name_derive: identify's "_id", optimize's "_opt")."""
    out = ctypes.create_string_buffer(17)
    lib.model_name_derive(base.encode(), suffix.encode(), out)
    return out.value.decode()
