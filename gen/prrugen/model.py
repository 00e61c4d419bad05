"""Model file loading and validation.

A model file is JSON; every number becomes an exact Fraction (parsed from its
decimal text, never through a binary float) so that the geometry folds
exactly in the symbolic engine. Every rejection names the file, the key path
and the reason, because users edit these files by hand.

Two formats are read into one normalized Model:
  format 1 (no "format" key): the paper's idealised robot, one b12/b3/l1/l2/a,
    gravity as a magnitude along -z, principal moments only;
  format 2 ("format": 2): per-limb geometry, a gravity vector, centres of mass
    off the body-frame origins, full inertia tensors and drive parameters
    (armature, viscous damping, smoothed Coulomb friction).
A format-1 file and its format-2 transcription give the same Model.
"""

import hashlib
import json
import math
import re
import struct
from decimal import Decimal, InvalidOperation
from fractions import Fraction

NLIMB = 3
LIMB_COUNTS = (3, 4)    # the 3-PRRU, and the redundant 4-PRRU (spec 12)


def body_names(nlimb):
    """P, then every limb's lower link, upper link and slider."""
    return ("P",) + tuple("%s%d" % (kind, i + 1) for kind in "LUS"
                          for i in range(nlimb))


BODY_NAMES = body_names(NLIMB)
GEOMETRY_KEYS = ("b12", "b3", "l1", "l2", "a")
GEOMETRY2_KEYS = ("b", "l1", "l2", "a")
TOP_KEYS = ("name", "description", "gravity", "geometry", "bodies")
TOP2_KEYS = ("format",) + TOP_KEYS + ("actuators",)
BODY_KEYS = ("mass", "inertia")
BODY2_KEYS = ("mass", "inertia", "com")
ACTUATOR_KEYS = ("armature", "damping", "coulomb", "coulomb_velocity",
                 "lead", "gear", "rotor_inertia", "torque_constant", "stroke",
                 "force_max", "torque_max", "speed_max", "motor_speed_max")
# Spec 13's keys that convert between the rail and the motor through the
# lead, in the order their missing lead is reported.
NEEDS_LEAD = ("rotor_inertia", "torque_max", "motor_speed_max",
              "torque_constant")
MAX_BYTES = 1 << 20
# Bounds the C loader (runtime/src/model_file.c) shares, so that it decides
# every file as this module does with fixed-size exact arithmetic: at most
# MAX_DIGITS significant digits per number (a double holds 17), JSON nested
# at most MAX_DEPTH deep (a model is 4 deep), an exponent of at most
# MAX_EXPONENT_DIGITS digits (beyond, Decimal refuses some and not others).
MAX_DIGITS = 40
MAX_DEPTH = 32
MAX_EXPONENT_DIGITS = 9
# |cos| of the upper link's angle at q = 0 above which a model is warned
# about: within 5 % of full stretch the limb tolerates almost no tilt.
NEAR_STRETCH = Fraction(95, 100)


class ModelError(Exception):
    """A model file that cannot be used; str() is the full user message."""

    def __init__(self, path, key, reason):
        self.path, self.key, self.reason = path, key, reason
        where = "%s: %s" % (path, key) if key else str(path)
        super().__init__("%s: %s" % (where, reason))


class Limb:
    """Geometry of one limb (m): rail offset b, upper link l1 (A to B),
    lower link l2 (B to C), U-joint offset a of C on the platform (limbs 1,
    2 only; limb 3's U joint is O' itself, a = 0)."""

    def __init__(self, b, l1, l2, a):
        self.b, self.l1, self.l2, self.a = b, l1, l2, a


