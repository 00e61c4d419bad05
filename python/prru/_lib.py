"""Finding and loading libprru.so, and the ctypes mirror of its headers.

Every array of a public C struct (runtime/include/prru_descriptor.h,
prru_dynamics.h, prru_sim.h, ...) is sized by the maxima of prru_sizes.h
(MAX_ACT actuators, MAX_BODY bodies, MAX_LAMBDA reaction coordinates), so
the layout is the same for every model and every build; a model's own
counts are its descriptor's (nact, nbody, nlambda), and the binding reads
the first that many entries of each array. ctypes applies the C ABI's
alignment rules, so mirroring a struct field by field reproduces the
compiler's layout.

A header change the mirror does not follow would go unnoticed by the C
compiler; Library therefore checks the layout when it loads (_self_check:
every mirror's size against the library's own sizeof, prru_struct_size;
fields the library fills must hold what independent calls compute, a
pointer the library stores must point where the mirror puts its target,
and guard bytes after each struct must stay untouched), and the Python
tests compare the mirror with the struct definitions in the headers field
by field.
"""

import ctypes
import ctypes.util
import math
import os

from . import errors

ENV_VAR = "PRRU_LIB"
LIB_NAME = "libprru.so"

c_double_p = ctypes.POINTER(ctypes.c_double)
c_int_p = ctypes.POINTER(ctypes.c_int)


# The maxima every public struct's arrays are sized by (prru_sizes.h): the
# layouts are the same for every model and build; a model's own counts are
# its descriptor's.
MAX_ACT, MAX_LIMB, MAX_BODY, MAX_JOINT, MAX_LAMBDA = 4, 4, 13, 16, 76
MAX_REG = 10 * MAX_BODY + 3 * MAX_ACT
MA, ML = MAX_ACT, MAX_LAMBDA


def _arr(ctype, n):
    return ctype * n


class _JointInfo(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("type", ctypes.c_char), ("limb", ctypes.c_int),
                ("proximal", ctypes.c_int), ("distal", ctypes.c_int),
                ("lambda_offset", ctypes.c_int), ("lambda_count", ctypes.c_int)]


# The descriptor's leading fields, identical for every model.
_MECH_HEAD = [("name", ctypes.c_char_p), ("description", ctypes.c_char_p),
              ("model_file", ctypes.c_char_p), ("sha256", ctypes.c_char_p),
              ("format", ctypes.c_int), ("nq", ctypes.c_int), ("nact", ctypes.c_int),
              ("nlimb", ctypes.c_int), ("nbody", ctypes.c_int), ("nlambda", ctypes.c_int),
              ("njoint", ctypes.c_int)]


class _MechHead(ctypes.Structure):
    _fields_ = _MECH_HEAD


class _Model(ctypes.Structure):
    """prru_model: a pointer to the descriptor, the two tolerances of the
    trust criterion (J_d's and the mass matrix's conditioning), the kernel
    table with its parameters, and a loaded model's storage."""
    _fields_ = [("mech", ctypes.c_void_p), ("jd_rcond_min", ctypes.c_double),
                ("mass_rcond_min", ctypes.c_double), ("kernels", ctypes.c_void_p),
                ("kernel_params", ctypes.c_void_p), ("own", ctypes.c_void_p)]


class _MapGrid(ctypes.Structure):
    _fields_ = [("q1_lo", ctypes.c_double), ("q1_hi", ctypes.c_double),
                ("q2_lo", ctypes.c_double), ("q2_hi", ctypes.c_double),
                ("q3", ctypes.c_double), ("n1", ctypes.c_int), ("n2", ctypes.c_int)]


class _MapSummary(ctypes.Structure):
    _fields_ = [("n_points", ctypes.c_long), ("n_ok", ctypes.c_long),
                ("n_singular", ctypes.c_long), ("n_unreachable", ctypes.c_long),
                ("n_other_mode", ctypes.c_long),
                ("index", ctypes.c_double), ("index_log", ctypes.c_double),
                ("singular_fraction", ctypes.c_double),
                ("w_min", ctypes.c_double), ("w_max", ctypes.c_double),
                ("w_min_q", _arr(ctypes.c_double, 2)), ("w_max_q", _arr(ctypes.c_double, 2))]


MAP_PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_long, ctypes.c_long, ctypes.c_void_p)


class _MapOptions(ctypes.Structure):
    # volatile sig_atomic_t is int with glibc on every Linux ABI.
    _fields_ = [("nthreads", ctypes.c_int), ("progress", MAP_PROGRESS_FN),
                ("ctx", ctypes.c_void_p), ("interrupt", c_int_p), ("precision", ctypes.c_int)]


class _MeasureOptions(ctypes.Structure):
    _fields_ = [("rate", ctypes.c_double), ("d_resolution", ctypes.c_double),
                ("force_sigma", ctypes.c_double), ("seed", ctypes.c_ulong)]


class _DiffOptions(ctypes.Structure):
    _fields_ = [("half_width", ctypes.c_int), ("degree", ctypes.c_int)]


class _DiffChoice(ctypes.Structure):
    _fields_ = [("best", _DiffOptions), ("best_error", ctypes.c_double),
                ("default_error", ctypes.c_double), ("tried", ctypes.c_int)]


# prru_stepper and prru_load_kind values.
STEPPERS = ("rk8pd", "rkf45", "rkck", "msbdf")
LOAD_CONSTANT, LOAD_HARMONIC, LOAD_TABLE = 0, 1, 2


class _Quintic(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("t", c_double_p), ("coef", c_double_p)]


class _Topp(ctypes.Structure):
    _fields_ = [("nseg", ctypes.c_int), ("grid", ctypes.c_int), ("q", c_double_p),
                ("x", c_double_p), ("u", c_double_p), ("t", c_double_p), ("duration", ctypes.c_double),
                ("active_fraction", ctypes.c_double), ("iterations", ctypes.c_int)]


class _PathSide(ctypes.Structure):
    _fields_ = [("sign", ctypes.c_int)]


# Design optimisation (prru_design.h).
DESIGN_MAX_VARS = 64


class _DesignProblem(ctypes.Structure):
    """prru_design_problem: the model designed (a prru_model pointer, set
    by prru_design_problem_default), the grid and the constraints."""
    _fields_ = [("model", ctypes.c_void_p), ("grid", _MapGrid), ("rcond_min", ctypes.c_double), ("objective", ctypes.c_int),
                ("stroke", ctypes.c_int), ("stroke_lo", ctypes.c_double), ("stroke_hi", ctypes.c_double),
                ("penalty_weight", ctypes.c_double)]


