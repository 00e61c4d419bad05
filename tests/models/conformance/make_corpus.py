#!/usr/bin/env python3
"""Writes the conformance corpus of the C model loader (valid/, invalid/)
from the committed models: every rule of gen/prrugen/model.py, the JSON
corner cases, and random models (tests/random_model.py). Run from the
repository root; the files are committed, so rerun only to extend it.
tests/model_conformance.py checks that the generator decides each file as
its directory says and that the C loader agrees with it."""

import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
HERE = os.path.dirname(os.path.abspath(__file__))
PAPER = open(os.path.join(ROOT, "models/3prru_paper.json")).read()
FOUR = open(os.path.join(ROOT, "models/4prru.json")).read()
PROTO = open(os.path.join(ROOT, "models/prototype_example.json")).read()
DRIVES = open(os.path.join(ROOT, "models/prototype_drives.json")).read()


def acts(text=PROTO, **keys):
    """text with its actuators' keys set (None deletes one)."""
    def fn(d):
        for k, v in keys.items():
            if v is None:
                del d["actuators"][k]
            else:
                d["actuators"][k] = v
    return edit(text, fn)


def sub(text, old, new):
    assert old in text, old
    return text.replace(old, new, 1)


def obj(text):
    return json.loads(text)


def dump(data):
    return json.dumps(data, indent=1)


def edit(text, fn):
    data = obj(text)
    fn(data)
    return dump(data)


def setk(path, value, text=PAPER):
    def fn(d):
        keys = path.split(".")
        for k in keys[:-1]:
            d = d[k]
        if value is DELETE:
            del d[keys[-1]]
        else:
            d[keys[-1]] = value
    return edit(text, fn)