class Drives:
    """Spec 13's screw drives and limits, per actuator: the values as the
    file gives them (None: key absent) and, as floats, the limits in rail
    units (drive_ratio and the limits' conversions below). The armature a
    rotor_inertia reflects is in Model.armature already."""

    def __init__(self, n):
        none = (None,) * n
        self.lead = self.rotor_inertia = self.torque_constant = none
        self.gear = (Fraction(1),) * n
        self.stroke = none                   # (d_min, d_max) or None
        self.force_max = self.torque_max = none
        self.speed_max = self.motor_speed_max = none
        self.keys = ()                       # the section 13 keys given

    @property
    def given(self):
        """Whether the file gives any spec-13 key."""
        return bool(self.keys)

    def ratio(self, i):
        """Motor radians per metre of slider travel, 2 pi gear / lead, as a
        double (None without a lead)."""
        lead = self.lead[i]
        return None if lead is None else drive_ratio(lead, self.gear[i])

    def force_limit(self, i):
        """|f_i| bound in N (rail force), inf when none."""
        if self.torque_max[i] is not None:
            return float(self.torque_max[i]) * self.ratio(i)
        return math.inf if self.force_max[i] is None else float(self.force_max[i])

    def speed_limit(self, i):
        """|d_i'| bound in m/s, inf when none."""
        if self.motor_speed_max[i] is not None:
            return motor_speed_to_rail(self.motor_speed_max[i], self.lead[i],
                                       self.gear[i])
        return math.inf if self.speed_max[i] is None else float(self.speed_max[i])

    def stroke_limits(self, i):
        """(d_min, d_max) in m, (-inf, inf) when none."""
        if self.stroke[i] is None:
            return -math.inf, math.inf
        return float(self.stroke[i][0]), float(self.stroke[i][1])


# The conversions are defined as these double operations, in this order,
# so that the C loader (runtime/src/model_file.c) computes the same bits.
def drive_ratio(lead, gear):
    """2 pi gear / lead (rad/m): ((2 pi) gear) / lead in doubles."""
    return 2.0 * math.pi * float(gear) / float(lead)


def reflected_armature(rotor_inertia, lead, gear):
    """k = J_r (2 pi gear / lead)^2 (kg): (J_r w) w in doubles."""
    w = drive_ratio(lead, gear)
    return float(rotor_inertia) * w * w


def motor_speed_to_rail(rpm, lead, gear):
    """rev/min at the motor to m/s on the rail: ((n / 60) lead) / gear."""
    return float(rpm) / 60.0 * float(lead) / float(gear)


class Model:
    """A validated model: exact Fractions, plus the file's SHA-256.

    gravity: acceleration vector in {S}; inertias: (Ixx, Iyy, Izz, Ixy, Ixz,
    Iyz) about each centre of mass in body axes; coms: centre of mass in the
    body frame from the frame origin of the pose functions; drives: per
    actuator armature (kg), damping (N s/m), Coulomb force (N), and the
    Coulomb smoothing velocity (m/s, None when no friction)."""

    def __init__(self, name, description, fmt, gravity, limbs, masses, coms,
                 inertias, armature, damping, coulomb, coulomb_velocity,
                 sha256, path):
        self.name = name
        self.description = description
        self.format = fmt
        self.gravity = gravity
        self.limbs = limbs
        self.masses = masses
        self.coms = coms
        self.inertias = inertias
        self.armature = armature
        self.damping = damping
        self.coulomb = coulomb
        self.coulomb_velocity = coulomb_velocity
        self.sha256 = sha256
        self.path = path
        self.drives = Drives(len(limbs))
        self.numbers = ()       # (key, value) of the file's numbers (parse)

    @property
    def nlimb(self):
        return len(self.limbs)

    @property
    def body_names(self):
        return body_names(self.nlimb)

    @property
    def total_mass(self):
        return sum(self.masses, Fraction(0))

    @property
    def has_drives(self):
        return any(self.armature) or any(self.damping) or any(self.coulomb)

    @property
    def has_passive(self):
        return any(self.damping) or any(self.coulomb)

    def warnings(self):
        """Valid but probably unintended: limbs that assemble at q = 0 only
        near full stretch or fold, so that most of the workspace is out of
        reach (a map of such a model is nearly all 'unreachable')."""
        out = []
        for i, limb in enumerate(self.limbs):
            r = (limb.b - limb.a - limb.l2) / limb.l1
            if abs(r) > NEAR_STRETCH:
                out.append("limb %d is within %.1f%% of full %s at q = 0 "
                           "(horizontal gap %s m, upper link %s m): most "
                           "poses will be out of reach"
                           % (i + 1, 100 * (1 - abs(float(r))),
                              "stretch" if r > 0 else "fold",
                              _fmt(limb.b - limb.a - limb.l2), _fmt(limb.l1)))
        return out


