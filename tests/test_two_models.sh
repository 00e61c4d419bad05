#!/usr/bin/env bash
# Kernels of several models link into one program: the paper's model
# generated as paper3prru, the prototype's as proto and the 4-limb model's
# as prru4 (their own names, or --prefix), each set complete (kernels,
# descriptor, parameter kernels, derivatives, regressor), with the shared topology
# kernels from the committed generated/, built as C99 under strict
# warnings with nothing but -lm; tests/two_models_main.c checks each
# model's constant kernels against its parameter kernels and that no
# model's numbers shadow another's. The generated kernels' names carry the
# model's name, so they never meet one another or the library's prru_ API.
set -u
SRC=${PRRU_SOURCE_DIR:-$(cd "$(dirname "$0")/.." && pwd)}
work=$(mktemp -d "${TMPDIR:-/tmp}/prru-two.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
gen() { "${PYTHON:-python3}" "$SRC/gen/prru_gen.py" "$SRC/models/$1" --out "$work" \
  --derivatives --regressor --quiet "${@:2}" ||
  fail "cannot generate $1"; }
gen 3prru_paper.json --prefix paper3prru
gen prototype_example.json
gen 4prru.json
for n in 3 4; do cp "$SRC/generated/prru_p${n}_kernels."[ch] "$work/" || fail "no topology kernels"; done
cp "$SRC/tests/two_models_main.c" "$work/main.c" || exit 1
cd "$work" || exit 1
sources=(main.c prru_p3_kernels.c prru_p4_kernels.c)
for m in paper3prru proto prru4; do
  for part in kernels mechanism param_kernels derivs regressor; do sources+=("${m}_${part}.c"); done
done
${CC:-cc} -std=c99 -O1 -Wall -Wextra -Wpedantic -Werror "${sources[@]}" -lm -o two ||
  fail "three models' kernels do not build into one program"
./two || fail "three models in one program"
echo "test_two_models: all passed"
