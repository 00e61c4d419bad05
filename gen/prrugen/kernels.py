"""Which C functions are generated, and from which derived quantities."""

from . import sym
from .cgen import Kernel
from .reactions import Reactions, null_direction

Q = ("q", ["q1", "q2", "q3"])
QD = ("qd", ["qd1", "qd2", "qd3"])


def _vec(name, n=3):
    return [sym.sym("%s%d" % (name, i + 1)) for i in range(n)]


def _arg(name, n):
    return (name, ["%s%d" % (name, i + 1) for i in range(n)])


def kernels(deriv):
    """The kernel list, in the order the header declares them."""
    guards = deriv.mech.guards
    d, jd = deriv.actuators(), deriv.actuator_jacobian()
    m, h, g = deriv.mass(), deriv.bias(), deriv.gravity_force()
    nact = len(d)
    fd, fp, mp = _vec("fd", nact), _vec("fp"), _vec("mp")
    rs, ps = deriv.poses()
    t, v = deriv.kinetic(), deriv.potential()
    names = [b.name for b in deriv.mech.bodies]
    nh, last = 6 * len(names), names[-1]
    spec = [
        ("ik", "Actuator displacements d_i (height of joint A_i on rail i).",
         [Q], [("d", d)]),
        ("jd", "Actuator Jacobian J_d = dd/dq (%dx3)." % nact, [Q],
         [("Jd", jd)]),
        ("ik_jd", "ik and jd fused (one shared evaluation).", [Q], [("d", d), ("Jd", jd)]),
        ("jacobians", "H (%dx3) = [J_R,P; ..; J_R,%s; J_T,P; ..; J_T,%s], "
         "world frame, body order %s." % (nh, last, last, " ".join(names)),
         [Q], [("H", deriv.jacobians())]),
        ("bias_terms", "[delta_P..delta_%s; mu_P..mu_%s] (%d): the parts of "
         "the angular and linear accelerations that are quadratic in qd."
         % (last, last, nh),
         [Q, QD], [("dm", deriv.bias_terms())]),
        ("mass", "Mass matrix M = H^T Phi H (+ J_d^T K_arm J_d) (3x3).",
         [Q], [("M", m)]),
        ("bias", "Bias forces h = H^T K (+ J_d^T K_arm Jd' qd) (3); drive "
         "damping and friction are not in h (see passive).",
         [Q, QD], [("h", h)]),
        ("gravity", "Generalized gravity G = sum_b J_T,b^T (m_b g), g the "
         "gravity vector.",
         [Q], [("G", g)]),
        ("dynamics", "M, h and G fused (one shared evaluation).",
         [Q, QD], [("M", m), ("h", h), ("G", g)]),
        ("eom", "Forward-dynamics terms: M and b = G + J_d^T fd + "
         "J_T,O'^T fp + J_R,P^T mp + passive - h, so that M qdd = b (fp "
         "acts at the platform frame's origin O').",
         [Q, QD, _arg("fd", nact), _arg("fp", 3), _arg("mp", 3)],
         [("M", m), ("b", deriv.eom_rhs(fd, fp, mp))]),
        ("platform_jacobian", "Platform Jacobians: rows 0-2 J_R,P, rows 3-5 "
         "J_T,O' of the tool point O' (6x3).", [Q], [("JP", deriv.platform_jacobian())]),
        ("poses", "Body rotations R_b (3x3 each) and centres p_b, body order.",
         [Q], [("R", rs), ("p", ps)]),
        ("inertia_world", "Inertia tensors I_b = R_b D_b R_b^T about each "
         "centre, in {S} (3x3 each), body order.",
         [Q], [("I", deriv.inertia_world())]),
        ("wrench_bias", "K (%d) = [I_b delta_b + w_b x I_b w_b; m_b mu_b]." % nh,
         [Q, QD], [("K", deriv.wrench_bias())]),
        ("energy", "E[0] = kinetic energy (with the drives' armature), "
         "E[1] = potential energy -sum_b m_b g . p_b.", [Q, QD],
         [("E", [t, v])]),
        ("actuator_rates", "Slider velocities dd = J_d qd and the "
         "qd-quadratic part of their accelerations, ddb = Jd' qd.",
         [Q, QD], [("dd", deriv.actuator_rates),
                   ("ddb", deriv.actuator_bias)]),
        ("passive", "Generalized drive forces J_d^T (-c dd - f tanh(dd / "
         "v_s)): viscous damping and smoothed Coulomb friction (zero without "
         "drives).", [Q, QD], [("Qp", deriv.passive())]),
        _reaction_basis(deriv),
    ]
    spec.append(_eom_solve(deriv, m, fd, fp, mp))
    spec.append(_inverse_terms(deriv, d, jd, fp, mp))
    spec += _reaction_kernels(deriv, fd, fp, mp)
    # eom_solve and inverse_terms also name the outputs whose finiteness
    # the runtime tests after each call (Kernel.witnesses); reaction_basis
    # the dense positions of its entries (Kernel.pattern).
    return [Kernel(k[0], k[1], k[2], k[3], guards,
                   witnesses=k[4] if len(k) > 4 else (),
                   pattern=k[5] if len(k) > 5 else None)
            for k in spec]