def _reject_constant(name):
    raise ValueError("non-finite number %s" % name)


def _pairs_no_duplicates(pairs):
    seen = {}
    for key, value in pairs:
        if key in seen:
            raise ValueError("duplicate key %s" % (
                "'%s'" % key if re.fullmatch(r"[A-Za-z0-9_]{1,40}", key)
                else _key_text(key)))
        seen[key] = value
    return seen


class _OutOfRange:
    """A JSON number far outside any model's range, kept as its text: its
    exact value could be a gigantic integer (1e99999999)."""

    def __init__(self, text):
        self.text = text if len(text) <= 40 else text[:20] + "..." + text[-10:]


class _TooPrecise(_OutOfRange):
    """A JSON number with more than MAX_DIGITS significant digits."""


_NUMBER = re.compile(r"-?(\d+)(?:\.(\d+))?(?:[eE][-+]?0*(\d*))?")


def _parse_number(text):
    """json.loads hook for every number: exact Fraction via Decimal, which
    reads the exponent without expanding the value. Zero is zero whatever
    its exponent; a longer exponent than MAX_EXPONENT_DIGITS is out of
    range (Decimal itself refuses some of those and not others)."""
    m = _NUMBER.fullmatch(text)
    if m is None:
        raise ValueError("bad number %r" % text[:40])
    digits = (m.group(1) + (m.group(2) or "")).strip("0")
    if not digits:
        return Fraction(0)
    if len(m.group(3) or "") > MAX_EXPONENT_DIGITS:
        return _OutOfRange(text)
    d = Decimal(text)
    if not -30 <= d.adjusted() <= 30:
        return _OutOfRange(text)
    if len(digits) > MAX_DIGITS:
        return _TooPrecise(text)
    return Fraction(d)


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
    if isinstance(value, _TooPrecise):
        raise ModelError(path, key, "has more than %d significant digits "
                         "(got %s)" % (MAX_DIGITS, value.text))
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


def _nonnegative(path, key, value):
    value = _number(path, key, value)
    if value < 0:
        raise ModelError(path, key, "must not be negative (got %s)"
                         % _fmt(value))
    return value


def _fmt(value):
    return repr(float(value))


def _object(path, key, value, allowed, required):
    if not isinstance(value, dict):
        raise ModelError(path, key or "(top level)", "must be a JSON object")
    prefix = key + "." if key else ""
    for k in value:
        if k not in allowed:
            raise ModelError(path, prefix + _key_text(k),
                             "unknown key (allowed: %s)" % ", ".join(allowed))
    for k in required:
        if k not in value:
            raise ModelError(path, prefix + k, "missing")
    return value


def _key_text(key):
    """A user's key as it may appear in a one-line message: escaped, short."""
    text = key.encode("unicode_escape").decode("ascii").replace('"', '\\"')
    return '"%s"' % (text if len(text) <= 40 else text[:37] + "...") \
        if not re.fullmatch(r"[A-Za-z0-9_]{1,40}", key) else key


def _per_limb(path, key, value, count, check, what):
    """One number for every limb, or a list of exactly count numbers."""
    if isinstance(value, list):
        if len(value) != count:
            raise ModelError(path, key, "must be one number or a list of %d "
                             "(%s), got %d entries" % (count, what,
                                                       len(value)))
        return tuple(check(path, "%s[%d]" % (key, i), v)
                     for i, v in enumerate(value))
    return (check(path, key, value),) * count


def _vector3(path, key, value, what):
    if not isinstance(value, list) or len(value) != 3:
        raise ModelError(path, key, "must be a list of 3 numbers (%s)" % what)
    return tuple(_number(path, "%s[%d]" % (key, i), v)
                 for i, v in enumerate(value))


