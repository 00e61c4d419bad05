#!/usr/bin/env python3
"""Smoke test of prru_bench: `prru_bench --quick --json` exits 0 and prints
one JSON object with every kernel of issue 5, the runtime-parameter kernels
and their cost against the constant ones, and the build description.

Timings are checked only for being positive and finite, never against
targets: this runs on a shared machine under ctest -j.

usage: check_json.py PATH_TO_PRRU_BENCH
"""
import json
import math
import subprocess
import sys

KERNELS = ["jd", "ik_jd", "param_ik_jd", "jacobians", "bias_terms", "mass",
           "param_mass", "bias", "gravity", "dynamics", "param_dynamics",
           "forward_dynamics", "inverse_dynamics", "reactions"]
# Runtime-parameter kernels and the constant kernel each is compared with.
PARAM_COST = {"ik_jd": "param_ik_jd", "mass": "param_mass",
              "dynamics": "param_dynamics"}


def fail(msg):
    print("bench_smoke: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def positive(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def main():
    if len(sys.argv) != 2:
        fail("usage: check_json.py PATH_TO_PRRU_BENCH")
    run = subprocess.run([sys.argv[1], "--quick", "--json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         universal_newlines=True, timeout=600)
    sys.stderr.write(run.stderr)
    if run.returncode != 0:
        fail("prru_bench exited with %d" % run.returncode)
    try:
        doc = json.loads(run.stdout)
    except ValueError as e:
        fail("stdout is not one JSON object (%s): %r" % (e, run.stdout[:200]))
    if not isinstance(doc, dict):
        fail("top level is not an object")
    for key in ("cpu", "compiler", "flags"):
        if not isinstance(doc.get(key), str) or not doc[key]:
            fail("%r missing or empty" % key)
    model = doc.get("model")
    if not isinstance(model, dict) or set(model) != {"name", "file", "sha256"} \
            or len(model["sha256"]) != 64:
        fail("'model' (name, file, sha256) missing: %r" % (model,))
    kernels = doc.get("kernels")
    if not isinstance(kernels, dict):
        fail("'kernels' missing")
    names = list(KERNELS)
    # w_r is required once the bench was built with the DME API.
    if "w_r" in kernels or "w_r" not in doc.get("missing", {}):
        names.append("w_r")
    for name in names:
        k = kernels.get(name)
        if not isinstance(k, dict):
            fail("kernel %r missing" % name)
        if set(k) != {"generated_ns", "reference_ns", "ratio"}:
            fail("kernel %r has keys %s" % (name, sorted(k)))
        if not (positive(k["generated_ns"]) and positive(k["reference_ns"])
                and positive(k["ratio"])):
            fail("kernel %r: non-positive or non-finite value %s" % (name, k))
        # ratio = reference / generated, up to the 4 printed digits
        want = k["reference_ns"] / k["generated_ns"]
        if abs(k["ratio"] - want) > 2e-3 * want:
            fail("kernel %r: ratio %g is not reference/generated = %g"
                 % (name, k["ratio"], want))
    extra = sorted(set(kernels) - set(names))
    if extra:
        fail("unexpected kernels %s" % extra)
    # The generated and reference paths agree: this is a correctness
    # property, not a timing, so it is asserted.
    for name, diff in doc.get("max_rel_diff", {}).items():
        if not (isinstance(diff, (int, float)) and diff <= 1e-9):
            fail("kernel %r: generated and reference differ by %r" % (name, diff))
    cost = doc.get("param_cost")
    if not isinstance(cost, dict) or set(cost) != set(PARAM_COST):
        fail("'param_cost' must list %s: %r" % (sorted(PARAM_COST), cost))
    for const, param in PARAM_COST.items():
        c = cost[const]
        if set(c) != {"param_ns", "constant_ns", "ratio", "ratio_spread",
                      "param_arith", "constant_arith"}:
            fail("param_cost %r has keys %s" % (const, sorted(c)))
        lo, hi = c["ratio_spread"]
        if not (positive(c["param_ns"]) and positive(c["constant_ns"])
                and positive(lo) and lo <= c["ratio"] <= hi):
            fail("param_cost %r: times or ratio median %r outside [min, max]"
                 " %r" % (const, c["ratio"], c["ratio_spread"]))
        if not (isinstance(c["param_arith"], int) and
                isinstance(c["constant_arith"], int) and
                c["param_arith"] >= c["constant_arith"] > 0):
            fail("param_cost %r: operation counts %r" % (const, c))
    # The model file loaded onto the parameter kernels, against the
    # specialised ones (both timed in the same run).
    # The parameter path is the simple structural variant where the
    # model's numbers allow it, and the general kernels are timed too.
    paths = doc.get("loaded_paths")
    if not isinstance(paths, dict) or set(paths) != {"structure", "dynamics", "forward_dynamics",
                                                      "inverse_dynamics", "reactions"}:
        fail("'loaded_paths' must time dynamics, forward and inverse dynamics and the "
             "reactions, and name the structure: %r" % (paths,))
    if paths["structure"] not in ("simple", "general"):
        fail("loaded_paths: structure %r" % (paths["structure"],))
    for name, r in paths.items():
        if name == "structure":
            continue
        for key in ("parameter_over_specialised", "general_over_specialised"):
            s = r.get(key, {})
            if not (positive(r.get("specialised_ns")) and positive(r.get("parameter_ns"))
                    and positive(r.get("general_ns")) and positive(s.get("min"))
                    and s["min"] <= s.get("median", 0) <= s.get("max", 0)):
                fail("loaded_paths %r: %r" % (name, r))
    sim = doc.get("simulated_second")
    if not isinstance(sim, dict) or not positive(sim.get("generated_s")):
        fail("simulated_second missing")
    if sim.get("scenario") != "paper section 4.3":
        fail("simulated second: scenario %r" % sim.get("scenario"))
    ps = sim.get("parameter_over_specialised", {})
    if not (positive(sim.get("parameter_s")) and positive(ps.get("min"))
            and ps["min"] <= ps.get("median", 0) <= ps.get("max", 0)):
        fail("simulated second: the parameter path %r" % (sim,))
    if not sim.get("max_abs_diff_q", 1.0) <= 1e-7:
        fail("simulated second: final q differs by %r" % sim.get("max_abs_diff_q"))
    bound = doc.get("bound")
    if not isinstance(bound, dict) or not positive(bound.get("calls_ns")):
        fail("'bound' missing: %r" % (bound,))
    if not isinstance(bound.get("clock_measured"), bool):
        fail("bound: clock_measured %r" % bound.get("clock_measured"))
    if positive(bound.get("clock_ghz")):
        rows = bound.get("kernels", {})
        if not {"dynamics", "forward_dynamics", "inverse_dynamics"} <= set(rows):
            fail("bound: rows %s" % sorted(rows))
        for name, r in rows.items():
            # the bound is the multiplies at the clock plus the calls
            want = r["muls"] / 2.0 / bound["clock_ghz"] + bound["calls_ns"]
            if not (isinstance(r["muls"], int) and r["muls"] > 0 and
                    positive(r["measured_ns"]) and r["bound_ns"] >= want * (1 - 2e-3)):
                fail("bound %r: %r" % (name, r))
    # The closed-form derivatives (the bench runs on the build's model,
    # whose specialised kernels have them): every time and ratio positive.
    derivs = doc.get("derivs")
    keys = ["forward_ns", "fused_kernel_ns", "linearize_ns", "central_differences_ns",
            "fused_over_forward", "linearize_over_forward", "central_over_linearize"]
    if not isinstance(derivs, dict) or derivs.get("nact") not in (3, 4):
        fail("'derivs' missing or without nact: %r" % (derivs,))
    if derivs["nact"] == 3:
        keys += ["inverse_ns", "inverse_kernel_ns", "inverse_derivs_ns",
                 "inverse_derivs_over_inverse"]
    if not all(positive(derivs.get(k)) for k in keys):
        fail("'derivs' incomplete: %r" % (derivs,))
    if not positive(doc.get("regeneration_s")):
        fail("regeneration_s missing")
    # Every set of the generator, each timed (bench_regen.c).
    sets = doc.get("regeneration_sets_s")
    set_names = ("default", "derivatives", "regressor", "float", "build")
    if not isinstance(sets, dict) or sorted(sets) != sorted(set_names) or \
            not all(positive(sets[k]) for k in set_names):
        fail("regeneration_sets_s incomplete: %r" % (sets,))
    if sets["default"] != doc["regeneration_s"]:
        fail("regeneration_s is not the default set's time")
    print("bench_smoke: JSON complete, %d kernels" % len(names))


if __name__ == "__main__":
    main()