def nonzero_positions(exprs):
    """Indices of the entries of exprs that are not identically zero."""
    return [i for i, e in enumerate(exprs)
            if not (e.op == "const" and e.args[0] == 0)]


def _reaction_basis(deriv):
    """Q, lambda -> body wrenches, as its structurally nonzero entries: a
    joint's reaction reaches only the two bodies it joins, so all but a few
    per cent of the dense 6 NBODY x NLAMBDA matrix is zero."""
    q = deriv.reaction_basis()
    rows = 6 * len(deriv.terms)
    cols = len(q) // rows
    at = nonzero_positions(q)
    return ("reaction_basis", "The entries of Q (%dx%d) that are not "
            "identically zero, Q mapping the joint reaction coordinates "
            "lambda to body wrenches about each centre (Phi H qdd + K = Fbar "
            "+ Q lambda): Q[k] is the dense row-major entry whose position "
            "is entry k of the index table declared next (%d of %d; every "
            "other entry is 0)." % (rows, cols, len(at), len(q)),
            [Q], [("Q", [q[i] for i in at])], (), (rows, cols, at))


def _atom(name, x):
    """x as a defined symbol (constants stay constants, to fold)."""
    return x if x.op == "const" else sym.define("_" + name, x)


def _mass_solver(deriv, m):
    """solve(b) -> (x, minors, how_sets) with M x = b, M's values as atoms:
    a constant diagonal entry of M eliminated first where there is one
    (_pivot_solve), else the adjugate (_adjugate_solve). Every call shares
    the factorization's nodes (hash-consing), so several right-hand sides
    cost only their own arithmetic."""
    # The solve works on M's values as atoms, so that it is the plain
    # arithmetic on them instead of being folded into their expressions
    # (the sums' scale factors would multiply through it).
    ma = [_atom("M%d" % k, x) for k, x in enumerate(m)]
    e = [[ma[3 * i + j] for j in range(3)] for i in range(3)]
    # A diagonal entry that is the same at every state: a number in a
    # model's kernels; in the runtime-parameter kernels an expression of
    # the parameters alone (M_22, the q3 direction moving every body as one
    # rigid translation, is the total mass plus the armatures for any
    # parameters), decided from the expressions, never from values.
    state = frozenset(x.id for x in list(deriv.mech.q) + list(deriv.mech.qd))
    pivots = [k for k in range(3)
              if e[k][k].op == "const" or not sym.free_symbols(m[4 * k]) & state]
    if pivots:
        return lambda rhs, tag="": _pivot_solve(e, rhs, pivots[-1], tag)
    return lambda rhs, tag="": _adjugate_solve(e, rhs, tag)


def _eom_solve(deriv, m, fd, fp, mp):
    """eom with M qdd = b solved in the same evaluation, by eliminating a
    constant diagonal entry of M first where there is one (_pivot_solve),
    else by the adjugate (_adjugate_solve)."""
    b = deriv.eom_rhs(fd, fp, mp)
    ba = [_atom("b%d" % k, x) for k, x in enumerate(b)]
    qdd, minors, how_sets = _mass_solver(deriv, m)(ba)
    return ("eom_solve", "eom's M and b, qdd = M^-1 b (%s), and three "
            "principal minors of M on nested index sets (%s): M is positive "
            "definite exactly when all three are positive (Sylvester), and "
            "qdd is meaningful only then." % how_sets,
            [Q, QD, _arg("fd", len(fd)), _arg("fp", 3), _arg("mp", 3)],
            [("M", m), ("b", b), ("qdd", qdd), ("minors", minors)], ("b", "qdd"))


