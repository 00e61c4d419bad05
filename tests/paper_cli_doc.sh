#!/usr/bin/env bash
# docs/cli.md, the command-line reference, is what docs/gen_cli.py makes now
# from this build's help texts (a paper test: the file is the paper model's
# build's). A help text changed without regenerating it fails here. The
# generator is first shown a stand-in prru whose help holds its own path:
# refused, so the reference never depends on where it is made.
. "$(dirname "$0")/cli_lib.sh"

gen="$PRRU_SOURCE_DIR/docs/gen_cli.py"
if python3 "$gen" "$PRRU" --out "$tmp/cli.md" 2>"$tmp/err"; then
  if diff -u "$PRRU_SOURCE_DIR/docs/cli.md" "$tmp/cli.md" >"$tmp/diff"; then ok
  else
    bad "docs/cli.md is stale (it differs from the help texts of this build): run 'make docs-cli' and commit docs/cli.md; the difference:"
    head -40 "$tmp/diff" >&2
  fi
else
  bad "docs/gen_cli.py $PRRU failed: $(cat "$tmp/err")"
fi

# A stand-in whose usage holds its directory: refused, exit 1, nothing written.
mkdir "$tmp/bin"
cat >"$tmp/bin/prru" <<EOF
#!/bin/sh
printf 'usage: prru\n\ncommands:\n  eval  one state\n\nfiles in $tmp/bin\n'
EOF
chmod +x "$tmp/bin/prru"
python3 "$gen" "$tmp/bin/prru" --out "$tmp/fake.md" 2>"$tmp/err"
st=$?
[ "$st" = 1 ] && grep -qF "the binary's directory ($tmp/bin)" "$tmp/err" && [ ! -e "$tmp/fake.md" ] && ok ||
  bad "gen_cli.py on a help text holding a path: exit $st, $(cat "$tmp/err")"
finish paper_cli_doc