DELETE = object()
VALID = {
    "paper": PAPER, "4prru": FOUR, "prototype": PROTO,
    # section 13: per-actuator lists and the rail forms of the limits;
    # armature beside a lead (no rotor_inertia) is allowed
    "f2_drives_lists": acts(lead=[0.02, 0.01, 0.005], gear=[1, 2, 3.5],
                            torque_constant=[0.11, 0.12, 0.13],
                            stroke=[[-0.05, 0.45], [-0.04, 0.44], [0, 0.4]],
                            force_max=[150, 160, 170], speed_max=0.75),
    "f2_drives_motor_forms": acts(DRIVES, lead=[0.02, 0.01, 0.005],
                                  gear=[1, 2, 3.5], torque_max=[0.64, 0.5, 0.3],
                                  motor_speed_max=[3000, 4500, 6000]),
    "f2_drives_gear_stroke_only": acts(gear=2, stroke=[-1, 1]),
    "f2_drives_four_limbs": setk("actuators", {
        "lead": 0.01, "rotor_inertia": [1e-6, 2e-6, 3e-6, 4e-6],
        "stroke": [[-0.1, 0.5]] * 4, "force_max": [100, 100, 200, 200],
        "motor_speed_max": 2000}, FOUR),
    "f2_drives_rotor_inertia_zero": acts(DRIVES, rotor_inertia=0),
    "paper_format_1_explicit": sub(PAPER, "{", '{"format": 1,'),
    "paper_format_1_real": sub(PAPER, "{", '{"format": 1.0e0,'),
    "paper_reordered": json.dumps(dict(reversed(list(obj(PAPER).items()))),
                                  separators=(",", ":")),
    "paper_exponents": sub(PAPER, '"mass": 1.31', '"mass": 131e-2'),
    "boundary_magnitudes": setk("bodies.P.mass", 1e6, setk(
        "geometry.a", 0.000000001, setk("geometry.a", 1e-9))),
    "triangle_equality": setk("bodies.P.inertia", [0.3, 0.1, 0.2]),
    "four_limbs_null_actuators": setk("actuators", None, FOUR),
    "negative_zero_com": setk("bodies.P.com", [-0.0, 0, 0], PROTO),
    "forty_digits": sub(PAPER, '"mass": 1.31',
                        '"mass": 1.310000000000000000000000000000000000001'),
    "unicode_description": setk("description", "Caf\u00e9 \U0001F600 \"quoted\""),
}
HUGE_KEY = "k" * 5000
INVALID = {
    # the JSON layer
    "empty": "", "whitespace_only": "  \n\t ", "bom": "\ufeff" + PAPER,
    "nan": sub(PAPER, "9.81", "NaN"), "infinity": sub(PAPER, "0.23", "Infinity"),
    "minus_infinity": sub(PAPER, "0.64", "-Infinity"),
    "duplicate_top": sub(PAPER, "{", '{"name": "x",'),
    "duplicate_nested": sub(PAPER, '"mass": 1.31', '"mass": 1.31, "mass": 1.3'),
    "duplicate_odd_key": sub(PAPER, "{", '{"a \\"b\\u00e9": 1, "a \\"b\u00e9": 2,'),
    "trailing_comma": sub(PAPER, '"mass": 1.31', '"mass": 1.31,,'),
    "too_deep": "[" * 33 + "]" * 33,
    "lone_surrogate": sub(PAPER, "Table 1", "Table \\ud800"),
    "lone_low_surrogate_key": sub(PAPER, "{", '{"\\udc00": 1,'),
    "nul_in_key": sub(PAPER, "{", '{"a\\u0000": 1,'),
    "nul_in_description": sub(PAPER, "Table 1", "Table\\u00001"),
    "huge_key": sub(PAPER, "{", '{"%s": 1,' % HUGE_KEY),
    "top_level_list": "[1, 2]",
    "top_level_number": "3",
    # numbers
    "overflow": sub(PAPER, "9.81", "1e999"),
    "minus_overflow": sub(PAPER, "0.64", "-1e999"),
    "underflow": sub(PAPER, "0.64", "1e-400"),
    "long_exponent": sub(PAPER, "0.64", "1e99999999999999999999"),
    "long_mantissa_out_of_range": sub(PAPER, "0.64", "1" * 60),
    "too_precise": sub(PAPER, '"mass": 1.31',
                       '"mass": 1.3100000000000000000000000000000000000001'),
    "magnitude_big": setk("bodies.P.mass", 1e7),
    "magnitude_small": setk("geometry.a", 1e-10),
    "magnitude_just_above_1e6": sub(PAPER, '"mass": 1.31',
                                    '"mass": 1000000.000000000000000000000000001'),
    "magnitude_just_below_1e-9": sub(PAPER, '"mass": 1.31',
                                     '"mass": 0.00000000099999999999999999999'),
    "string_number": setk("gravity", "9.81"),
    "bool_number": setk("bodies.P.mass", True),
    "null_number": setk("geometry.l1", None),
    "nested_list_number": setk("geometry.l1", [[[0.23]]]),
    "object_number": setk("geometry.l1", {"v": [1, "x", None, False]}),
    "positive_zero": setk("bodies.P.mass", 0),
    "positive_negative": setk("geometry.b3", -0.2),
    # parse
    "format_3": sub(PAPER, "{", '{"format": 3,'),
    "format_string": sub(PAPER, "{", '{"format": "2",'),
    "format_bool": sub(PAPER, "{", '{"format": true,'),
    "format_real": sub(PAPER, "{", '{"format": 1.5,'),
    "format_overflow": sub(PAPER, "{", '{"format": 1e999,'),
    "name_upper": setk("name", "Prru"),
    "name_long": setk("name", "a" * 17),
    "name_number": setk("name", 3),
    "description_comment_end": setk("description", "a */ b"),
    "description_control": setk("description", "a\tb"),
    "description_long": setk("description", "\u00e9" * 401),
    "description_list": setk("description", ["x"]),
    "missing_name": setk("name", DELETE),
    "missing_geometry_l1": setk("geometry.l1", DELETE),
    "missing_body": setk("bodies.U2", DELETE),
    "missing_mass": setk("bodies.S1.mass", DELETE),
    "unknown_top": setk("colour", "red"),
    "unknown_top_format_1_actuators": setk("actuators", {}),
    "unknown_geometry": setk("geometry.b4", 0.1),
    "unknown_body": setk("bodies.L4", {"mass": 1, "inertia": [1, 1, 1]}),
    "unknown_body_key": setk("bodies.P.com", [0, 0, 0]),
    "geometry_list": setk("geometry", [1]),
    "bodies_string": setk("bodies", "none"),
    "body_number": setk("bodies.P", 2),
    "inertia_fmt1_six": setk("bodies.P.inertia", [1, 1, 1, 0, 0, 0]),
    "inertia_fmt1_number": setk("bodies.P.inertia", 1),
    "inertia_triangle": setk("bodies.P.inertia", [0.31, 0.1, 0.2]),
    "inertia_triangle_beyond_double": sub(PAPER, "{", "{") if False else
    setk("bodies.P.inertia", [0, 0.1, 0.2]).replace(
        "[\n    0,", "[\n    0.300000000000000000000000000001,"),
    "inertia_negative_moment": setk("bodies.P.inertia", [-1, 1, 1]),
    "gravity_negative": setk("gravity", -9.81),
    "gravity_list_format_1": setk("gravity", [0, 0, -9.81]),
    "assembly_limbs_1_2": setk("geometry.a", 0.5),
    "assembly_limb_3": setk("geometry.b3", 0.9),
    # format 2
    "f2_b_not_list": setk("geometry.b", 0.36, FOUR),
    "f2_b_five": setk("geometry.b", [0.36] * 5, FOUR),
    "f2_l1_count": setk("geometry.l1", [0.23] * 3, FOUR),
    "f2_a_count": setk("geometry.a", [0.05] * 3, FOUR),
    "f2_assembly_limb_4": edit(FOUR, lambda d: d["geometry"]["b"].__setitem__(3, 0.9)),
    "f2_gravity_two": setk("gravity", [0, -9.81], FOUR),
    "f2_com_two": setk("bodies.P.com", [0, 0], PROTO),
    "f2_com_string": setk("bodies.P.com", "0", PROTO),
    "f2_inertia_four": setk("bodies.P.inertia", [1, 1, 1, 0], PROTO),
    "f2_not_positive_definite": setk("bodies.P.inertia", [1, 1, 1, 2, 0, 0], PROTO),
    "f2_tensor_triangle": setk("bodies.P.inertia", [1, 0.1, 0.1, 0, 0, 0], PROTO),
    "f2_actuators_list": setk("actuators", [1], PROTO),
    "f2_actuators_unknown": setk("actuators.gearing", 1, PROTO),
    "f2_damping_negative": setk("actuators.damping", [0.1, -0.1, 0.1], PROTO),
    "f2_armature_count": setk("actuators.armature", [0.1, 0.1], PROTO),
    "f2_coulomb_without_velocity": setk("actuators.coulomb_velocity", DELETE, PROTO),
    "f2_coulomb_velocity_zero": setk("actuators.coulomb_velocity", 0, PROTO),
    "f2_four_limbs_body_missing": setk("bodies.S4", DELETE, FOUR),
    # section 13
    "f2_rotor_inertia_with_armature": acts(lead=0.02, rotor_inertia=2e-6),
    "f2_rotor_inertia_without_lead": acts(DRIVES, lead=None),
    "f2_torque_max_without_lead": acts(torque_max=0.5),
    "f2_motor_speed_max_without_lead": acts(motor_speed_max=3000),
    "f2_torque_constant_without_lead": acts(torque_constant=0.1),
    "f2_force_max_and_torque_max": acts(DRIVES, force_max=[100, 100, 100]),
    "f2_speed_max_and_motor_speed_max": acts(DRIVES, speed_max=1),
    "f2_lead_zero": acts(DRIVES, lead=0),
    "f2_lead_negative_entry": acts(DRIVES, lead=[0.02, -0.02, 0.02]),
    "f2_gear_zero": acts(DRIVES, gear=0),
    "f2_gear_bool": acts(DRIVES, gear=True),
    "f2_rotor_inertia_negative": acts(DRIVES, rotor_inertia=[2e-6, 2e-6, -2e-6]),
    "f2_torque_constant_zero": acts(DRIVES, torque_constant=0),
    "f2_torque_max_negative": acts(DRIVES, torque_max=-0.64),
    "f2_motor_speed_max_string": acts(DRIVES, motor_speed_max="3000"),
    "f2_force_max_zero": acts(force_max=0),
    "f2_speed_max_count": acts(speed_max=[1, 1]),
    "f2_lead_count": acts(DRIVES, lead=[0.02] * 4),
    "f2_stroke_reversed": acts(stroke=[0.45, -0.05]),
    "f2_stroke_empty": acts(stroke=[0.1, 0.1]),
    "f2_stroke_pair_equal": acts(stroke=[[0, 0.4], [0.2, 0.2], [0, 0.4]]),
    "f2_stroke_number": acts(stroke=0.4),
    "f2_stroke_three_numbers": acts(stroke=[0, 0.2, 0.4]),
    "f2_stroke_pair_count": acts(stroke=[[0, 0.4], [0, 0.4]]),
    "f2_stroke_pair_three": acts(stroke=[[0, 0.4], [0, 0.2, 0.4], [0, 0.4]]),
    "f2_stroke_pair_number": acts(stroke=[[0, 0.4], 0.4, [0, 0.4]]),
    "f2_stroke_entry_string": acts(stroke=[[0, "0.4"], [0, 0.4], [0, 0.4]]),
    "f2_stroke_entry_huge": acts(stroke=[-0.05, 2e6]),
    "f2_drives_four_limbs_count": setk("actuators", {"lead": [0.01] * 3}, FOUR),
}
INVALID_BYTES = {
    "not_utf8": PAPER.encode().replace(b"Table", b"T\xe4ble", 1),
    "utf8_surrogate_bytes": PAPER.encode().replace(b"Table", b"T\xed\xa0\x80", 1),
    "utf8_overlong": PAPER.encode().replace(b"Table", b"T\xc0\xafble", 1),
    "raw_nul_byte": PAPER.encode().replace(b"Table", b"T\x00ble", 1),
}


def write(sub_dir, name, data):
    path = os.path.join(HERE, sub_dir, name + ".json")
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode("utf-8"))


def main():
    for d in ("valid", "invalid"):
        os.makedirs(os.path.join(HERE, d), exist_ok=True)
    for name, text in VALID.items():
        write("valid", name, text)
    for name, text in INVALID.items():
        write("invalid", name, text)
    for name, data in INVALID_BYTES.items():
        write("invalid", name, data)
    for seed, extra in ((1, []), (2, ["--limbs", "4"]), (3, ["--limbs", "3", "--format", "1"]),
                        (4, ["--limbs", "3"])):
        subprocess.run([sys.executable, os.path.join(ROOT, "tests/random_model.py"),
                        "--seed", str(seed), "--out",
                        os.path.join(HERE, "valid", "random_%d.json" % seed)]
                       + extra, check=True)


if __name__ == "__main__":
    main()