def _pivot_solve(e, b, k, tag=""):
    """M x = b with M_kk a constant: x_k eliminated first (a Cholesky step
    with no square root and no division, 1/M_kk being a constant), then
    the 2x2 Schur complement S by its adjugate. About 18 multiplies and one
    division against the adjugate's 27; the minors are M_kk, M_kk S_ii and
    det M = M_kk det S."""
    i, j = [n for n in range(3) if n != k]
    r = sym.power(e[k][k], -1)
    ui = _atom("u%d" % i, sym.mul(e[i][k], r))
    uj = _atom("u%d" % j, sym.mul(e[j][k], r))
    sii = e[i][i] - ui * e[i][k]
    sij = e[i][j] - ui * e[j][k]
    sjj = e[j][j] - uj * e[j][k]
    ci = b[i] - ui * b[k]
    cj = b[j] - uj * b[k]
    det = sii * sjj - sij * sij
    inv = sym.power(det, -1)
    x = [None] * 3
    x[i] = _atom("x%s%d" % (tag, i), (sjj * ci - sij * cj) * inv)
    x[j] = _atom("x%s%d" % (tag, j), (sii * cj - sij * ci) * inv)
    # b_k / M_kk as an atom: otherwise the sum is normalised to
    # (b_k - M_kk (u_i x_i + u_j x_j)) / M_kk, a multiply more.
    x[k] = _atom("y%s%d" % (tag, k), b[k] * r) - ui * x[i] - uj * x[j]
    minors = [e[k][k], e[k][k] * sii, e[k][k] * det]
    what = "a constant" if e[k][k].op == "const" else \
        "constant in q and qd for any parameters (one division by it)"
    return x, minors, ("M_%d%d, %s, eliminated first, then the 2x2 "
                       "Schur complement S by its adjugate" % (k, k, what),
                       "{%d}, {%d, %d}, {0, 1, 2}" % (k, k, i))


def _adjugate_solve(e, b, tag=""):
    """M x = b by M's adjugate: the cofactors are products of M's entries,
    independent of each other, so only one division is serial."""
    cof = [[sym.add(sym.mul(e[(j + 1) % 3][(i + 1) % 3],
                            e[(j + 2) % 3][(i + 2) % 3]),
                    -sym.mul(e[(j + 1) % 3][(i + 2) % 3],
                             e[(j + 2) % 3][(i + 1) % 3]))
            for j in range(3)] for i in range(3)]
    # Symmetric M: the adjugate is symmetric; one expression for both.
    for i in range(3):
        for j in range(i):
            cof[i][j] = cof[j][i]
    det = sym.add(*[sym.mul(e[0][k], cof[k][0]) for k in range(3)])
    inv_det = sym.power(det, -1)
    x = [sym.mul(sym.add(*[sym.mul(cof[i][k], b[k]) for k in range(3)]),
                 inv_det) for i in range(3)]
    return x, [e[0][0], cof[2][2], det], ("M's adjugate", "{0}, {0, 1}, {0, 1, 2}")