def _minors_ok(m, strict):
    """Sylvester's criterion on an exact symmetric 3x3: positive definite
    (strict) from the leading minors, positive semidefinite from all
    principal minors."""
    det2 = lambda i, j: m[i][i] * m[j][j] - m[i][j] * m[j][i]  # noqa: E731
    det3 = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    if strict:
        return m[0][0] > 0 and det2(0, 1) > 0 and det3 > 0
    return (all(m[i][i] >= 0 for i in range(3))
            and all(det2(i, j) >= 0 for i, j in ((0, 1), (0, 2), (1, 2)))
            and det3 >= 0)


def _tensor(t):
    xx, yy, zz, xy, xz, yz = t
    return ((xx, xy, xz), (xy, yy, yz), (xz, yz, zz))


def _inertia(path, key, value, fmt):
    sizes = (3,) if fmt == 1 else (3, 6)
    if not isinstance(value, list) or len(value) not in sizes:
        raise ModelError(path, key, "must be a list of 3 principal moments "
                         "[Ixx, Iyy, Izz] in the body frame" if fmt == 1 else
                         "must be a list of 3 principal moments [Ixx, Iyy, "
                         "Izz] or 6 tensor entries [Ixx, Iyy, Izz, Ixy, Ixz, "
                         "Iyz] about the centre of mass, in body axes")
    if len(value) == 3:
        moments = tuple(_positive(path, "%s[%d]" % (key, i), v)
                        for i, v in enumerate(value))
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            if moments[i] > moments[j] + moments[k]:
                raise ModelError(path, key, "violates the triangle "
                                 "inequality (I%d = %s > %s + %s): no rigid "
                                 "body has it"
                                 % (i + 1, _fmt(moments[i]), _fmt(moments[j]),
                                    _fmt(moments[k])))
        return moments + (Fraction(0),) * 3
    entries = tuple(_number(path, "%s[%d]" % (key, i), v)
                    for i, v in enumerate(value))
    tensor = _tensor(entries)
    if not _minors_ok(tensor, strict=True):
        raise ModelError(path, key, "is not positive definite: no rigid body "
                         "has this inertia tensor")
    # I = tr(I)/2 E - S with S = integral of r r^T dm, which must be positive
    # semidefinite: the tensor form of the triangle inequality.
    half = sum(tensor[i][i] for i in range(3)) / 2
    second = tuple(tuple((half if i == j else 0) - tensor[i][j]
                         for j in range(3)) for i in range(3))
    if not _minors_ok(second, strict=False):
        raise ModelError(path, key, "violates the triangle inequality of "
                         "its principal moments: no rigid body has it")
    return entries


def _check_assembly(path, limbs, fmt):
    # At q = 0 the limbs must close with the upper links strictly short of
    # full stretch; otherwise acos() is undefined or J_d singular at home.
    if fmt == 1:
        groups = (("limbs 1, 2", limbs[0]), ("limb 3", limbs[2]))
    else:
        groups = tuple(("limb %d" % (i + 1), l) for i, l in enumerate(limbs))
    for label, limb in groups:
        gap = limb.b - limb.a - limb.l2
        if not -1 < gap / limb.l1 < 1:
            raise ModelError(path, "geometry", "%s cannot be assembled at "
                             "q = 0: the horizontal gap %s m must be shorter "
                             "than the upper link l1 = %s m"
                             % (label, _fmt(gap), _fmt(limb.l1)))


def _geometry1(path, geo):
    geo = _object(path, "geometry", geo, GEOMETRY_KEYS, GEOMETRY_KEYS)
    g = {k: _positive(path, "geometry." + k, geo[k]) for k in GEOMETRY_KEYS}
    return (Limb(g["b12"], g["l1"], g["l2"], g["a"]),
            Limb(g["b12"], g["l1"], g["l2"], g["a"]),
            Limb(g["b3"], g["l1"], g["l2"], Fraction(0)))