# Identification (prru_ident.h).
EXCITE_MAX_HARMONICS = 8
CONSISTENT_EXACT, CONSISTENT_COVARIANCE = 0, 1
# prru_identification.stage (prru_ident.h)
IDENTIFY_FIT, IDENTIFY_CONSISTENT, IDENTIFY_PHYSICS, IDENTIFY_MODEL, IDENTIFY_DONE = range(5)


class _Fourier(ctypes.Structure):
    _fields_ = [("period", ctypes.c_double), ("harmonics", ctypes.c_int), ("centre", ctypes.c_double * 3),
                ("a", (ctypes.c_double * EXCITE_MAX_HARMONICS) * 3),
                ("b", (ctypes.c_double * EXCITE_MAX_HARMONICS) * 3)]


class _ConsistentOptions(ctypes.Structure):
    _fields_ = [("mu", ctypes.c_double), ("alpha", ctypes.c_double), ("sigma_floor", ctypes.c_double),
                ("eps", ctypes.c_double), ("max_newton", ctypes.c_int)]


def _guarded(struct, guard_bytes):
    """A struct followed by guard bytes: a library whose struct is larger
    than the mirror writes into the guard instead of foreign memory."""
    return type("_Guarded" + struct.__name__, (ctypes.Structure,),
                {"_fields_": [("s", struct), ("guard", ctypes.c_ubyte * guard_bytes)]})


GUARD_BYTE = 0xA5


def fill_guard(g):
    ctypes.memset(ctypes.addressof(g.guard), GUARD_BYTE, ctypes.sizeof(g.guard))


def guard_intact(g):
    return bytes(g.guard) == bytes([GUARD_BYTE]) * ctypes.sizeof(g.guard)