def _inverse_terms(deriv, d, jd, fp, mp):
    """Inverse dynamics in one evaluation: ik_jd, and the generalized force
    tau = M qdd - b that the drives supply (J_d^T fd = tau); with three
    actuators also J_d^-1 by its adjugate and fd = J_d^-T tau, so the
    runtime only judges J_d's conditioning. Four actuators need J_d^+,
    which the runtime forms by a QR of J_d."""
    qdd = _vec("qdd")
    tau = deriv.drive_force(qdd, fp, mp)
    ins = [Q, QD, _arg("qdd", 3), _arg("fp", 3), _arg("mp", 3)]
    if len(d) != 3:
        return ("inverse_terms", "d, J_d (as ik_jd) and tau = M qdd + h "
                "- G - J_T,O'^T fp - J_R,P^T mp - passive, the generalized "
                "force the drives supply: J_d^T fd = tau.", ins,
                [("d", d), ("Jd", jd), ("tau", tau)], ("d", "tau"))
    # As in eom_solve, the inverse and the solve work on J_d's and tau's
    # values as atoms.
    ja = [_atom("Jd%d" % k, x) for k, x in enumerate(jd)]
    tau = [_atom("tau%d" % k, x) for k, x in enumerate(tau)]
    cof, inv_det, inv = _adjugate_inverse(ja)
    # fd = J_d^-T tau: fd_i = sum_k (J_d^-1)_ki tau_k = sum_k cof_ik tau_k / det.
    fd = [sym.mul(sym.add(*[sym.mul(cof[i][k], tau[k]) for k in range(3)]),
                  inv_det) for i in range(3)]
    return ("inverse_terms", "d, J_d (as ik_jd), J_d^-1 (by the "
            "adjugate: NaN or infinite where J_d is singular) and fd = J_d^-T "
            "tau, tau = M qdd + h - G - J_T,O'^T fp - J_R,P^T mp - passive: "
            "the actuator forces of the motion.", ins,
            [("d", d), ("Jd", jd), ("Jdinv", inv), ("fd", fd)], ("d", "fd"))


def _reaction_kernels(deriv, fd, fp, mp):
    """joint_reactions (and, with a redundant reaction direction,
    reaction_nullspace): the closed form of reactions.py."""
    nact = len(fd)
    qdd = _vec("qdd")
    lam, z = Reactions(deriv, qdd, fd, fp, mp).solve()
    outs = [("lambda", lam)]
    doc = ("The joint reaction coordinates lambda (%d, docs/model.md section "
           "7) at the accelerations qdd (which must solve the equations of "
           "motion: M qdd = b of prru_eom), in closed form limb by limb"
           % len(lam))
    if z is None:
        doc += "."
    else:
        doc += (": the solution of least norm, lambda . z = 0, and z, the "
                "unit null direction of Q (C3's force along e2 positive).")
        outs.append(("z", z))
    ins = [Q, QD, _arg("qdd", 3), _arg("fd", nact), _arg("fp", 3),
           _arg("mp", 3)]
    spec = [("joint_reactions", doc, ins, outs)]
    if z is not None:
        spec.append(("reaction_nullspace", "z of joint_reactions at q alone.",
                     [Q], [("z", null_direction(deriv))]))
    return spec


def lambda_labels(mech):
    """Names of the 57 reaction coordinates, e.g. 'C1_fx', 'C3_mn'."""
    labels = []
    axis_names = "xyz"
    for j in mech.joints:
        fi = mi = 0
        for kind, e in j.basis:
            named = [k for k in range(3) if e[k].op == "const" and
                     e[k].args[0] == 1 and all(e[o].op == "const" and
                                               e[o].args[0] == 0
                                               for o in range(3) if o != k)]
            if named:
                suffix = axis_names[named[0]]
            else:
                suffix = "u" if j.name in ("C1", "C2") else "n"
            labels.append("%s_%s%s" % (j.name, kind, suffix))
            fi += kind == "f"
            mi += kind == "m"
    return labels


def _frozen(name, value, over):
    """value as a symbol whose partial derivatives with respect to every
    symbol of over are zero: a number computed once in the kernel (qdd
    after the solve) that the derivative of an expression holding it
    treats as an input. Lowered, it is value's own node (shared by CSE)."""
    return sym.define(name, value, partials={s: sym.ZERO for s in over})


def _columns(r, xs, tag):
    """d r / d x for each symbol x of xs: one column (as atoms) each."""
    return [[_atom("%s%d_%d" % (tag, c, i), sym.diff(ri, x))
             for i, ri in enumerate(r)] for c, x in enumerate(xs)]


def _row_major(cols):
    """Columns (one list per variable) as a row-major matrix's entries."""
    return [cols[k][i] for i in range(len(cols[0])) for k in range(len(cols))]