def _geometry2(path, geo):
    """Per-limb geometry; the number of rails in b sets the number of limbs:
    3, or 4 for the redundant variant whose limb 4 mirrors limb 3 (rail at
    x = -b4)."""
    geo = _object(path, "geometry", geo, GEOMETRY2_KEYS, GEOMETRY2_KEYS)
    if not isinstance(geo["b"], list) or len(geo["b"]) not in LIMB_COUNTS:
        raise ModelError(path, "geometry.b", "must be a list of 3 rail "
                         "offsets [b1, b2, b3], or 4 for the redundant "
                         "4-limb variant [b1, b2, b3, b4]")
    n = len(geo["b"])
    names = ", ".join("b%d" % (i + 1) for i in range(n))
    b = _per_limb(path, "geometry.b", geo["b"], n, _positive,
                  "rail offsets " + names)
    l1 = _per_limb(path, "geometry.l1", geo["l1"], n, _positive,
                   "one upper link per limb")
    l2 = _per_limb(path, "geometry.l2", geo["l2"], n, _positive,
                   "one lower link per limb")
    a = _per_limb(path, "geometry.a", geo["a"], 2, _positive,
                  "U-joint offsets a1, a2 of limbs 1 and 2")
    return tuple(Limb(b[i], l1[i], l2[i], a[i] if i < 2 else Fraction(0))
                 for i in range(n))


def _gravity(path, value, fmt):
    if fmt == 2 and isinstance(value, list):
        return _vector3(path, "gravity", value, "acceleration in {S}, m/s^2")
    g = _number(path, "gravity", value)
    if g < 0:
        raise ModelError(path, "gravity", "is the magnitude along -z and "
                         "must not be negative (got %s)" % _fmt(g))
    return (Fraction(0), Fraction(0), -g)


def _actuators(path, value, nlimb):
    """Section 11's drive terms and section 13's drives and limits: the
    armature, damping and Coulomb lists, v_s, and the Drives."""
    zero = (Fraction(0),) * nlimb
    drives = Drives(nlimb)
    if value is None:
        return zero, zero, zero, None, drives
    value = _object(path, "actuators", value, ACTUATOR_KEYS, ())
    lists = [_per_limb(path, "actuators." + k, value[k], nlimb, _nonnegative,
                       "one per actuator") if k in value else zero
             for k in ACTUATOR_KEYS[:3]]
    vs = None
    if "coulomb_velocity" in value:
        vs = _positive(path, "actuators.coulomb_velocity",
                       value["coulomb_velocity"])
    if any(lists[2]) and vs is None:
        raise ModelError(path, "actuators.coulomb_velocity", "missing: the "
                         "Coulomb force -f tanh(dd / v_s) needs the smoothing "
                         "velocity v_s (m/s)")
    _drives(path, value, nlimb, drives)
    if drives.rotor_inertia[0] is not None:
        # The double's shortest decimal, as the user would write the
        # armature (the same double: the loader agrees bit for bit), so
        # that a rotor inertia and its armature written out fold alike.
        lists[0] = tuple(Fraction(repr(reflected_armature(
            drives.rotor_inertia[i], drives.lead[i], drives.gear[i])))
            for i in range(nlimb))
    return lists[0], lists[1], lists[2], vs if any(lists[2]) else None, drives


def _stroke(path, value, n):
    """[d_min, d_max] for every actuator, or a list of n such pairs."""
    key = "actuators.stroke"
    if isinstance(value, list) and any(isinstance(v, list) for v in value):
        if len(value) != n:
            raise ModelError(path, key, "must be one pair [d_min, d_max] (m) "
                             "or a list of %d pairs (one per actuator), got "
                             "%d entries" % (n, len(value)))
        items = [("%s[%d]" % (key, i), v) for i, v in enumerate(value)]
    elif isinstance(value, list) and len(value) == 2:
        items = [(key, value)]
    else:
        raise ModelError(path, key, "must be one pair [d_min, d_max] (m) or a "
                         "list of %d pairs (one per actuator)" % n)
    pairs = []
    for k, pair in items:
        if not isinstance(pair, list) or len(pair) != 2:
            raise ModelError(path, k, "must be a pair [d_min, d_max] (m)")
        lo = _number(path, k + "[0]", pair[0])
        hi = _number(path, k + "[1]", pair[1])
        if lo >= hi:
            raise ModelError(path, k, "d_min = %s m must be below d_max = %s m"
                             % (_fmt(lo), _fmt(hi)))
        pairs.append((lo, hi))
    return tuple(pairs) if len(pairs) == n else (pairs[0],) * n


