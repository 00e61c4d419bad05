"""Newton-Euler in generalized coordinates, derived from the poses.

For each body: J_T = dp/dq and mu = d/dt(J_T) qd by differentiation; the
angular velocity from the rotation chain (chain rule on its angles),
J_R = d omega / d qd and delta = d/dt(J_R) qd. Then

  M = H^T Phi H = sum_b m_b J_T^T J_T + J_Rb^T D_b J_Rb
  h = H^T K     = sum_b m_b J_T^T mu + J_Rb^T (D_b delta_b + w_b x D_b w_b)

with the rotational part in each body's own frame (subscript b), where the
inertia D_b is a constant tensor: I_b = R D R^T never has to be formed,
and R^T (I delta + w x I w) = D delta_b + w_b x D w_b because
d/dt (R^T w) = R^T w'. The world-frame quantities (H, delta, mu, K, I_b)
are derived too, for the kernels that return them.

M, h and G are formed in the coordinates theta = (q, atoms) and then
projected, M = A^T Mt A, h = A^T ht, G = A^T Gt with A = d theta / d q:
an atom (limb 3's angle gamma, a function of q1 and q2) then enters only
through the few entries of A instead of into every product of Jacobians,
so the bodies of limb 3 sum once, not once per entry of M. The theta
Jacobians hold the atoms fixed (sym.diff explicit); mu is the same either
way, d/dt (J_theta A) qd with the atom's rate bias in d/dt (A) qd.

Drives (model format 2) enter through the actuator coordinates d(q): an
armature k_i adds the kinetic energy k_i dd_i^2 / 2, so M += J_d^T K J_d
and h += J_d^T K (Jd' qd); damping and Coulomb friction are generalized
forces J_d^T (-c dd - f tanh(dd / v_s)) kept out of h (as MuJoCo keeps
qfrc_passive out of qfrc_bias) and added where accelerations are computed.
"""

from . import sym
from .linalg import vec, vadd, vscale, dot, cross, matvec, matmul, \
    transpose, identity, rot, unit, diag, jacobian


class BodyTerms:
    """Derived velocity-level quantities of one body."""

    def __init__(self, body, q, qd, dt, theta, theta_d):
        self.body = body
        rates = [dt(angle) for _, angle in body.chain]
        n = len(body.chain)
        omega_w, omega_b = vec(0, 0, 0), vec(0, 0, 0)
        prefix = identity()
        for k, (axis, angle) in enumerate(body.chain):
            omega_w = vadd(omega_w, vscale(rates[k], matvec(prefix,
                                                            unit(axis))))
            prefix = matmul(prefix, rot(axis, angle))
        suffix = identity()
        for k in range(n - 1, -1, -1):
            axis, angle = body.chain[k]
            omega_b = vadd(omega_b, vscale(rates[k], matvec(transpose(suffix),
                                                            unit(axis))))
            suffix = matmul(rot(axis, angle), suffix)
        self.rotation = prefix
        self.omega_w, self.omega_b = omega_w, omega_b
        self.jr_w = jacobian(omega_w, qd)
        self.jr_b = jacobian(omega_b, qd)
        self.jt = jacobian(body.centre, q)
        # In theta = (q, atoms), the atoms held fixed.
        self.jr_theta = explicit_jacobian(omega_b, theta_d)
        self.jt_theta = explicit_jacobian(body.centre, theta)
        self.delta_w = [dt(x) for x in omega_w]
        self.delta_b = [dt(x) for x in omega_b]
        velocity = [dt(x) for x in body.centre]
        self.mu = [dt(x) for x in velocity]
        self.velocity = velocity
        self.inertia = body.inertia

    def gyro_b(self):
        """D delta_b + w_b x D w_b: the body-frame rotational bias wrench."""
        d_w = matvec(self.inertia, self.omega_b)
        return vadd(matvec(self.inertia, self.delta_b),
                    cross(self.omega_b, d_w))


def explicit_jacobian(f, xs):
    """[d f_i / d x_j] with every atom not in xs held fixed."""
    return [[sym.diff(fi, x, explicit=True) for x in xs] for fi in f]


def _quad(a, d, b):
    """a^T d b for 3 x n a, b and a constant symmetric d (its zero entries
    contribute no terms, so a diagonal d gives the diagonal formula)."""
    return [[sym.add(*[sym.mul(d[k][l], a[k][i], b[l][j])
                       for k in range(3) for l in range(3)
                       if not sym.is_const(d[k][l], 0)])
             for j in range(len(b[0]))] for i in range(len(a[0]))]