def derivative_kernels(deriv):
    """The closed-form derivatives of forward and inverse dynamics:
    eom_solve_derivs and inverse_derivs (with four actuators the pieces
    the runtime composes the minimum-norm solution's derivatives from)."""
    guards = deriv.mech.guards
    nact = len(deriv.actuators())
    fd, fp, mp = _vec("fd", nact), _vec("fp"), _vec("mp")
    q, qd = list(deriv.mech.q), list(deriv.mech.qd)
    spec = [_eom_solve_derivs(deriv, q, qd, fd, fp, mp)]
    if nact == 3:
        spec.append(_inverse_derivs(deriv, q, qd, fp, mp))
    else:
        spec.append(_inverse_pieces(deriv, q, qd, fp, mp))
    return [Kernel(k[0], k[1], k[2], k[3], guards, witnesses=k[4])
            for k in spec]


def _eom_solve_derivs(deriv, q, qd, fd, fp, mp):
    """qdd = M^-1 b and its derivatives, d qdd/dx = M^-1 (db/dx - (dM/dx)
    qdd): the residual r = b - M qdd with qdd frozen (its value after the
    solve, a number to the derivative) differentiated symbolically, then
    every column solved by eom_solve's factorization of M."""
    m = deriv.mass()
    b = deriv.eom_rhs(fd, fp, mp)
    solve = _mass_solver(deriv, m)
    ba = [_atom("b%d" % k, x) for k, x in enumerate(b)]
    qdd, minors, _ = solve(ba)
    xs = q + qd + fd + fp + mp
    qv = [_frozen("_qddv%d" % i, qdd[i], xs) for i in range(3)]
    r = [b[i] - sym.add(*[m[3 * i + j] * qv[j] for j in range(3)])
         for i in range(3)]
    blocks = []
    for tag, vs in (("rq", q), ("rqd", qd), ("rfd", fd), ("rfp", fp),
                    ("rmp", mp)):
        blocks.append(_row_major([solve(col, "%s%d_" % (tag, c))[0]
                                  for c, col in enumerate(_columns(r, vs, tag))]))
    nact = len(fd)
    return ("eom_solve_derivs", "eom_solve's M, b, qdd and minors, and the "
            "derivatives of qdd, each row-major with row i = qdd_i and "
            "column k = the k-th variable: Dq = dqdd/dq (3x3), Dqd = "
            "dqdd/dqd (3x3), Dfd = dqdd/dfd (3x%d), Dfp = dqdd/dfp (3x3), "
            "Dmp = dqdd/dmp (3x3); d qdd/dx = M^-1 (db/dx - (dM/dx) qdd), "
            "the solves by eom_solve's factorization of M." % nact,
            [Q, QD, _arg("fd", nact), _arg("fp", 3), _arg("mp", 3)],
            [("M", m), ("b", b), ("qdd", qdd), ("minors", minors),
             ("Dq", blocks[0]), ("Dqd", blocks[1]), ("Dfd", blocks[2]),
             ("Dfp", blocks[3]), ("Dmp", blocks[4])], ("b", "qdd"))


def _adjugate_inverse(ja):
    """J_d (3x3, row-major atoms ja) inverted by its adjugate: the
    cofactors cof (cof[i][j] of entry (i, j)), 1 / det and J_d^-1 =
    cof^T / det, row-major (NaN or infinite where J_d is singular)."""
    e = [[ja[3 * i + j] for j in range(3)] for i in range(3)]
    cof = [[sym.add(sym.mul(e[(i + 1) % 3][(j + 1) % 3],
                            e[(i + 2) % 3][(j + 2) % 3]),
                    -sym.mul(e[(i + 1) % 3][(j + 2) % 3],
                             e[(i + 2) % 3][(j + 1) % 3]))
            for j in range(3)] for i in range(3)]
    inv_det = sym.power(sym.add(*[sym.mul(e[0][k], cof[0][k])
                                  for k in range(3)]), -1)
    inv = [sym.mul(cof[j][i], inv_det) for i in range(3) for j in range(3)]
    return cof, inv_det, inv


