#!/usr/bin/env bash
# Every command README.md and docs/*.md show runs, as written, and exits 0
# (tests/doc_commands.py): the fenced sh/bash/console lines and python
# blocks, each file's in order in a fresh directory holding links to
# models/, gen/, templates/ and this build as build/ (the docs' `make
# build`), with this build's prru first on PATH and python/ on PYTHONPATH.
# Commands that cannot run here (package installs, full builds, a viewer,
# Slurm) are listed with the reason in tests/doc_commands_exempt.txt; a
# command neither run nor exempt, and an exemption that matches nothing,
# fail. A paper test: the docs' build/ is the paper's model built in (their
# outputs, poses and forces are the paper robot's).
# The runner itself is first shown a small doc with each verdict.
set -u
SRC=${PRRU_SOURCE_DIR:-$(cd "$(dirname "$0")/.." && pwd)}
: "${PRRU_BUILD_DIR:?set PRRU_BUILD_DIR to the build directory}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

# ---- the runner on known verdicts ----
mkdir -p "$tmp/self/docs"
cat >"$tmp/self/docs/a.md" <<'MD'
# A page
```sh
echo made > made.txt   # a file the next blocks read
```
```console
$ cat made.txt \
> && echo continued
made
$ exempt-me --now
```
```python
assert open("made.txt").read() == "made\n"
```
```
untagged
```
```text
not a command
```
```sh
sh -c 'echo oops >&2; exit 3'
echo never
```
MD
cat >"$tmp/self/exempt.txt" <<'EX'
# a comment
^exempt-me # exempt in the self-test
^no-such-command # stale
no-reason
[docs/b.md] ^echo made # limited to another file: stale here
EX
(cd "$tmp/self" && python3 "$SRC/tests/doc_commands.py" --exempt exempt.txt docs/a.md) >"$tmp/self/out" 2>&1
st=$?
want="exempt docs/a.md:9: exempt-me --now  [exempt.txt:2: exempt in the self-test]
ok docs/a.md:3: echo made > made.txt   # a file the next blocks read
ok docs/a.md:6: cat made.txt  && echo continued
ok docs/a.md:11: python block: assert open(\"made.txt\").read() == \"made\\n\"
FAIL: exempt.txt:4: exemption without a reason (PATTERN # REASON): no-reason
FAIL: docs/a.md:14: code block without a language tag (commands: bash, console, python, sh, shell; others: c, cmake, json, text)
FAIL: docs/a.md:21: exit status 3: sh -c 'echo oops >&2; exit 3'
    oops
FAIL: docs/a.md:22: not run (an earlier command of docs/a.md failed): echo never
FAIL: exempt.txt:3: stale exemption, matches no command: ^no-such-command
FAIL: exempt.txt:5: stale exemption, matches no command: ^echo made
3 commands run, 2 failed or not run, 1 exempt, 1 blocks not commands, 6 problems"
got=$(sed -E 's/^(ok [^ ]+) \([0-9.]+ s\)/\1/' "$tmp/self/out")
if [ "$st" != 1 ] || [ "$got" != "$want" ]; then
  echo "FAIL: the runner on known verdicts: exit $st, output:" >&2
  cat "$tmp/self/out" >&2
  diff <(echo "$want") <(echo "$got") >&2
  fail=1
fi

# ---- the docs ----
mkdir "$tmp/home"
start=$(date +%s)
(cd "$SRC" && env -u PRRU_MODEL PATH="$PRRU_BUILD_DIR/cli:$PATH" PYTHONPATH="$SRC/python" \
  PYTHONDONTWRITEBYTECODE=1 HOME="$tmp/home" \
  python3 tests/doc_commands.py --exempt tests/doc_commands_exempt.txt \
    --link models="$SRC/models" --link gen="$SRC/gen" --link templates="$SRC/templates" \
    --link build="$PRRU_BUILD_DIR" README.md docs/*.md)
st=$?
echo "the docs' commands: $(($(date +%s) - start)) s"
if [ "$st" != 0 ]; then
  echo "FAIL: a command of README.md or docs/ (above, FAIL:) failed, was not run, or an exemption is stale" >&2
  fail=1
fi
exit $fail