def _drives(path, value, n, drives):
    """Section 13, checked in key order, then the keys' relations."""
    def per(key, check):
        if key not in value:
            return None
        return _per_limb(path, "actuators." + key, value[key], n, check,
                         "one per actuator")
    got = {k: per(k, _nonnegative if k == "rotor_inertia" else _positive)
           for k in ("lead", "gear", "rotor_inertia", "torque_constant")}
    if "stroke" in value:
        drives.stroke = _stroke(path, value["stroke"], n)
    for k in ("force_max", "torque_max", "speed_max", "motor_speed_max"):
        got[k] = per(k, _positive)
    for a, b, what in (("armature", "rotor_inertia", "drive inertia"),
                       ("force_max", "torque_max", "force limit"),
                       ("speed_max", "motor_speed_max", "speed limit")):
        if a in value and b in value:
            raise ModelError(path, "actuators." + b, "given with actuators.%s:"
                             " both set the %s of every actuator (ambiguous);"
                             " give one" % (a, what))
    if "lead" not in value:
        for k in NEEDS_LEAD:
            if k in value:
                raise ModelError(path, "actuators." + k, "needs actuators."
                                 "lead (m of slider travel per screw "
                                 "revolution) to convert between motor and "
                                 "rail")
    for k, v in got.items():
        if v is not None:
            setattr(drives, k, v)
    drives.keys = tuple(k for k in ACTUATOR_KEYS[4:] if k in value)


_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"?|[\[\]{}]', re.S)


def _depth(text):
    """Deepest bracket nesting outside strings, on any text (valid JSON or
    not): the C loader scans the same way before its parser runs."""
    depth = deepest = 0
    for m in _TOKEN.finditer(text):
        c = m.group()
        if c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth -= 1
    return deepest


def _strings(value):
    """Every key and string value of parsed JSON."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for k, v in value.items():
            yield k
            yield from _strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v)


def _keys(value):
    if isinstance(value, dict):
        for k, v in value.items():
            yield k
            yield from _keys(v)
    elif isinstance(value, list):
        for v in value:
            yield from _keys(v)


def _load_json(text, path):
    if len(text) > MAX_BYTES:
        raise ModelError(path, None, "file is %d bytes; a model file is at "
                         "most %d" % (len(text), MAX_BYTES))
    if _depth(text) > MAX_DEPTH:
        raise ModelError(path, None, "not valid JSON: nested deeper than %d "
                         "levels" % MAX_DEPTH)
    try:
        data = json.loads(text, parse_float=_parse_number,
                          parse_int=_parse_number,
                          parse_constant=_reject_constant,
                          object_pairs_hook=_pairs_no_duplicates)
    except (ValueError, RecursionError) as exc:
        raise ModelError(path, None, "not valid JSON: %s" % exc) from None
    # A JSON escape "\ud800" alone decodes to a lone surrogate: no UTF-8
    # (nor C, nor XML) can hold it, and the C loader's parser refuses it.
    if any(0xd800 <= ord(c) < 0xe000 for s in _strings(data) for c in s):
        raise ModelError(path, None, "not valid JSON: a string holds a lone "
                         "UTF-16 surrogate escape (\\udXXX): not text")
    if any("\0" in k for k in _keys(data)):
        raise ModelError(path, None, "not valid JSON: an object key holds "
                         "U+0000")
    return data


def parse(text, path="<model>"):
    """Validate model JSON text; returns a Model or raises ModelError."""
    data = _load_json(text, path)
    if isinstance(data, dict) and "format" in data:
        fmt = data["format"]
        if isinstance(fmt, bool) or fmt not in (1, 2):
            raise ModelError(path, "format", "must be 1 or 2 (got %s)"
                             % _json_text(fmt))
        fmt = int(fmt)
    else:
        fmt = 1
    if fmt == 1:
        _object(path, "", data, ("format",) + TOP_KEYS, TOP_KEYS)
    else:
        _object(path, "", data, TOP2_KEYS, TOP_KEYS)
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
    # A JSON escape "\ud800" alone decodes to a lone surrogate: no UTF-8
    # (nor C, nor XML) can hold it.
    if any(0xd800 <= ord(c) < 0xe000 for c in description):
        raise ModelError(path, "description", "holds a lone UTF-16 surrogate "
                         "escape (\\udXXX): not text")
    gravity = _gravity(path, data["gravity"], fmt)
    limbs = _geometry1(path, data["geometry"]) if fmt == 1 else \
        _geometry2(path, data["geometry"])
    _check_assembly(path, limbs, fmt)
    body_keys = BODY_KEYS if fmt == 1 else BODY2_KEYS
    names = body_names(len(limbs))
    bodies = _object(path, "bodies", data["bodies"], names, names)
    masses, coms, inertias = [], [], []
    for b in names:
        key = "bodies." + b
        body = _object(path, key, bodies[b], body_keys, BODY_KEYS)
        masses.append(_positive(path, key + ".mass", body["mass"]))
        inertias.append(_inertia(path, key + ".inertia", body["inertia"], fmt))
        coms.append(_vector3(path, key + ".com", body["com"], "centre of mass "
                             "in the body frame, m") if "com" in body
                    else (Fraction(0),) * 3)
    *terms, drives = _actuators(path, data.get("actuators"), len(limbs))
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    m = Model(name, description, fmt, gravity, limbs, tuple(masses),
              tuple(coms), tuple(inertias), *terms, sha256=sha, path=path)
    m.drives = drives
    m.numbers = tuple(_numbers(data))
    return m


def _numbers(value, key=""):
    """(key, value) of every number of parsed JSON, keys as messages name
    them (bodies.P.mass, geometry.b[2])."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _numbers(v, (key + "." if key else "") + _key_text(k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _numbers(v, "%s[%d]" % (key, i))
    elif isinstance(value, (int, Fraction)) and not isinstance(value, bool):
        yield key, Fraction(value)


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