def _inverse_derivs(deriv, q, qd, fp, mp):
    """inverse_terms (three actuators) and the derivatives of fd = J_d^-T
    tau: dfd/dx = J_d^-T (dtau/dx - (dJ_d/dx)^T fd), from the residual
    r = tau - J_d^T fd with fd frozen, each column by J_d's adjugate."""
    d, jd = deriv.actuators(), deriv.actuator_jacobian()
    qdd = _vec("qdd")
    tau = deriv.drive_force(qdd, fp, mp)
    ja = [_atom("Jd%d" % k, x) for k, x in enumerate(jd)]
    cof, inv_det, inv = _adjugate_inverse(ja)

    def solve_t(rhs):
        """J_d^T x = rhs: x_i = sum_k cof_ik rhs_k / det."""
        return [sym.mul(sym.add(*[sym.mul(cof[i][k], rhs[k])
                                  for k in range(3)]), inv_det)
                for i in range(3)]
    fd = solve_t([_atom("tau%d" % k, x) for k, x in enumerate(tau)])
    xs = q + qd + qdd + fp + mp
    fv = [_frozen("_fdv%d" % i, fd[i], xs) for i in range(3)]
    r = [tau[i] - sym.add(*[jd[3 * j + i] * fv[j] for j in range(3)])
         for i in range(3)]
    # The nine columns by J_d^-T's entries as atoms (the output Jdinv):
    # 9 multiplies a column, where solve_t's cofactors and 1 / det take 12.
    ia = [_atom("Ji%d" % k, x) for k, x in enumerate(inv)]

    def map_inv_t(rhs):
        """J_d^-T rhs: x_i = sum_k (J_d^-1)_ki rhs_k."""
        return [sym.add(*[sym.mul(ia[3 * k + i], rhs[k]) for k in range(3)])
                for i in range(3)]
    blocks = [_row_major([map_inv_t(col) for col in _columns(r, vs, tag)])
              for tag, vs in (("sq", q), ("sqd", qd), ("sqdd", qdd))]
    ins = [Q, QD, _arg("qdd", 3), _arg("fp", 3), _arg("mp", 3)]
    return ("inverse_derivs", "inverse_terms (d, J_d, J_d^-1, fd) and the "
            "derivatives of fd, row-major with row i = fd_i and column k = "
            "the k-th variable: Dq = dfd/dq, Dqd = dfd/dqd, Dqdd = dfd/dqdd "
            "(= J_d^-T M), each 3x3; dfd/dx = J_d^-T (dtau/dx - (dJ_d/dx)^T "
            "fd).", ins,
            [("d", d), ("Jd", jd), ("Jdinv", ia), ("fd", fd),
             ("Dq", blocks[0]), ("Dqd", blocks[1]), ("Dqdd", blocks[2])],
            ("d", "fd"))


def _inverse_pieces(deriv, q, qd, fp, mp):
    """Four actuators: inverse_terms (d, J_d, tau) and the derivatives of
    tau and J_d, from which the runtime composes those of the
    minimum-norm fd = J_d^+T tau (+ t n) with the J_d^+ of its own QR
    (prru_inverse_dynamics'), not the normal equations a symbolic
    (J_d^T J_d)^-1 would be: those square J_d's condition number."""
    d, jd = deriv.actuators(), deriv.actuator_jacobian()
    qdd = _vec("qdd")
    tau = deriv.drive_force(qdd, fp, mp)
    blocks = [_row_major(_columns(tau, vs, tag))
              for tag, vs in (("tq", q), ("tqd", qd), ("tqdd", qdd))]
    # dJ_d/dq_k, one NACT x 3 block per k.
    djd = [x for col in _columns(jd, q, "jq") for x in col]
    ins = [Q, QD, _arg("qdd", 3), _arg("fp", 3), _arg("mp", 3)]
    nact = len(d)
    return ("inverse_derivs", "inverse_terms (d, J_d, tau) and the "
            "derivatives the runtime composes those of the minimum-norm fd "
            "from, row-major with row i = tau_i and column k = the k-th "
            "variable: Dq = dtau/dq, Dqd = dtau/dqd, Dqdd = dtau/dqdd (= M), "
            "each 3x3; DJd = dJ_d/dq (%d: block k, %dx3 row-major, is "
            "dJ_d/dq_k)." % (3 * 3 * nact, nact), ins,
            [("d", d), ("Jd", jd), ("tau", tau), ("Dq", blocks[0]),
             ("Dqd", blocks[1]), ("Dqdd", blocks[2]), ("DJd", djd)],
            ("d", "tau"))
