"""Model file loading and validation.

A model file is JSON; every number becomes an exact Fraction (parsed from its
decimal text, never through a binary float) so that the geometry folds
exactly in the symbolic engine. Every rejection names the file, the key path
and the reason, because users edit these files by hand.
"""

import hashlib
import json
import math
import re
from decimal import Decimal, InvalidOperation
from fractions import Fraction

BODY_NAMES = ("P", "L1", "L2", "L3", "U1", "U2", "U3", "S1", "S2", "S3")
GEOMETRY_KEYS = ("b12", "b3", "l1", "l2", "a")
TOP_KEYS = ("name", "description", "gravity", "geometry", "bodies")
BODY_KEYS = ("mass", "inertia")
MAX_BYTES = 1 << 20


class ModelError(Exception):
    """A model file that cannot be used; str() is the full user message."""

    def __init__(self, path, key, reason):
        self.path, self.key, self.reason = path, key, reason
        where = "%s: %s" % (path, key) if key else str(path)
        super().__init__("%s: %s" % (where, reason))


class Model:
    """A validated model: exact Fractions, plus the file's SHA-256."""

    def __init__(self, name, description, gravity, geometry, masses,
                 inertias, sha256, path):
        self.name = name
        self.description = description
        self.gravity = gravity
        self.geometry = geometry      # dict name -> Fraction
        self.masses = masses          # tuple of Fraction, body order
        self.inertias = inertias      # tuple of (Ixx, Iyy, Izz), body order
        self.sha256 = sha256
        self.path = path

    @property
    def total_mass(self):
        return sum(self.masses, Fraction(0))


def _reject_constant(name):
    raise ValueError("non-finite number %s" % name)


def _pairs_no_duplicates(pairs):
    seen = {}
    for key, value in pairs:
        if key in seen:
            raise ValueError("duplicate key %r" % key)
        seen[key] = value
    return seen


class _OutOfRange:
    """A JSON number far outside any model's range, kept as its text: its
    exact value could be a gigantic integer (1e99999999)."""

    def __init__(self, text):
        self.text = text if len(text) <= 40 else text[:20] + "..." + text[-10:]


def _parse_number(text):
    """json.loads hook for every number: exact Fraction via Decimal, which
    reads the exponent without expanding the value."""
    try:
        d = Decimal(text)
    except InvalidOperation:
        raise ValueError("bad number %r" % text[:40]) from None
    if d.is_finite() and (d == 0 or -30 <= d.adjusted() <= 30):
        return Fraction(d)
    return _OutOfRange(text)


def _json_text(value):
    def default(v):
        if isinstance(v, Fraction):
            return float(v)
        if isinstance(v, _OutOfRange):
            return v.text
        raise TypeError(type(v).__name__)
    text = json.dumps(value, default=default)
    return text if len(text) <= 60 else text[:57] + "..."


def _number(path, key, value):
    if isinstance(value, _OutOfRange):
        raise ModelError(path, key, "magnitude %s is outside [1e-9, 1e6]"
                         % value.text)
    if isinstance(value, bool) or not isinstance(value, (int, Fraction)):
        raise ModelError(path, key, "must be a number (got %s)"
                         % _json_text(value))
    value = Fraction(value)
    if abs(value) > 10 ** 6 or (value != 0 and abs(value) < Fraction(1, 10 ** 9)):
        raise ModelError(path, key, "magnitude %s is outside [1e-9, 1e6]"
                         % _fmt(value))
    return value


def _positive(path, key, value):
    value = _number(path, key, value)
    if value <= 0:
        raise ModelError(path, key, "must be positive (got %s)" % _fmt(value))
    return value


def _fmt(value):
    return repr(float(value))


def _object(path, key, value, allowed, required):
    if not isinstance(value, dict):
        raise ModelError(path, key or "(top level)", "must be a JSON object")
    prefix = key + "." if key else ""
    for k in value:
        if k not in allowed:
            raise ModelError(path, prefix + k, "unknown key (allowed: %s)"
                             % ", ".join(allowed))
    for k in required:
        if k not in value:
            raise ModelError(path, prefix + k, "missing")
    return value