CANONICAL_MAGIC = b"prru-model-canonical-1\n"


def canonical_bytes(model):
    """The parsed numbers in a fixed order, for a hash that ignores layout:
    the magic, the format and the number of limbs as one byte each, then
    IEEE-754 binary64 little-endian of float() of each exact value: gravity
    (3); per limb b, l1, l2, a; per body (body_names order) mass, com (3),
    inertia (Ixx, Iyy, Izz, Ixy, Ixz, Iyz); per actuator armature, damping,
    coulomb; coulomb_velocity (0 when none); then, only for a file with
    section 13's keys (so that other files keep their hash), per actuator
    lead (0 when none), gear, torque_constant (0 when none), d_min, d_max,
    the force and the speed limit in rail units (infinities when none; a
    rotor_inertia is in the armature). Name and description are left out. runtime/src/model_file.c
    writes the same bytes (docs/model-files.md)."""
    numbers = list(model.gravity)
    for limb in model.limbs:
        numbers += [limb.b, limb.l1, limb.l2, limb.a]
    for i in range(len(model.masses)):
        numbers += [model.masses[i]] + list(model.coms[i]) \
            + list(model.inertias[i])
    for i in range(model.nlimb):
        numbers += [model.armature[i], model.damping[i], model.coulomb[i]]
    numbers.append(model.coulomb_velocity or 0)
    dr = model.drives
    if dr.given:
        for i in range(model.nlimb):
            numbers += [dr.lead[i] or 0, dr.gear[i], dr.torque_constant[i] or 0,
                        *dr.stroke_limits(i), dr.force_limit(i),
                        dr.speed_limit(i)]
    return CANONICAL_MAGIC + bytes((model.format, model.nlimb)) + b"".join(
        struct.pack("<d", float(x)) for x in numbers)


def canonical_sha256(model):
    """SHA-256 (hex) of canonical_bytes: the same for a whitespace or key
    order edit of the file, different for any change of a parsed number."""
    return hashlib.sha256(canonical_bytes(model)).hexdigest()


def c_double(value):
    """Shortest decimal that round-trips the nearest double of a Fraction."""
    f = float(value)
    if not math.isfinite(f):
        raise ValueError("non-finite constant")
    return repr(f)
