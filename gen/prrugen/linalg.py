"""3-vectors and 3x3 matrices of expressions (lists, row-major)."""

from . import sym


def vec(*xs):
    return [sym.as_expr(x) for x in xs]


def vadd(*vs):
    return [sym.add(*c) for c in zip(*vs)]


def vsub(a, b):
    return [x - y for x, y in zip(a, b)]


def vscale(k, v):
    return [sym.mul(k, x) for x in v]


def dot(a, b):
    return sym.add(*[sym.mul(x, y) for x, y in zip(a, b)])


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0]]


def matvec(m, v):
    return [dot(row, v) for row in m]


def transpose(m):
    return [list(col) for col in zip(*m)]


def matmul(a, b):
    bt = transpose(b)
    return [[dot(row, col) for col in bt] for row in a]


def identity():
    return [[sym.const(int(i == j)) for j in range(3)] for i in range(3)]


def diag(d):
    return [[sym.as_expr(d[i]) if i == j else sym.ZERO for j in range(3)]
            for i in range(3)]


def unit(axis):
    return [sym.const(int(i == axis)) for i in range(3)]


def rot(axis, angle):
    """Elementary right-handed rotation about e1, e2 or e3 (axis 0, 1, 2)."""
    c, s = sym.cos(angle), sym.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    m = identity()
    m[i][i], m[i][j] = c, -s
    m[j][i], m[j][j] = s, c
    return m


def jacobian(f, xs):
    """[d f_i / d x_j]."""
    return [[sym.diff(fi, x) for x in xs] for fi in f]


def flatten(m):
    return [x for row in m for x in row]
