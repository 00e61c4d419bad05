"""Hostile model files through the command line, end to end.

test_generator.BadModels checks model.parse's messages for common mistakes;
this table feeds malformed and adversarial files to prru_gen.py itself, the
way a user's typo or a corrupted download reaches it, and requires for every
one: exit status 1 (not a signal, not a hang), one "prru_gen: error:" line
naming the file, the key and the reason, no Python traceback, and the output
directory byte-identical (no new, changed or stray temporary files).

Cases the loader currently gets wrong are separate methods marked
expectedFailure (see the bottom); once the loader is fixed they pass, which
unittest reports as an unexpected success and fails the run, so the marker
has to be removed and the case becomes an ordinary regression test.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

GEN_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROOT = os.path.dirname(GEN_DIR)
MODEL = os.path.join(ROOT, "models", "3prru_paper.json")
ENTRY = os.path.join(GEN_DIR, "prru_gen.py")
# Generous: a rejection takes ~0.15 s; only a runaway loader gets near it.
TIMEOUT = 60


def paper():
    with open(MODEL, encoding="utf-8") as f:
        return json.load(f)


def paper_text():
    return json.dumps(paper(), indent=2)


def edited(fn):
    m = paper()
    fn(m)
    return json.dumps(m, indent=2).encode("utf-8")


def replaced(old, new, count=1):
    text = paper_text()
    assert old in text, old
    return text.replace(old, new, count).encode("utf-8")


def set_body(body, key, value):
    return edited(lambda m: m["bodies"][body].__setitem__(key, value))


def set_geo(key, value):
    return edited(lambda m: m["geometry"].__setitem__(key, value))


def set_top(key, value):
    return edited(lambda m: m.__setitem__(key, value))


def delete(*keys):
    def fn(m):
        for k in keys[:-1]:
            m = m[k]
        del m[keys[-1]]
    return edited(fn)


GRAVITY = '"gravity": 9.81'
# (description, file content, key the message must name or None for
# file-level errors, reason fragment). Content None means "use the path as
# is" (see SPECIAL_PATHS).
CASES = [
    # --- not JSON at all, or not a JSON object ---
    ("empty file", b"", None, "not valid JSON"),
    ("whitespace only", b" \n\t\n", None, "not valid JSON"),
    ("truncated inside a string",
     paper_text()[:paper_text().index("Nonlinear")].encode(), None,
     "not valid JSON"),
    ("truncated after the first brace", b"{", None, "not valid JSON"),
    ("trailing garbage", paper_text().encode() + b"\n}", None,
     "not valid JSON"),
    ("two objects", paper_text().encode() * 2, None, "not valid JSON"),
    ("NUL byte", replaced(GRAVITY, '"gravity": 9.81\x00'), None,
     "not valid JSON"),
    ("UTF-8 byte order mark", b"\xef\xbb\xbf" + paper_text().encode(), None,
     "not valid JSON"),
    ("invalid UTF-8 in a string",
     replaced("Table 1", "Table @1").replace(b"@", b"\xff"), None,
     "not UTF-8"),
    ("UTF-16 file", paper_text().encode("utf-16"), None, "not UTF-8"),
    ("Latin-1 description", paper_text().replace("Table 1", "Tabl\u00e9 1")
     .encode("latin-1"), None, "not UTF-8"),
    ("top level is an array", b"[]", "(top level)", "must be a JSON object"),
    ("top level is null", b"null", "(top level)", "must be a JSON object"),
    ("top level is a string", b'"prru"', "(top level)",
     "must be a JSON object"),
    ("deeply nested array, whole file", b"[" * 400000 + b"]" * 400000, None,
     "not valid JSON"),
    ("deeply nested value", replaced(GRAVITY, '"gravity": ' + "[" * 100000
                                     + "]" * 100000), None, "not valid JSON"),
    ("deeply nested objects", replaced(GRAVITY, '"gravity": '
                                       + '{"a":' * 50000 + "1"
                                       + "}" * 50000), None,
     "not valid JSON"),
    ("10 MB file", paper_text().encode() + b" " * (10 << 20), None,
     "larger than"),
    ("10 MB description", set_top("description", "x" * (10 << 20)), None,
     "larger than"),
    # --- non-finite and out-of-range numbers ---
    ("Infinity length", replaced('"l1": 0.23', '"l1": Infinity'), None,
     "non-finite number Infinity"),
    ("-Infinity mass", replaced('"mass": 0.64', '"mass": -Infinity'), None,
     "non-finite number -Infinity"),
    ("NaN inertia moment", replaced("0.0024", "NaN"), None,
     "non-finite number NaN"),
    ("tiny gravity 1e-400", replaced(GRAVITY, '"gravity": 1e-400'),
     "gravity", "outside [1e-9, 1e6]"),
    ("tiny mass 1e-12", set_body("P", "mass", 1e-12), "bodies.P.mass",
     "outside [1e-9, 1e6]"),
    ("huge length 1e7", set_geo("b3", 1e7), "geometry.b3",
     "outside [1e-9, 1e6]"),
    ("huge inertia", set_body("U3", "inertia", [1e12, 1e12, 1e12]),
     "bodies.U3.inertia[0]", "outside [1e-9, 1e6]"),
    # --- wrong types ---
    ("bodies is a list", set_top("bodies", []), "bodies",
     "must be a JSON object"),
    ("geometry is null", set_top("geometry", None), "geometry",
     "must be a JSON object"),
    ("a body is a number", edited(lambda m: m["bodies"].__setitem__("P", 1.77)),
     "bodies.P", "must be a JSON object"),
    ("gravity is a string", set_top("gravity", "9.81"), "gravity",
     "must be a number"),
    ("mass is null", set_body("S2", "mass", None), "bodies.S2.mass",
     "must be a number"),
    ("inertia is a string", set_body("L2", "inertia", "0.0025 0.0003 0.0027"),
     "bodies.L2.inertia", "3 principal moments"),
    ("inertia has 4 moments", set_body("L3", "inertia", [1e-3] * 4),
     "bodies.L3.inertia", "3 principal moments"),
    ("inertia is empty", set_body("U1", "inertia", []),
     "bodies.U1.inertia", "3 principal moments"),
    ("inertia moment is a string", set_body("U2", "inertia",
                                            [0.0065, "0.0016", 0.0079]),
     "bodies.U2.inertia[1]", "must be a number"),
    ("inertia moment is true", set_body("P", "inertia", [0.0024, True, 0.0032]),
     "bodies.P.inertia[1]", "must be a number"),
    ("name is a number", set_top("name", 3), "name", "C identifier"),
    ("name 17 characters", set_top("name", "p" * 17), "name", "C identifier"),
    ("name injects C", set_top("name", "prru;int"), "name", "C identifier"),
    ("name in upper case", set_top("name", "Prru"),
     "name", "C identifier"),
    ("description is a number", set_top("description", 1), "description",
     "one line"),
    ("description closes the C comment",
     set_top("description", "ok */ int evil; /*"), "description", "'*/'"),
    ("description has a newline", set_top("description", "a\n#include <x>"),
     "description", "one line"),
    ("description 401 characters", set_top("description", "d" * 401),
     "description", "400 characters"),
    # refused at the JSON layer, wherever it stands, as the C loader's
    # parser (jansson) refuses it (tests/model_conformance.py)
    ("description with a lone surrogate escape",
     replaced("Table 1", "Table \\ud800"), None, "surrogate"),
    # --- missing, extra and duplicated keys ---
    ("no bodies", delete("bodies"), "bodies", "missing"),
    ("no geometry", delete("geometry"), "geometry", "missing"),
    ("empty bodies", set_top("bodies", {}), "bodies.P", "missing"),
    ("body without mass", delete("bodies", "L2", "mass"), "bodies.L2.mass",
     "missing"),
    ("geometry without a", delete("geometry", "a"), "geometry.a", "missing"),
    ("extra body S4", edited(lambda m: m["bodies"].__setitem__(
        "S4", m["bodies"]["S3"])), "bodies.S4", "unknown key"),
    ("extra top-level key", set_top("joints", []), "joints", "unknown key"),
    ("extra body key", set_body("P", "com", [0, 0, 0]), "bodies.P.com",
     "unknown key"),
    ("body name in lower case", edited(lambda m: m["bodies"].__setitem__(
        "p", m["bodies"].pop("P"))), "bodies.p", "unknown key"),
    ("duplicated body", replaced('"P": {', '"P": {"mass": 1, "inertia": '
                                 '[1, 1, 1]},\n    "P": {'), None,
     "duplicate key 'P'"),
    ("duplicated mass", replaced('"mass": 1.31', '"mass": 1.31, "mass": 1.3'),
     None, "duplicate key 'mass'"),
    ("duplicated geometry object", replaced('"geometry": {',
                                            '"geometry": {}, "geometry": {'),
     None, "duplicate key 'geometry'"),
    # --- lengths, masses and geometry that cannot be a robot ---
    ("zero length", set_geo("l2", 0), "geometry.l2", "must be positive"),
    ("negative zero length", replaced('"a": 0.045', '"a": -0.0'),
     "geometry.a", "must be positive"),
    ("negative b3", set_geo("b3", -0.315), "geometry.b3", "must be positive"),
    ("negative mass", set_body("U1", "mass", -1.31), "bodies.U1.mass",
     "must be positive"),
    ("zero inertia moment", set_body("S1", "inertia", [0.0036, 0, 0.0015]),
     "bodies.S1.inertia[1]", "must be positive"),
    ("negative gravity", set_top("gravity", -9.81), "gravity",
     "must not be negative"),
    ("upper link too short", set_geo("l1", 0.05), "geometry",
     "cannot be assembled"),
    ("limbs 1, 2 exactly at full stretch",
     # b12 - a - l2 = 0.5 - 0.045 - 0.225 = l1 exactly (exact Fractions)
     set_geo("b12", 0.5), "geometry", "limbs 1, 2 cannot be assembled"),
    ("limb 3 out of reach", set_geo("b3", 0.6), "geometry",
     "limb 3 cannot be assembled"),
    ("rails inside out", set_geo("b12", 0.01), "geometry",
     "cannot be assembled"),
    ("inertia violates the triangle inequality",
     set_body("S2", "inertia", [0.0036, 0.0032, 0.0069]),
     "bodies.S2.inertia", "triangle inequality"),
]

# Paths that are not regular files (content None in the runner).
SPECIAL_PATHS = [
    ("a directory", "dir", "cannot read: Is a directory"),
    ("/dev/zero (endless)", "/dev/zero", "larger than"),
    ("/dev/null (empty)", "/dev/null", "not valid JSON"),
    ("missing file in a missing directory", "missing/none.json",
     "cannot read: No such file or directory"),
]


def snapshot(d):
    """Every file under d (hidden ones too) with its bytes and mode."""
    out = {}
    for folder, _, files in os.walk(d):
        for f in files:
            p = os.path.join(folder, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, d)] = (fh.read(), os.stat(p).st_mode)
    return out


class HostileModels(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.tmp.name, "generated")
        r = subprocess.run([sys.executable, ENTRY, MODEL, "--out", cls.out,
                            "--quiet"], capture_output=True, text=True,
                           timeout=TIMEOUT)
        assert r.returncode == 0, r.stderr
        cls.before = snapshot(cls.out)
        os.mkdir(os.path.join(cls.tmp.name, "dir"))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_gen(self, path, timeout=TIMEOUT):
        return subprocess.run([sys.executable, ENTRY, path, "--out", self.out],
                              capture_output=True, timeout=timeout,
                              cwd=self.tmp.name)

    def check_rejected(self, path, key, reason, timeout=TIMEOUT):
        try:
            r = self.run_gen(path, timeout)
        except subprocess.TimeoutExpired:
            self.fail("%s: prru_gen.py still running after %d s" % (path, timeout))
        err = r.stderr.decode("utf-8", "replace")
        self.assertNotIn("Traceback", err)
        self.assertEqual(r.returncode, 1, err)
        self.assertEqual(r.stdout, b"")
        lines = err.splitlines()
        self.assertEqual(len(lines), 1, err)
        self.assertTrue(lines[0].startswith("prru_gen: error: %s: " % path), err)
        if key:
            self.assertIn(": %s: " % key, lines[0])
        self.assertIn(reason, lines[0])
        self.assertEqual(snapshot(self.out), self.before,
                         "output directory changed")
        # The reason fits on a terminal line: a 10 MB value must not be echoed.
        self.assertLess(len(lines[0]), 600, lines[0][:200])

    def check_content(self, desc, content, key, reason, timeout=TIMEOUT):
        path = os.path.join(self.tmp.name, "model.json")
        with open(path, "wb") as f:
            f.write(content)
        try:
            self.check_rejected(path, key, reason, timeout)
        finally:
            os.unlink(path)

    def test_table(self):
        for desc, content, key, reason in CASES:
            with self.subTest(desc):
                self.check_content(desc, content, key, reason)

    def test_special_paths(self):
        for desc, path, reason in SPECIAL_PATHS:
            with self.subTest(desc):
                self.check_rejected(path, None, reason)

    def test_failure_does_not_create_the_output_directory(self):
        path = os.path.join(self.tmp.name, "bad.json")
        with open(path, "wb") as f:
            f.write(set_geo("l1", -1))
        fresh = os.path.join(self.tmp.name, "fresh", "out")
        r = subprocess.run([sys.executable, ENTRY, path, "--out", fresh],
                           capture_output=True, text=True, timeout=TIMEOUT)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertFalse(os.path.exists(os.path.dirname(fresh)))

    def test_float_refuses_a_constant_beyond_single_precision(self):
        # Every number in range ([1e-9, 1e6]), but the armature the drives
        # reflect, rotor_inertia (2 pi gear / lead)^2, is 4e37 kg and M's
        # constants reach 1.6e42: finite as doubles, inf as floats. The
        # double kernels generate; the float ones are refused, naming the
        # file's largest number (gear and rotor_inertia tie; gear first).
        with open(os.path.join(ROOT, "models", "prototype_drives.json"),
                  encoding="utf-8") as f:
            m = json.load(f)
        m["actuators"] = {"lead": 1e-9, "gear": 1e6, "rotor_inertia": 1e6,
                          "damping": 18.0, "coulomb": 3.2,
                          "coulomb_velocity": 0.004}
        path = os.path.join(self.tmp.name, "float_overflow.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(m, f)
        r = subprocess.run([sys.executable, ENTRY, path, "--precision",
                            "float", "--out", self.out],
                           capture_output=True, text=True, timeout=TIMEOUT)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertEqual(r.stdout, "")
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith(
            "prru_gen: error: %s: actuators.gear: cannot be generated in "
            "single precision: " % path), lines[0])
        self.assertIn("overflows single precision", lines[0])
        self.assertEqual(snapshot(self.out), self.before,
                         "output directory changed")
        out = os.path.join(self.tmp.name, "float_overflow_double")
        r = subprocess.run([sys.executable, ENTRY, path, "--out", out,
                            "--quiet"], capture_output=True, text=True,
                           timeout=TIMEOUT)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_largest_accepted_file_still_generates(self):
        # The size limit is inclusive: a valid model padded to exactly
        # MAX_BYTES is accepted, so the limit rejects size, not content.
        from prrugen import model
        text = paper_text().encode()
        path = os.path.join(self.tmp.name, "padded.json")
        with open(path, "wb") as f:
            f.write(text + b" " * (model.MAX_BYTES - len(text)))
        self.assertEqual(os.path.getsize(path), model.MAX_BYTES)
        out = os.path.join(self.tmp.name, "padded_out")
        r = subprocess.run([sys.executable, ENTRY, path, "--out", out,
                            "--quiet"], capture_output=True, text=True,
                           timeout=TIMEOUT)
        self.assertEqual(r.returncode, 0, r.stderr)
        # Same kernels as the unpadded model (only the recorded hash differs).
        got = snapshot(out)["paper3prru_kernels.c"][0].split(b"*/", 1)[1]
        want = self.before["paper3prru_kernels.c"][0].split(b"*/", 1)[1]
        self.assertEqual(got, want)


# Inputs that once broke the loader (tracebacks, a 10**99999999 Fraction):
# regression tests now. (test name, content, key, reason, timeout)
REGRESSIONS = [
    ("number_beyond_double_range",
     # model._fmt calls float() on the Fraction for the message and raises
     # OverflowError: a traceback instead of a message.
     replaced(GRAVITY, '"gravity": 1e400'), "gravity", "outside", TIMEOUT),
    ("integer_beyond_double_range",
     replaced(GRAVITY, '"gravity": 1' + "0" * 400), "gravity", "outside",
     TIMEOUT),
    ("integer_of_5000_digits_names_the_key",
     # Rejected, but as "not valid JSON: Exceeds the limit (4300 digits)":
     # it is valid JSON, and the message names no key.
     replaced(GRAVITY, '"gravity": ' + "1" * 5000), "gravity", "outside",
     TIMEOUT),
    ("huge_exponent_is_rejected_promptly",
     # Fraction("1e99999999") builds the integer 10**99999999 first: the
     # generator spins for minutes on a 400-byte file.
     replaced(GRAVITY, '"gravity": 1e99999999'), "gravity", "outside", 5),
    ("mass_is_a_list_of_numbers",
     # _number's message json.dumps() a list holding a Fraction: TypeError.
     set_body("S1", "mass", [1.59]), "bodies.S1.mass", "must be a number",
     TIMEOUT),
    ("inertia_moment_is_a_list",
     set_body("P", "inertia", [[0.0024], 0.0028, 0.0032]),
     "bodies.P.inertia[0]", "must be a number", TIMEOUT),
    ("mass_is_an_object_with_a_number",
     set_body("L1", "mass", {"value": 0.64}), "bodies.L1.mass",
     "must be a number", TIMEOUT),
]


def _regression(content, key, reason, timeout):
    def test(self):
        self.check_content("", content, key, reason, timeout)
    return test


for _name, _content, _key, _reason, _timeout in REGRESSIONS:
    setattr(HostileModels, "test_regression_" + _name,
            _regression(_content, _key, _reason, _timeout))

# Texts that break C if written into it raw: trigraphs (on under -std=c99:
# "??/" is a backslash), quotes, backslashes, comment delimiters, line
# splices at the end, control and non-ASCII characters (an octal escape
# followed by a digit, a hex digit after an escape).
HOSTILE_TEXTS = [
    'What??/"',
    '??/"); system("touch pwned"); ("',
    "??= ??( ??) ??' ??< ??! ??> ??- ???/ ????/",
    "ends in a trigraph ??/",
    "ends in a star and a trigraph *??/",
    "ends in a backslash \\",
    "ends in a star and a backslash *\\",
    "ends in a backslash and spaces \\  ",
    "a */ int closed_early; /* b",
    "a /* nested comment",
    "// line comment \\",
    '\\" \\\\ \\n \\x41 \\101',
    "\u00e91 \x7f7 \x01f \u2028 \uffff \u2603 \U0001f600 \x80",
    "tab\tnew\nline\rreturn",
    "",
]


def c_compiler():
    return os.environ.get("CC", "cc")


def compile_c(test, sources, out, include=None, link=False):
    """cc -std=c99 (trigraphs on) -Wall -Werror: every warning about a
    trigraph, a nested comment or a stray character fails the test."""
    cmd = [c_compiler(), "-std=c99", "-pedantic", "-Wall", "-Wextra",
           "-Werror", "-O0", "-o", out] + ([] if link else ["-c"])
    if include:
        cmd += ["-I", include]
    r = subprocess.run(cmd + sources, capture_output=True, text=True,
                       timeout=600)
    test.assertEqual(r.returncode, 0, "%s:\n%s" % (" ".join(cmd + sources),
                                                    r.stderr[-3000:]))


@unittest.skipUnless(shutil.which(c_compiler()), "no C compiler")
class HostileTextInC(unittest.TestCase):
    """ctext.c_string and c_comment, the one way any text reaches C."""

    def test_literals_hold_the_exact_bytes_and_comments_stay_closed(self):
        from prrugen.ctext import c_comment, c_string
        lines = ["#include <stdio.h>"]
        for t in HOSTILE_TEXTS:
            # A comment that a splice or a stray "*/" would end early: the
            # line after it starts with '/', and "int broken;" then stands
            # outside any comment before a stray "*/" (a syntax error).
            lines.append("/* %s\n/ int broken; */" % c_comment(t))
        literals = ", ".join(c_string(t) for t in HOSTILE_TEXTS)
        literals.encode("ascii")  # octal escapes: the literals are ASCII
        lines.append("static const char *const texts[] = {%s};" % literals)
        lines.append("int main(void)\n{\n  for (unsigned i = 0; i < sizeof "
                     "texts / sizeof texts[0]; i++) {\n    fputs(texts[i], "
                     "stdout);\n    putchar(0);\n  }\n  return 0;\n}\n")
        with tempfile.TemporaryDirectory() as d:
            src, exe = os.path.join(d, "t.c"), os.path.join(d, "t")
            with open(src, "w", encoding="utf-8") as f:
                f.write("\n".join(lines))
            compile_c(self, [src], exe, link=True)
            got = subprocess.run([exe], capture_output=True, timeout=60)
        self.assertEqual(got.stdout.split(b"\0")[:-1],
                         [t.encode("utf-8") for t in HOSTILE_TEXTS])

    def test_comments_hold_no_delimiter_trigraph_or_line_break(self):
        from prrugen.ctext import c_comment
        for t in HOSTILE_TEXTS:
            with self.subTest(t):
                c = c_comment(t)
                for bad in ("*/", "/*", "??", "\n", "\r", "\u2028"):
                    self.assertNotIn(bad, c)
                self.assertFalse(c.rstrip(" ").endswith("\\"))


HOSTILE_DESCRIPTION = ('What??/" ??/"); system("touch pwned"); ("??= ??( ??) '
                       "??' ??< ??! ??> ??- ???/ /* a \\\" \\\\ \u00e91 "
                       "\u2603 \U0001f600 \x7f7 \u2028 end *??/")
HOSTILE_FILE = 'm??=*-->"\\$(touch pwned);`x`??-.json'


@unittest.skipUnless(shutil.which(c_compiler()), "no C compiler")
class HostileDescriptionGenerates(unittest.TestCase):
    """A valid model whose description and file name are hostile to C: the
    generated files compile under -std=c99 (trigraphs on) with every
    warning an error, and the descriptor holds the exact texts."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.model = os.path.join(cls.tmp.name, HOSTILE_FILE)
        with open(cls.model, "wb") as f:
            f.write(set_top("description", HOSTILE_DESCRIPTION))
        cls.out = os.path.join(cls.tmp.name, "out")
        cls.gen = subprocess.run([sys.executable, ENTRY, cls.model, "--out",
                                  cls.out, "--derivatives", "--regressor",
                                  "--quiet"], capture_output=True,
                                 text=True, timeout=600)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def setUp(self):
        self.assertEqual(self.gen.returncode, 0, self.gen.stderr)

    def test_every_generated_file_compiles(self):
        for name in sorted(os.listdir(self.out)):
            if name.endswith(".c"):
                with self.subTest(name):
                    # The committed generated/ for the topology kernels'
                    # header that prru_param_kernels.h names (quoted
                    # includes find the output's own files first).
                    compile_c(self, [os.path.join(self.out, name)],
                              os.path.join(self.tmp.name, name + ".o"),
                              include=os.path.join(ROOT, "generated"))

    def test_descriptor_holds_the_exact_texts(self):
        from prrugen.render import _safe_name
        main = os.path.join(self.tmp.name, "main.c")
        with open(main, "w") as f:
            f.write('#include <stdio.h>\n#include "paper3prru_mechanism.h"\n'
                    "int main(void)\n{\n  printf(\"%s%c%s%c%s%c\", "
                    "paper3prru_mech.name, 0, paper3prru_mech.description, 0, "
                    "paper3prru_mech.model_file, 0);\n  return 0;\n}\n")
        exe = os.path.join(self.tmp.name, "main")
        compile_c(self, [main, os.path.join(self.out, "paper3prru_mechanism.c")],
                  exe, include=self.out, link=True)
        got = subprocess.run([exe], capture_output=True, timeout=60)
        self.assertEqual(got.stdout.split(b"\0")[:-1],
                         [b"paper3prru", HOSTILE_DESCRIPTION.encode("utf-8"),
                          _safe_name(HOSTILE_FILE).encode("ascii")])


if __name__ == "__main__":
    unittest.main()