def _atb(a, v):
    """a^T v (a has len(v) rows)."""
    return [dot([a[k][i] for k in range(len(v))], v)
            for i in range(len(a[0]))]


def _quad_n(a, d, b):
    """a^T d b for n x m a, b and a constant n x n diagonal d."""
    n = len(d)
    return [[sym.add(*[sym.mul(d[k][k], a[k][i], b[k][j]) for k in range(n)
                       if d[k][k]])
             for j in range(len(b[0]))] for i in range(len(a[0]))]


class Derivation:
    def __init__(self, mech, model):
        self.mech = mech
        self.gravity = model.gravity
        self.armature = model.armature
        self.damping = model.damping
        self.coulomb = model.coulomb
        self.coulomb_velocity = model.coulomb_velocity
        q, qd = mech.q, mech.qd
        dt = sym.TimeDerivative(q, qd)
        self.theta = list(q) + list(mech.atoms)
        self.theta_d = list(qd) + [dt(a) for a in mech.atoms]
        # A = d theta / d q: the identity over the atoms' partials.
        self.a_rows = [[sym.diff(a, x) for x in q] for a in mech.atoms]
        self.terms = [BodyTerms(b, q, qd, dt, self.theta, self.theta_d)
                      for b in mech.bodies]
        self._jd = jacobian(mech.actuators, q)
        self._jd_theta = explicit_jacobian(mech.actuators, self.theta)
        self.actuator_rates = [dt(x) for x in mech.actuators]
        self.actuator_bias = [dt(x) for x in self.actuator_rates]

    def _project(self, v):
        """A^T v for v over theta: a generalized force in q."""
        return [sym.add(v[i], *[sym.mul(row[i], v[3 + a]) for a, row in
                                enumerate(self.a_rows)]) for i in range(3)]

    def _sum(self, parts):
        return [sym.add(*[p[i] for p in parts]) for i in
                range(len(self.theta))]

    def _mass_theta(self):
        n = len(self.theta)
        parts = []
        for t in self.terms:
            m = t.body.mass
            parts.append(_quad(t.jt_theta, diag([m, m, m]), t.jt_theta))
            parts.append(_quad(t.jr_theta, t.inertia, t.jr_theta))
        if any(self.armature):
            k = [[self.armature[i] if i == j else 0 for j in range(len(
                self.armature))] for i in range(len(self.armature))]
            parts.append(_quad_n(self._jd_theta, k, self._jd_theta))
        return [[sym.add(*[p[i][j] for p in parts]) for j in range(n)]
                for i in range(n)]

    def _bias_theta(self):
        parts = []
        for t in self.terms:
            parts.append(_atb(t.jt_theta, vscale(t.body.mass, t.mu)))
            parts.append(_atb(t.jr_theta, t.gyro_b()))
        if any(self.armature):
            parts.append(_atb(self._jd_theta, [sym.mul(k, a) for k, a in zip(
                self.armature, self.actuator_bias)]))
        return self._sum(parts)

    def _gravity_theta(self):
        v = self.potential()
        return [-sym.diff(v, x, explicit=True) for x in self.theta]

    def _passive_theta(self):
        forces = []
        for c, f, dd in zip(self.damping, self.coulomb, self.actuator_rates):
            terms = [sym.mul(-c, dd)]
            if f:
                terms.append(sym.mul(-f, sym.tanh(sym.mul(
                    1 / self.coulomb_velocity, dd))))
            forces.append(sym.add(*terms))
        return _atb(self._jd_theta, forces)

    def mass(self):
        mt = self._mass_theta()
        n = len(self.theta)
        # A^T Mt A: columns first, then rows.
        cols = [self._project([mt[i][j] for i in range(n)]) for j in range(n)]
        rows = [self._project([cols[j][i] for j in range(n)])
                for i in range(3)]
        m = [rows[i][j] for i in range(3) for j in range(3)]
        # Exact symmetry: take the upper triangle's expressions for both.
        for i in range(3):
            for j in range(i):
                m[3 * i + j] = m[3 * j + i]
        return m

    def bias(self):
        return self._project(self._bias_theta())

    def passive(self):
        """J_d^T (-c dd - f tanh(dd / v_s)): damping and Coulomb friction of
        the drives as generalized forces (zero without drives)."""
        return self._project(self._passive_theta())

    def potential(self):
        gx, gy, gz = self.gravity
        if gx == 0 and gy == 0:
            # Format-1 models: V = g sum m z, the expressions as they were.
            return sym.mul(-gz, sym.add(*[
                sym.mul(t.body.mass, t.body.centre[2]) for t in self.terms]))
        return sym.add(*[sym.mul(-g, sym.add(*[
            sym.mul(t.body.mass, t.body.centre[k]) for t in self.terms]))
            for k, g in enumerate(self.gravity) if g != 0])

    def gravity_force(self):
        return self._project(self._gravity_theta())

    def kinetic(self):
        total = []
        for t in self.terms:
            total.append(sym.mul(t.body.mass, dot(t.velocity, t.velocity)))
            total.append(dot(t.omega_b, matvec(t.inertia, t.omega_b)))
        if any(self.armature):
            total += [sym.mul(k, dd, dd) for k, dd in
                      zip(self.armature, self.actuator_rates) if k]
        return sym.mul(sym.Fraction(1, 2), sym.add(*total))

    def actuators(self):
        return list(self.mech.actuators)

    def actuator_jacobian(self):
        return [x for row in self._jd for x in row]

    def jacobians(self):
        rows = [r for t in self.terms for r in t.jr_w]
        rows += [r for t in self.terms for r in t.jt]
        return [x for r in rows for x in r]

    def bias_terms(self):
        return [x for t in self.terms for x in t.delta_w] + \
            [x for t in self.terms for x in t.mu]

    def platform_jacobian(self):
        t = self.terms[0]
        return [x for r in t.jr_w + self.tool_jacobian() for x in r]

    def poses(self):
        rs = [x for t in self.terms for r in t.rotation for x in r]
        ps = [x for t in self.terms for x in t.body.centre]
        return rs, ps

    def inertia_world(self):
        out = []
        for t in self.terms:
            r = t.rotation
            out += [x for row in _quad(transpose(r), t.inertia, transpose(r))
                    for x in row]
        return out

    def wrench_bias(self):
        rot_part = [x for t in self.terms
                    for x in matvec(t.rotation, t.gyro_b())]
        lin_part = [x for t in self.terms for x in vscale(t.body.mass, t.mu)]
        return rot_part + lin_part

    def tool_jacobian(self):
        """J_T of the platform's frame origin O', where the external force
        acts (the platform's centre of mass only when its com is 0)."""
        return jacobian(self.terms[0].body.origin, self.mech.q)

    def eom_rhs(self, fd, fp, mp):
        """b = G + J_d^T fd + J_T,O'^T fp + J_R,P^T mp + passive - h,
        summed over theta and projected once."""
        return self._project(self._rhs_theta(fd, fp, mp))

    def drive_force(self, qdd, fp, mp):
        """tau = M qdd - b (b without drive forces): the generalized force
        the drives supply, A^T (Mt (A qdd) - bt), so M is never formed."""
        mt = self._mass_theta()
        acc = list(qdd) + [dot(row, qdd) for row in self.a_rows]
        bt = self._rhs_theta([sym.ZERO] * len(self.mech.actuators), fp, mp)
        return self._project([sym.add(dot(row, acc), -x)
                              for row, x in zip(mt, bt)])

    def _rhs_theta(self, fd, fp, mp):
        t = self.terms[0]
        jr = explicit_jacobian(t.omega_w, self.theta_d)
        jt = explicit_jacobian(t.body.origin, self.theta)
        parts = [self._gravity_theta(), _atb(self._jd_theta, fd),
                 _atb(jt, fp), _atb(jr, mp),
                 [-x for x in self._bias_theta()]]
        if any(self.damping) or any(self.coulomb):
            parts.append(self._passive_theta())
        return self._sum(parts)

    def reaction_basis(self):
        """Q (60 x 57): lambda -> wrenches about each body's centre."""
        nb = len(self.terms)
        cols = []
        for joint in self.mech.joints:
            for kind, e in joint.basis:
                col = [sym.ZERO] * (6 * nb)
                for body, sign in ((joint.distal, 1), (joint.proximal, -1)):
                    if body is None:
                        continue
                    if kind == "f":
                        arm = [c - p for c, p in
                               zip(joint.centre, self.terms[body].body.centre)]
                        moment = cross(arm, e)
                        force = e
                    else:
                        moment, force = e, vec(0, 0, 0)
                    for k in range(3):
                        col[3 * body + k] = col[3 * body + k] + sign * moment[k]
                        col[3 * nb + 3 * body + k] = \
                            col[3 * nb + 3 * body + k] + sign * force[k]
                cols.append(col)
        return [cols[j][i] for i in range(6 * nb) for j in range(len(cols))]
