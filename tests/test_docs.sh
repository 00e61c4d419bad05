#!/usr/bin/env bash
# The documentation's links: README.md and docs/*.md link each other and
# docs/img/ by relative paths and #anchors; a moved section or a renamed
# heading must not leave a link that leads nowhere (tests/doc_links.py).
# The checker itself is first shown a file with each kind of bad link.
set -u
SRC=${PRRU_SOURCE_DIR:-$(cd "$(dirname "$0")/.." && pwd)}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

mkdir -p "$tmp/docs"
cat >"$tmp/docs/a.md" <<'MD'
# A page

## Set up (fresh Debian machine)
[ok](#set-up-fresh-debian-machine) [ok](b.md#bs-heading) ![ok](b.md)
[gone](missing.md) [no anchor](b.md#nowhere) [self](#set-up)
```sh
echo "[inside a code block](not-checked.md)"
```
MD
printf '# B'"'"'s heading\n' >"$tmp/docs/b.md"
python3 "$SRC/tests/doc_links.py" "$tmp/docs/a.md" >"$tmp/out"
st=$?
want="$tmp/docs/a.md:5: missing.md: no such file
$tmp/docs/a.md:5: b.md#nowhere: no heading makes the anchor #nowhere
$tmp/docs/a.md:5: #set-up: no heading makes the anchor #set-up
1 files, 3 bad links"
if [ "$st" != 1 ] || [ "$(cat "$tmp/out")" != "$want" ]; then
  echo "FAIL: the checker on known bad links: exit $st, output:" >&2
  cat "$tmp/out" >&2
  fail=1
fi

if ! python3 "$SRC/tests/doc_links.py" "$SRC/README.md" "$SRC"/docs/*.md; then
  echo "FAIL: bad links in README.md or docs/ (above)" >&2
  fail=1
fi
exit $fail