def _inertia(path, key, value):
    if not isinstance(value, list) or len(value) != 3:
        raise ModelError(path, key, "must be a list of 3 principal moments "
                         "[Ixx, Iyy, Izz] in the body frame")
    moments = tuple(_positive(path, "%s[%d]" % (key, i), v)
                    for i, v in enumerate(value))
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        if moments[i] > moments[j] + moments[k]:
            raise ModelError(path, key, "violates the triangle inequality "
                             "(I%d = %s > %s + %s): no rigid body has it"
                             % (i + 1, _fmt(moments[i]), _fmt(moments[j]),
                                _fmt(moments[k])))
    return moments


def _check_assembly(path, geometry):
    # At q = 0 the limbs must close with the upper links strictly short of
    # full stretch; otherwise acos() is undefined or J_d singular at home.
    g = geometry
    for limb, num in (("limbs 1, 2", g["b12"] - g["a"] - g["l2"]),
                      ("limb 3", g["b3"] - g["l2"])):
        x = num / g["l1"]
        if not -1 < x < 1:
            raise ModelError(path, "geometry", "%s cannot be assembled at "
                             "q = 0: the horizontal gap %s m must be shorter "
                             "than the upper link l1 = %s m"
                             % (limb, _fmt(num), _fmt(g["l1"])))


def parse(text, path="<model>"):
    """Validate model JSON text; returns a Model or raises ModelError."""
    if len(text) > MAX_BYTES:
        raise ModelError(path, None, "file is %d bytes; a model file is at "
                         "most %d" % (len(text), MAX_BYTES))
    try:
        data = json.loads(text, parse_float=_parse_number,
                          parse_int=_parse_number,
                          parse_constant=_reject_constant,
                          object_pairs_hook=_pairs_no_duplicates)
    except (ValueError, RecursionError) as exc:
        raise ModelError(path, None, "not valid JSON: %s" % exc) from None
    _object(path, "", data, TOP_KEYS, TOP_KEYS)
    name = data["name"]
    if not isinstance(name, str) or not re.fullmatch(r"[a-z][a-z0-9_]{0,15}",
                                                      name):
        raise ModelError(path, "name", "must be a lower-case C identifier of "
                         "at most 16 characters (it becomes the C prefix)")
    description = data["description"]
    if not isinstance(description, str) or "*/" in description \
            or any(ord(c) < 32 for c in description) or len(description) > 400:
        raise ModelError(path, "description", "must be one line of text "
                         "(at most 400 characters, no '*/')")
    gravity = _number(path, "gravity", data["gravity"])
    if gravity < 0:
        raise ModelError(path, "gravity", "is the magnitude along -z and "
                         "must not be negative (got %s)" % _fmt(gravity))
    geo = _object(path, "geometry", data["geometry"], GEOMETRY_KEYS,
                  GEOMETRY_KEYS)
    geometry = {k: _positive(path, "geometry." + k, geo[k])
                for k in GEOMETRY_KEYS}
    _check_assembly(path, geometry)
    bodies = _object(path, "bodies", data["bodies"], BODY_NAMES, BODY_NAMES)
    masses, inertias = [], []
    for b in BODY_NAMES:
        key = "bodies." + b
        body = _object(path, key, bodies[b], BODY_KEYS, BODY_KEYS)
        masses.append(_positive(path, key + ".mass", body["mass"]))
        inertias.append(_inertia(path, key + ".inertia", body["inertia"]))
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return Model(name, description, gravity, geometry, tuple(masses),
                 tuple(inertias), sha, path)


def load(path):
    """Read and validate a model file."""
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise ModelError(path, None, "cannot read: %s" % exc.strerror) from None
    if len(raw) > MAX_BYTES:
        raise ModelError(path, None, "file is larger than %d bytes; not a "
                         "model file" % MAX_BYTES)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ModelError(path, None, "not UTF-8 text") from None
    return parse(text, path)


def c_double(value):
    """Shortest decimal that round-trips the nearest double of a Fraction."""
    f = float(value)
    if not math.isfinite(f):
        raise ValueError("non-finite constant")
    return repr(f)