class Types:
    """The struct types of the library (every array of the maxima, the same
    for every model) and the counts of its built-in model's descriptor."""

    def __init__(self, nact, nbody, nlimb, nlambda, njoint):
        nh = 6 * nbody
        d = ctypes.c_double
        self.nact, self.nh, self.nlambda = nact, nh, nlambda
        self.Mechanism = type("prru_mechanism", (ctypes.Structure,), {"_fields_": _MECH_HEAD + [
            ("body_names", _arr(ctypes.c_char_p, MAX_BODY)), ("body_limb", _arr(ctypes.c_int, MAX_BODY)),
            ("platform", ctypes.c_int), ("lower", _arr(ctypes.c_int, MAX_LIMB)),
            ("upper", _arr(ctypes.c_int, MAX_LIMB)), ("slider", _arr(ctypes.c_int, MAX_LIMB)),
            ("gravity", _arr(d, 3)), ("mass", _arr(d, MAX_BODY)), ("total_mass", d),
            ("com", _arr(_arr(d, 3), MAX_BODY)), ("inertia", _arr(_arr(d, 9), MAX_BODY)),
            ("inertia_inv", _arr(_arr(d, 9), MAX_BODY)),
            ("b", _arr(d, MAX_LIMB)), ("l1", _arr(d, MAX_LIMB)), ("l2", _arr(d, MAX_LIMB)),
            ("a", _arr(d, MAX_LIMB)),
            ("armature", _arr(d, MA)), ("damping", _arr(d, MA)), ("coulomb", _arr(d, MA)),
            ("coulomb_velocity", d), ("joint", _arr(_JointInfo, MAX_JOINT)),
            ("lambda_labels", _arr(ctypes.c_char_p, ML)),
            ("lead", _arr(d, MA)), ("gear", _arr(d, MA)), ("torque_constant", _arr(d, MA)),
            ("force_max", _arr(d, MA)), ("speed_max", _arr(d, MA)),
            ("d_min", _arr(d, MA)), ("d_max", _arr(d, MA)),
            ("drive_keys", ctypes.c_uint), ("rotor_inertia", _arr(d, MA)),
            ("torque_max", _arr(d, MA)), ("motor_speed_max", _arr(d, MA))]})
        self.Loads = type("prru_loads", (ctypes.Structure,), {"_fields_": [
            ("fd", _arr(d, MA)), ("fp", _arr(d, 3)), ("mp", _arr(d, 3))]})
        self.Data = type("prru_data", (ctypes.Structure,), {"_fields_": [
            ("d", _arr(d, MA)), ("Jd", _arr(d, MA * 3)), ("Jdpinv", _arr(d, 3 * MA)),
            ("M", _arr(d, 9)), ("b", _arr(d, 3)), ("qdd", _arr(d, 3)),
            ("r", _arr(d, ML)), ("lambda_null", _arr(d, ML))]})
        self.Linearization = type("prru_linearization", (ctypes.Structure,), {"_fields_": [
            ("qdd", _arr(d, 3)), ("dqdd_dq", _arr(d, 9)), ("dqdd_dqd", _arr(d, 9)),
            ("dqdd_dfd", _arr(d, 3 * MA)), ("dqdd_dfp", _arr(d, 9)),
            ("dqdd_dmp", _arr(d, 9)), ("A", _arr(d, 36)), ("B", _arr(d, 6 * MA)),
            ("dt", d), ("Ad", _arr(d, 36)), ("Bd", _arr(d, 6 * MA))]})
        self.Schedule = type("prru_load_schedule", (ctypes.Structure,), {"_fields_": [
            ("kind", ctypes.c_int), ("base", self.Loads), ("amp", d), ("omega", d),
            ("nact", ctypes.c_int), ("nrows", ctypes.c_int), ("rows", c_double_p)]})
        self.Sample = type("prru_sample", (ctypes.Structure,), {"_fields_": [
            ("t", d), ("q", _arr(d, 3)), ("qd", _arr(d, 3)), ("qdd", _arr(d, 3)),
            ("d", _arr(d, MA)), ("lambda_", _arr(d, ML)), ("T", d), ("V", d)]})
        self.SampleFn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(self.Sample), ctypes.c_void_p)
        self.SimOptions = type("prru_sim_options", (ctypes.Structure,), {"_fields_": [
            ("stepper", ctypes.c_int), ("t_end", d), ("dt_out", d), ("abs_tol", d),
            ("rel_tol", d), ("h0", d), ("reactions", ctypes.c_int),
            ("loads", ctypes.POINTER(self.Schedule)), ("on_sample", self.SampleFn),
            ("ctx", ctypes.c_void_p), ("interrupt", c_int_p),
            ("max_steps", ctypes.c_long)]})
        self.Scenario = type("prru_scenario", (ctypes.Structure,), {"_fields_": [
            ("q0", _arr(d, 3)), ("qd0", _arr(d, 3)), ("loads", self.Schedule),
            ("opt", self.SimOptions)]})
        self.Dme = type("prru_dme", (ctypes.Structure,), {"_fields_": [
            ("status", ctypes.c_int), ("jd_rcond", d), ("w_R", d), ("sigma", _arr(d, 2)),
            ("semi_axis", _arr(d, 2)), ("axis_dir", _arr(_arr(d, 3), 2)), ("sigma_T", d),
            ("half_length_T", d), ("dir_T", _arr(d, 3)), ("Mt", _arr(d, MA * MA)),
            ("JtR", _arr(d, 3 * MA)), ("JtT", _arr(d, 3 * MA))]})
        # Sample columns as doubles: the struct is all doubles, no padding;
        # (first, count) of the model's values, each array holding its maximum.
        self.sample_columns = {}
        col = 0
        for name, width, room in (("t", 1, 1), ("q", 3, 3), ("qd", 3, 3), ("qdd", 3, 3),
                                  ("d", nact, MA), ("lambda", nlambda, ML), ("T", 1, 1), ("V", 1, 1)):
            self.sample_columns[name] = (col, width)
            col += room
        self.sample_width = col
        # Motion planning and tracking (prru.h, prru_traj.h, prru_control.h,
        # prru_param_kernels.h).
        self.Limits = type("prru_limits", (ctypes.Structure,), {"_fields_": [
            ("force_max", _arr(d, MA)), ("speed_max", _arr(d, MA)),
            ("d_min", _arr(d, MA)), ("d_max", _arr(d, MA))]})
        self.Params = type("prru_params", (ctypes.Structure,), {"_fields_": [
            ("b", _arr(d, MAX_LIMB)), ("l1", _arr(d, MAX_LIMB)), ("l2", _arr(d, MAX_LIMB)),
            ("a", _arr(d, MAX_LIMB)), ("gravity", _arr(d, 3)), ("mass", _arr(d, MAX_BODY)),
            ("com", _arr(_arr(d, 3), MAX_BODY)), ("inertia", _arr(_arr(d, 6), MAX_BODY)),
            ("armature", _arr(d, MA)), ("damping", _arr(d, MA)), ("coulomb", _arr(d, MA)),
            ("coulomb_velocity", d)]})
        self.TrackSample = type("prru_track_sample", (ctypes.Structure,), {"_fields_": [
            ("t", d), ("q_ref", _arr(d, 3)), ("qd_ref", _arr(d, 3)), ("qdd_ref", _arr(d, 3)),
            ("q", _arr(d, 3)), ("qd", _arr(d, 3)), ("e", _arr(d, 3)), ("fd", _arr(d, MA)),
            ("fd_cmd", _arr(d, MA)), ("d", _arr(d, MA)), ("dd", _arr(d, MA)), ("qdd", _arr(d, 3)),
            ("saturated", _arr(ctypes.c_int, MA))]})
        self.TrackFn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(self.TrackSample),
                                        ctypes.c_void_p)
        self.TrackOptions = type("prru_track_options", (ctypes.Structure,), {"_fields_": [
            ("kp", _arr(d, 3)), ("kd", _arr(d, 3)), ("control_period", d), ("dt_out", d),
            ("f_max", _arr(d, MA)), ("speed_max", _arr(d, MA)), ("d_min", _arr(d, MA)),
            ("d_max", _arr(d, MA)),
            ("noise_q", d), ("noise_qd", d), ("seed", ctypes.c_ulong), ("q0_offset", _arr(d, 3)),
            ("plant", self.Params), ("abs_tol", d), ("rel_tol", d), ("on_sample", self.TrackFn),
            ("ctx", ctypes.c_void_p), ("interrupt", c_int_p), ("controller", ctypes.c_int),
            ("lqr_q", _arr(d, 6)), ("lqr_r", _arr(d, MA))]})
        self.TrackSummary = type("prru_track_summary", (ctypes.Structure,), {"_fields_": [
            ("samples", ctypes.c_long), ("t_end", d), ("rms_e", _arr(d, 3)), ("max_e", _arr(d, 3)),
            ("max_fd", _arr(d, MA)), ("saturated", _arr(ctypes.c_long, MA)),
            ("any_saturated", ctypes.c_long), ("max_dd", _arr(d, MA)), ("over_speed", ctypes.c_long)]})
        # Identification: PRRU_NREG standard parameters (10 per body, 3 per
        # actuator; prru_regressor_names' last is checked at load).
        self.nreg = 10 * nbody + 3 * nact
        nreg = MAX_REG
        i = ctypes.c_int
        self.Base = type("prru_base", (ctypes.Structure,), {"_fields_": [
            ("nbase", i), ("nreg", i), ("nbody", i), ("nact", i), ("col", _arr(i, nreg)), ("role", _arr(i, nreg)), ("B", _arr(d, nreg * nreg)),
            ("vs", d), ("last_kept", d), ("first_dropped", d), ("nstates", i), ("seed", ctypes.c_ulong)]})
        self.IdentResult = type("prru_ident_result", (ctypes.Structure,), {"_fields_": [
            ("nsamples", i), ("nrows", i), ("dof", i), ("beta", _arr(d, nreg)), ("se", _arr(d, nreg)),
            ("scale", _arr(d, nreg)), ("sigma", d), ("rms", _arr(d, MA)), ("cond", d), ("yrms", d),
            ("inflation", d), ("hac_lags", i), ("R", _arr(d, nreg * nreg))]})
        self.ConsistentResult = type("prru_consistent_result", (ctypes.Structure,), {"_fields_": [
            ("how", i), ("beta", _arr(d, nreg)), ("t", _arr(d, nreg)), ("w", _arr(d, nreg)), ("d2", d),
            ("d2_max", d), ("sigma_w", d), ("prior_dist", d), ("margin", d), ("newton", i)]})
        self.Identification = type("prru_identification", (ctypes.Structure,), {"_fields_": [
            ("stage", i), ("bad", i), ("fit", self.IdentResult), ("options", _ConsistentOptions),
            ("consistent", self.ConsistentResult), ("pi0", _arr(d, nreg)), ("prior", _arr(d, nreg)),
            ("pi", _arr(d, nreg)), ("text", ctypes.c_void_p), ("msg", _arr(ctypes.c_char, 1024))]})
        self.ExciteOptions = type("prru_excite_options", (ctypes.Structure,), {"_fields_": [
            ("fd_max", _arr(d, MA)), ("d_min", _arr(d, MA)), ("d_max", _arr(d, MA)), ("rcond_min", d),
            ("amplitude_max", _arr(d, 3)), ("samples", i), ("check_samples", i), ("max_evals", i),
            ("seed", ctypes.c_ulong), ("speed_max", _arr(d, MA)), ("dt", d), ("periods", i)]})
        self.ExciteResult = type("prru_excite_result", (ctypes.Structure,), {"_fields_": [
            ("cond", d), ("cond_start", d), ("fd_peak", _arr(d, MA)), ("rcond_worst", d), ("evals", i),
            ("shrunk", i)]})
        # Design optimisation (prru_design.h).
        self.DesignVar = type("prru_design_var", (ctypes.Structure,), {"_fields_": [
            ("name", _arr(ctypes.c_char, 24)), ("n", i), ("offset", _arr(ctypes.c_size_t, MAX_BODY)),
            ("lo", d), ("hi", d)]})
        self.DesignEval = type("prru_design_eval", (ctypes.Structure,), {"_fields_": [
            ("valid", i), ("sum", _MapSummary), ("objective", d), ("n_other_mode", ctypes.c_long),
            ("reg_violation", d), ("stroke_violation", d), ("d_min", d), ("d_max", d), ("merit", d),
            ("feasible", i)]})
        self.DesignProgress = ctypes.CFUNCTYPE(i, i, i, ctypes.POINTER(self.DesignEval), d, ctypes.c_void_p)
        self.DesignOptions = type("prru_design_options", (ctypes.Structure,), {"_fields_": [
            ("max_iter", i), ("tol", d), ("restarts", i), ("nthreads", i), ("progress", self.DesignProgress),
            ("ctx", ctypes.c_void_p), ("precision", i)]})
        self.DesignResult = type("prru_design_result", (ctypes.Structure,), {"_fields_": [
            ("best", self.Params), ("start_eval", self.DesignEval), ("best_eval", self.DesignEval),
            ("x0", _arr(d, DESIGN_MAX_VARS)), ("x", _arr(d, DESIGN_MAX_VARS)), ("iterations", i),
            ("evaluations", i), ("restarts_done", i), ("converged", i)]})
        self.GuardedLimits = _guarded(self.Limits, 4096)
        self.GuardedTrackOptions = _guarded(self.TrackOptions, 4096)
        self.GuardedExciteOptions = _guarded(self.ExciteOptions, 4096)
        self.GuardedData = _guarded(self.Data, ctypes.sizeof(self.Data) // 2 + 4096)
        self.GuardedDme = _guarded(self.Dme, 4096)
        self.GuardedScenario = _guarded(self.Scenario, 4096)


def _declare(dll, name, restype, *argtypes):
    f = getattr(dll, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    return f


class Library:
    """One loaded libprru.so: its functions, struct types and descriptor.

    Use load_library() to get one; libraries are cached by path, and
    libraries built from different models can be loaded side by side.
    """

    def __init__(self, path):
        self.path = path
        self.dll = ctypes.CDLL(path)
        try:
            head = _MechHead.in_dll(self.dll, "prru_mech")
        except ValueError as e:
            raise errors.LibraryNotFound(
                "%s: not a prru library (no prru_mech descriptor: %s)" % (path, e)) from None
        self.types = Types(head.nact, head.nbody, head.nlimb, head.nlambda, head.njoint)
        self.mech = self.types.Mechanism.in_dll(self.dll, "prru_mech")
        self._declare_functions()
        self._self_check()

    def _declare_functions(self):
        t, dll, i, d = self.types, self.dll, ctypes.c_int, ctypes.c_double
        mp, dp = ctypes.POINTER(_Model), ctypes.POINTER(t.Data)
        lp, vp = ctypes.POINTER(t.Loads), c_double_p
        self.strerror = _declare(dll, "prru_strerror", ctypes.c_char_p, i)
        self.model_default = _declare(dll, "prru_model_default", None, mp)
        self.model_load = _declare(dll, "prru_model_load", i, mp, ctypes.c_char_p,
                                   ctypes.c_char_p, i)
        self.model_free = _declare(dll, "prru_model_free", None, mp)
        self.check_reachable = _declare(dll, "prru_check_reachable", i, mp, dp, vp)
        self.check_regular = _declare(dll, "prru_check_regular", i, mp, dp, vp, vp)
        self.actuators = _declare(dll, "prru_actuators", i, mp, dp, vp, vp)
        self.forward_kinematics = _declare(dll, "prru_forward_kinematics", i, mp, dp, vp, vp, vp)
        self.forward_kinematics_lsq = _declare(dll, "prru_forward_kinematics_lsq", i,
                                               mp, dp, vp, vp, vp, vp)
        self.fk_default_seed = _declare(dll, "prru_fk_default_seed", None, mp, vp, vp)
        self.forward_dynamics = _declare(dll, "prru_forward_dynamics", i, mp, dp, vp, vp, lp, vp)
        self.linearize_why = _declare(dll, "prru_linearize_why", i, mp, dp, vp, vp, lp, d,
                                      ctypes.POINTER(t.Linearization), ctypes.c_char_p, i)
        self.linearize_batch = _declare(dll, "prru_linearize_batch", i, mp, i, vp, vp, lp, d,
                                        ctypes.POINTER(t.Linearization), c_int_p)
        self.inverse_dynamics_preload = _declare(dll, "prru_inverse_dynamics_preload", i,
                                                 mp, dp, vp, vp, vp, lp, d, vp)
        self.actuator_null = _declare(dll, "prru_actuator_null", i, mp, dp, vp, vp)
        self.reactions = _declare(dll, "prru_reactions", i, mp, dp, vp, vp, lp, vp)
        self.reaction_null = _declare(dll, "prru_reaction_null", i, mp, dp, vp, vp)
        self.energies = _declare(dll, "prru_energies", i, mp, vp, vp, vp, vp)
        self.power = _declare(dll, "prru_power", None, mp, vp, vp, lp, vp, vp)
        # A model's kernels (prru_model_*: the specialised ones or, for a
        # loaded model, the parameter ones): NaN outputs where q is unreachable.
        self.model_ik_jd = _declare(dll, "prru_model_ik_jd", None, mp, vp, vp, vp)
        self.model_dynamics = _declare(dll, "prru_model_dynamics", None, mp, vp, vp, vp, vp, vp)
        self.model_passive = _declare(dll, "prru_model_passive", None, mp, vp, vp, vp)
        self.model_platform_jacobian = _declare(dll, "prru_model_platform_jacobian", None,
                                                mp, vp, vp)
        self.model_poses = _declare(dll, "prru_model_poses", None, mp, vp, vp, vp)
        # Generated kernels (prru_kernels.h), for the layout self-check.
        self.ik_jd = _declare(dll, "prru_ik_jd", None, vp, vp, vp)
        self.dynamics = _declare(dll, "prru_dynamics", None, vp, vp, vp, vp, vp)
        self.passive = _declare(dll, "prru_passive", None, vp, vp, vp)
        self.platform_jacobian = _declare(dll, "prru_platform_jacobian", None, vp, vp)
        self.poses = _declare(dll, "prru_poses", None, vp, vp, vp)
        # Simulation and scenarios.
        sp, op = ctypes.POINTER(t.Scenario), ctypes.POINTER(t.SimOptions)
        self.sim_options_default = _declare(dll, "prru_sim_options_default", None, op)
        self.simulate = _declare(dll, "prru_simulate", i, mp, vp, vp, op, vp,
                                 ctypes.c_char_p, i)
        self.scenario_paper = _declare(dll, "prru_scenario_paper", None, sp)
        self.scenario_read = _declare(dll, "prru_scenario_read", i, mp, sp, ctypes.c_char_p,
                                      ctypes.c_char_p, i)
        self.scenario_free = _declare(dll, "prru_scenario_free", None, sp)
        # Manipulability and maps (prru_dme.h).
        self.dme_eval = _declare(dll, "prru_dme_eval", i, mp, dp, vp, ctypes.POINTER(t.Dme))
        self.map_axis = _declare(dll, "prru_map_axis", d, d, d, i, i)
        self.dme_status_name = _declare(dll, "prru_dme_status_name", ctypes.c_char_p, i)
        self.map_check = _declare(dll, "prru_map_check", i, ctypes.POINTER(_MapGrid))
        self.map_options_default = _declare(dll, "prru_map_options_default", None,
                                            ctypes.POINTER(_MapOptions))
        self.precision_available = _declare(dll, "prru_precision_available", i, mp, i)
        self.map_eval = _declare(dll, "prru_map_eval", i, mp, ctypes.POINTER(_MapGrid),
                                 ctypes.POINTER(_MapOptions), vp,
                                 ctypes.POINTER(ctypes.c_ubyte), ctypes.POINTER(_MapSummary))

        mo = ctypes.POINTER(_MeasureOptions)
        self.measure_rows = _declare(dll, "prru_measure_rows", i, vp, i, mo, c_int_p, c_int_p,
                                     ctypes.c_char_p, i)
        self.measure_apply = _declare(dll, "prru_measure_apply", i, mo, i, i, vp, vp, ctypes.c_char_p, i)
        self.measure_best_diff = _declare(dll, "prru_measure_best_diff", i, mp, i, vp, vp, vp,
                                          ctypes.POINTER(_DiffChoice), ctypes.c_char_p, i)
        # Motion: limits, quintics, the time-optimal planner, tracking.
        cp, lmp = ctypes.c_char_p, ctypes.POINTER(t.Limits)
        qp, tpp = ctypes.POINTER(_Quintic), ctypes.POINTER(_Topp)
        self.limits_none = _declare(dll, "prru_limits_none", None, lmp)
        self.model_limits = _declare(dll, "prru_model_limits", None, mp, lmp)
        self.limits_ratio = _declare(dll, "prru_limits_ratio", i, mp, dp, lmp, vp, vp, vp, vp, vp,
                                     vp, c_int_p, c_int_p)
        self.quintic_waypoints = _declare(dll, "prru_quintic_waypoints", i, qp, i, vp, vp, d, cp, i)
        self.quintic_samples = _declare(dll, "prru_quintic_samples", i, qp, i, vp, vp, vp, vp, cp, i)
        self.quintic_eval = _declare(dll, "prru_quintic_eval", i, qp, d, vp, vp, vp)
        self.quintic_t_begin = _declare(dll, "prru_quintic_t_begin", d, qp)
        self.quintic_t_end = _declare(dll, "prru_quintic_t_end", d, qp)
        self.row_count = _declare(dll, "prru_row_count", ctypes.c_long, d, d, d)
        self.row_time = _declare(dll, "prru_row_time", d, d, d, d, ctypes.c_long, ctypes.c_long)
        self.quintic_free = _declare(dll, "prru_quintic_free", None, qp)
        self.quintic_fastest = _declare(dll, "prru_quintic_fastest", i, mp, i, vp, lmp, i, vp, cp, i)
        self.path_side_init = _declare(dll, "prru_path_side_init", None, ctypes.POINTER(_PathSide))
        self.path_sample = _declare(dll, "prru_path_sample", i, ctypes.POINTER(_PathSide), mp, dp, vp,
                                    vp, c_int_p)
        self.model_actuator_rates = _declare(dll, "prru_model_actuator_rates", None, mp, vp, vp, vp, vp)
        self.topp_solve = _declare(dll, "prru_topp_solve", i, tpp, mp, i, vp, lmp, i, cp, i)
        self.topp_eval = _declare(dll, "prru_topp_eval", i, tpp, d, vp, vp, vp)
        self.topp_free = _declare(dll, "prru_topp_free", None, tpp)
        self.topp_row = _declare(dll, "prru_topp_row", i, mp, dp, lmp, tpp, d, vp, vp, vp, vp, vp, cp, i)
        top, pp = ctypes.POINTER(t.TrackOptions), ctypes.POINTER(t.Params)
        self.track_options_default = _declare(dll, "prru_track_options_default", None, mp, top)
        self.track_options_check = _declare(dll, "prru_track_options_check", i, mp, top, cp, i)
        self.track_gains_bandwidth = _declare(dll, "prru_track_gains_bandwidth", i, d, top)
        self.track_check_reference = _declare(dll, "prru_track_check_reference", i, mp, qp, top, d,
                                              vp, cp, i)
        self.track = _declare(dll, "prru_track", i, mp, qp, top, ctypes.POINTER(t.TrackSummary), cp, i)
        self.lqr_default_weights = _declare(dll, "prru_lqr_default_weights", i, mp, qp, d,
                                            ctypes.POINTER(d), ctypes.POINTER(d), cp, i)
        self.model_params = _declare(dll, "prru_model_params", None, mp, pp)
        self.params_scale = _declare(dll, "prru_params_scale", i, pp, cp, d)
        # Identification.
        bp, irp = ctypes.POINTER(t.Base), ctypes.POINTER(t.IdentResult)
        eop, fp = ctypes.POINTER(t.ExciteOptions), ctypes.POINTER(_Fourier)
        self.model_is_built = _declare(dll, "prru_model_is_built", i, mp, i)
        self.model_with_limits = _declare(dll, "prru_model_with_limits", i, mp, mp, lmp)
        self.ident_default_vs = _declare(dll, "prru_ident_default_vs", d, mp)
        self.base_compute = _declare(dll, "prru_base_compute", i, mp, d, i, ctypes.c_ulong, bp)
        self.base_params = _declare(dll, "prru_base_params", None, bp, vp, vp)
        self.base_param_name = _declare(dll, "prru_base_param_name", ctypes.c_char_p, bp, i)
        self.ident_standard = _declare(dll, "prru_ident_standard", None, ctypes.c_void_p, vp)
        self.identify = _declare(dll, "prru_identify", i, mp, bp, i, vp, vp, vp, vp, irp, c_int_p)
        self.consistent_options_default = _declare(dll, "prru_consistent_options_default", None,
                                                   ctypes.POINTER(_ConsistentOptions))
        self.ident_consistent = _declare(dll, "prru_ident_consistent", i, mp, bp, irp, vp,
                                         ctypes.POINTER(_ConsistentOptions), vp,
                                         ctypes.POINTER(t.ConsistentResult))
        self.identify_model = _declare(dll, "prru_identify_model", i, mp, bp, i, vp, vp, vp, vp, cp, cp,
                                       ctypes.POINTER(t.Identification))
        self.ident_model_params = _declare(dll, "prru_ident_model_params", i, mp, bp, vp, pp, cp, i)
        self.model_file_text = _declare(dll, "prru_model_file_text", i, mp, pp, cp, cp,
                                        ctypes.POINTER(ctypes.c_void_p), cp, i)
        self.model_name_valid = _declare(dll, "prru_model_name_valid", i, cp)
        self.model_name_derive = _declare(dll, "prru_model_name_derive", None, cp, cp, cp)
        self.excite_options_default = _declare(dll, "prru_excite_options_default", None, eop)
        self.excite_options_limits = _declare(dll, "prru_excite_options_limits", None, eop, lmp)
        self.excite_rows = _declare(dll, "prru_excite_rows", ctypes.c_long, fp, eop)
        self.fourier_default = _declare(dll, "prru_fourier_default", None, fp)
        self.excite = _declare(dll, "prru_excite", i, mp, bp, eop, c_int_p, fp,
                               ctypes.POINTER(t.ExciteResult), cp, i)
        self.fourier_eval = _declare(dll, "prru_fourier_eval", None, fp, d, vp, vp, vp)
        self.regressor_names = (ctypes.c_char_p * t.nreg).in_dll(dll, "prru_regressor_names")
        # Design optimisation.
        dpp, dvp = ctypes.POINTER(_DesignProblem), ctypes.POINTER(t.DesignVar)
        self.design_problem_default = _declare(dll, "prru_design_problem_default", None, mp, dpp,
                                               ctypes.POINTER(_MapGrid))
        self.design_problem_check = _declare(dll, "prru_design_problem_check", i, dpp, cp, i)
        self.design_problem_stroke = _declare(dll, "prru_design_problem_stroke", i, dpp, lmp, cp, i)
        self.objective_parse = _declare(dll, "prru_objective_parse", i, cp, c_int_p)
        self.design_var_parse = _declare(dll, "prru_design_var_parse", i, mp, cp, dvp, cp, i)
        self.design_var_bounds = _declare(dll, "prru_design_var_bounds", i, mp, pp, dvp, d)
        self.design_get = _declare(dll, "prru_design_get", d, pp, dvp)
        self.design_check = _declare(dll, "prru_design_check", i, mp, pp, cp, i)
        self.design_options_default = _declare(dll, "prru_design_options_default", None,
                                               ctypes.POINTER(t.DesignOptions))
        self.design_optimize = _declare(dll, "prru_design_optimize", i, dpp, pp, dvp, i,
                                        ctypes.POINTER(t.DesignOptions), ctypes.POINTER(t.DesignResult), cp, i)
        # The C library's free, for the strings the library allocates.
        self.free = _declare(ctypes.CDLL(None), "free", None, ctypes.c_void_p)

    def status_text(self, status):
        return self.strerror(status).decode()

    def new_model(self, jd_rcond_min=None, path=None):
        """A prru_model: the built-in one, or the model file at path
        (prru_model_load; its status's exception with the library's message:
        PrruIOError unreadable, ParseError refused, InputError another
        number of limbs than the library's)."""
        m = _Model()
        if path is None:
            self.model_default(ctypes.byref(m))
        else:
            msg = ctypes.create_string_buffer(1024)
            st = self.model_load(ctypes.byref(m), os.fsencode(path), msg, len(msg))
            if st != 0:
                text = msg.value.decode("utf-8", "replace") or self.status_text(st)
                raise errors.make_error(st, text)
        if jd_rcond_min is not None:
            m.jd_rcond_min = jd_rcond_min
        return m

    def mechanism(self, m):
        """The descriptor m points at (the built model's, or a loaded one's)."""
        return ctypes.cast(m.mech, ctypes.POINTER(self.types.Mechanism)).contents

    def new_data(self):
        g = self.types.GuardedData()
        fill_guard(g)
        return g

    # ---- layout self-check ----
    def _layout_error(self, what):
        return errors.LayoutError(
            "%s does not match this Python package's mirror of prru.h / prru_mechanism.h (%s): "
            "the package and the library come from different versions of prru; use the "
            "python/ directory of the tree the library was built from" % (self.path, what))

    # The mirrors defined at module level, by their C names (Types' are
    # named after their C structs).
    _MODULE_MIRRORS = {"prru_model": _Model, "prru_joint_info": _JointInfo, "prru_map_grid": _MapGrid,
                       "prru_map_summary": _MapSummary, "prru_map_options": _MapOptions,
                       "prru_measure_options": _MeasureOptions, "prru_diff_options": _DiffOptions,
                       "prru_diff_choice": _DiffChoice, "prru_quintic": _Quintic, "prru_topp": _Topp,
                       "prru_path_side": _PathSide, "prru_design_problem": _DesignProblem,
                       "prru_fourier": _Fourier, "prru_consistent_options": _ConsistentOptions}

    def mirrors(self):
        """{C name: ctypes mirror} of every public struct this package mirrors."""
        out = dict(self._MODULE_MIRRORS)
        for v in vars(self.types).values():
            if isinstance(v, type) and issubclass(v, ctypes.Structure) and v.__name__.startswith("prru_"):
                out[v.__name__] = v
        return out

    def _check_struct_sizes(self):
        """Every mirror's size against the library's own sizeof
        (prru_struct_size): a field missing, added or resized in either."""
        size = _declare(self.dll, "prru_struct_size", ctypes.c_size_t, ctypes.c_char_p)
        for name, mirror in sorted(self.mirrors().items()):
            if size(name.encode()) != ctypes.sizeof(mirror):
                raise self._layout_error("sizeof(%s): %d in the library, %d in the mirror"
                                         % (name, size(name.encode()), ctypes.sizeof(mirror)))

    def _self_check(self):
        self._check_struct_sizes()
        self._check_mechanism()
        self._check_scenario()
        self._check_data_and_dme()
        self._check_map_summary()
        self._check_motion()

    def _check_mechanism(self):
        me = self.mech
        if me.nq != 3 or me.nact < 3 or me.nbody != 1 + 3 * me.nlimb or me.njoint != 4 * me.nlimb:
            raise self._layout_error("descriptor sizes nq=%d nact=%d nlimb=%d nbody=%d njoint=%d"
                                     % (me.nq, me.nact, me.nlimb, me.nbody, me.njoint))
        offset = 0
        for k in range(me.njoint):
            j = me.joint[k]
            if j.lambda_offset != offset or j.lambda_count <= 0:
                raise self._layout_error("joint %d's reaction offset" % k)
            offset += j.lambda_count
        if offset != me.nlambda:
            raise self._layout_error("joint reaction counts do not add up to nlambda")
        for k in range(me.nbody):
            a, b = me.inertia[k], me.inertia_inv[k]
            for r in range(3):
                for c in range(3):
                    v = sum(a[3 * r + s] * b[3 * s + c] for s in range(3))
                    if not abs(v - (r == c)) <= 1e-9:
                        raise self._layout_error("body %d's inertia times its inverse" % k)
        last = me.joint[me.njoint - 1]
        label = me.lambda_labels[me.nlambda - 1]
        if not label or not label.decode().startswith(last.name.decode() + "_"):
            raise self._layout_error("the last reaction label")

    def _check_scenario(self):
        t = self.types
        g = t.GuardedScenario()
        fill_guard(g)
        self.scenario_paper(ctypes.byref(g.s))
        s = g.s
        loads_at = ctypes.addressof(s) + t.Scenario.loads.offset
        if ctypes.cast(s.opt.loads, ctypes.c_void_p).value != loads_at:
            raise self._layout_error("prru_scenario.opt.loads")
        if (list(s.q0) != [0.0, math.pi / 6, -0.8] or s.opt.t_end != 1.0 or s.opt.dt_out != 1e-3
                or s.loads.kind != LOAD_HARMONIC or s.loads.amp != 50.0
                or s.opt.max_steps != 0 or s.loads.nrows != 0):
            raise self._layout_error("prru_scenario_paper's fields")
        if not guard_intact(g):
            raise self._layout_error("sizeof(prru_scenario)")
        self.scenario_free(ctypes.byref(s))

    def _check_map_summary(self):
        """A 2 x 2 map's summary in a guarded mirror: its counts add up (a
        field missing or moved reads a double as a count) and the library
        writes nothing past the mirror."""
        g = _MapGrid(-1e-3, 1e-3, -1e-3, 1e-3, 0.0, 2, 2)
        o = _MapOptions()
        self.map_options_default(ctypes.byref(o))
        o.nthreads = 1
        w, st = (ctypes.c_double * 4)(), (ctypes.c_ubyte * 4)()
        gs = _guarded(_MapSummary, 4096)()
        fill_guard(gs)
        m = self.new_model()
        if self.map_eval(ctypes.byref(m), ctypes.byref(g), ctypes.byref(o), w, st,
                         ctypes.byref(gs.s)) != errors.OK:
            return
        s = gs.s
        n_not_ok = s.n_singular + s.n_unreachable
        if (s.n_points != 4 or s.n_ok + n_not_ok != 4 or not 0 <= s.n_other_mode <= s.n_singular
                or s.singular_fraction != n_not_ok / 4 or not guard_intact(gs)):
            raise self._layout_error("prru_map_summary")

    def _check_motion(self):
        """prru_track_options_default, prru_model_limits and
        prru_excite_options_default into guarded mirrors: the defaults the
        headers state, the plant the model's own numbers
        (prru_model_params), and nothing written past the mirror."""
        t, m = self.types, self.new_model()
        g = t.GuardedTrackOptions()
        fill_guard(g)
        self.track_options_default(ctypes.byref(m), ctypes.byref(g.s))
        o, p = g.s, t.Params()
        self.model_params(ctypes.byref(m), ctypes.byref(p))
        if (list(o.kp) != [400.0] * 3 or list(o.kd) != [40.0] * 3 or o.control_period != 0
                or o.dt_out != 1e-3 or o.seed != 1 or o.abs_tol != 1e-12 or o.rel_tol != 1e-12
                or any(v != math.inf for v in o.f_max[:t.nact]) or any(v != math.inf for v in o.speed_max[:t.nact])
                or any(v != -math.inf for v in o.d_min[:t.nact])
                or bytes(o.plant) != bytes(p) or p.coulomb_velocity <= 0 or o.on_sample
                or o.controller != 0 or any(o.lqr_q) or any(o.lqr_r) or not guard_intact(g)):
            raise self._layout_error("prru_track_options")
        gl = t.GuardedLimits()
        fill_guard(gl)
        self.model_limits(ctypes.byref(m), ctypes.byref(gl.s))
        lim = gl.s
        if (not guard_intact(gl) or any(not lim.d_min[i] < lim.d_max[i] for i in range(t.nact))
                or any(not lim.force_max[i] > 0 or not lim.speed_max[i] > 0 for i in range(t.nact))):
            raise self._layout_error("prru_limits")
        ge = t.GuardedExciteOptions()
        fill_guard(ge)
        self.excite_options_default(ctypes.byref(ge.s))
        e = ge.s
        if (not guard_intact(ge) or e.samples != 100 or e.check_samples != 0 or e.max_evals != 3000
                or e.seed != 1 or e.dt != 0.01 or e.periods != 1 or any(v != math.inf for v in e.speed_max[:t.nact])):
            raise self._layout_error("prru_excite_options")
        last = self.regressor_names[t.nreg - 1]
        if last != ("coulomb%d" % t.nact).encode():
            raise self._layout_error("PRRU_NREG (prru_regressor_names' last is %r)" % last)

    def _check_data_and_dme(self):
        """At q = 0 (every valid model assembles there; when J_d happens to
        be singular the data checks are skipped), the fields prru_reactions
        leaves in prru_data and prru_dme_eval's outputs against independent
        calls."""
        t, n = self.types, self.types.nact
        m, g = self.new_model(), self.new_data()
        q = (ctypes.c_double * 3)()
        zero3 = (ctypes.c_double * 3)()
        if self.check_regular(ctypes.byref(m), ctypes.byref(g.s), q, None) != errors.OK:
            return
        lam = (ctypes.c_double * t.nlambda)()
        loads = t.Loads()
        if self.reactions(ctypes.byref(m), ctypes.byref(g.s), q, zero3, ctypes.byref(loads),
                          lam) != errors.OK:
            return
        d_ref, jd_ref = (ctypes.c_double * n)(), (ctypes.c_double * (3 * n))()
        self.ik_jd(q, d_ref, jd_ref)
        qdd_ref = (ctypes.c_double * 3)()
        g2 = self.new_data()
        self.forward_dynamics(ctypes.byref(m), ctypes.byref(g2.s), q, zero3, ctypes.byref(loads),
                              qdd_ref)
        s = g.s
        if s.d[:n] != list(d_ref) or s.Jd[:3 * n] != list(jd_ref):
            raise self._layout_error("prru_data.d, prru_data.Jd")
        if list(s.qdd) != list(qdd_ref) or s.r[:t.nlambda] != list(lam):
            raise self._layout_error("prru_data.qdd, prru_data.r")
        if self.mech.nlambda - (t.nh - 3) == 0 and any(s.lambda_null):
            raise self._layout_error("prru_data.lambda_null")
        if not guard_intact(g):
            raise self._layout_error("sizeof(prru_data)")
        gd = t.GuardedDme()
        fill_guard(gd)
        if self.dme_eval(ctypes.byref(m), ctypes.byref(g.s), q, ctypes.byref(gd.s)) != errors.OK:
            return
        o = gd.s
        if (o.status != errors.OK or o.w_R != o.sigma[0] / o.sigma[1]
                or o.semi_axis[0] != 1 / o.sigma[0] or o.half_length_T != 1 / o.sigma_T
                or abs(sum(x * x for x in o.dir_T) - 1) > 1e-12 or not guard_intact(gd)):
            raise self._layout_error("prru_dme")


_cache = {}


def _installed_library(here):
    """The library `cmake --install` put beside this package's install
    (named in the _installed.py it writes), or None in a source tree."""
    try:
        from . import _installed
    except ImportError:
        return None
    if _installed.RELATIVE:
        return os.path.normpath(os.path.join(here, _installed.LIBRARY))
    return _installed.LIBRARY


def _candidates(explicit):
    """(source, path) pairs to try, in order."""
    if explicit is not None:
        return [("argument", os.fspath(explicit))]
    out = []
    env = os.environ.get(ENV_VAR)
    if env:
        out.append(("$" + ENV_VAR, env))
        return out
    here = os.path.dirname(os.path.abspath(__file__))
    out.append(("beside the package", os.path.join(here, LIB_NAME)))
    installed = _installed_library(here)
    if installed:
        out.append(("the installed library (prru/_installed.py)", installed))
    root = os.path.dirname(os.path.dirname(here))
    out.append(("the source tree's build/", os.path.join(root, "build", "runtime", LIB_NAME)))
    out.append(("the system's library path", ctypes.util.find_library("prru")))
    return out


def _resolve(path):
    """A build directory stands for its runtime/libprru.so."""
    if os.path.isdir(path):
        for sub in (os.path.join(path, "runtime", LIB_NAME), os.path.join(path, LIB_NAME)):
            if os.path.exists(sub):
                return sub
        return os.path.join(path, "runtime", LIB_NAME)
    return path


def load_library(path=None):
    """The prru library at path (a file, or a build directory holding
    runtime/libprru.so); without a path, $PRRU_LIB (when set, the only
    place tried: a wrong setting is an error, not a fallback), then
    libprru.so beside this package, then the library installed with it
    (`cmake --install` writes its place into prru/_installed.py), then
    build/runtime/libprru.so of the source tree the package sits in, then
    the system's library path.

    Raises LibraryNotFound naming every place tried and why it failed, and
    LayoutError when the library's structs differ from this package's."""
    tried = []
    for source, cand in _candidates(path):
        if cand is None:
            tried.append("libprru (%s): not found" % source)
            continue
        if cand in _cache:
            return _cache[cand]
        full = cand if source == "the system's library path" else _resolve(cand)
        if source != "the system's library path" and not os.path.exists(full):
            tried.append("%s (%s): no such file" % (full, source))
            continue
        key = os.path.realpath(full) if os.path.exists(full) else full
        if key in _cache:
            return _cache[key]
        try:
            lib = Library(full)
        except OSError as e:
            if isinstance(e, errors.PrruError):
                raise
            tried.append("%s (%s): %s" % (full, source, e))
            continue
        _cache[key] = _cache[cand] = lib
        return lib
    raise errors.LibraryNotFound(
        "prru: cannot load libprru.so (build it with `cmake --build BUILD --target prru_shared`, "
        "then pass its path, or set %s=BUILD/runtime/libprru.so); tried:\n  %s"
        % (ENV_VAR, "\n  ".join(tried)))
