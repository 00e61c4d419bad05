#!/usr/bin/env python3
"""Relative links of Markdown files: every `](target)` outside code blocks
names a file that exists, and every `#anchor` names a heading of its target
file as GitHub makes anchors from headings (lower case, punctuation other
than '-' and '_' dropped, spaces to '-', a repeated heading gets -1, -2...).
Usage: doc_links.py FILE.md...; exit 1, one line per bad link, when any is."""
import os
import re
import sys

LINK = re.compile(r'\]\(([^)\s]+)\)')
HEADING = re.compile(r'#{1,6} +(.*?)[ #]*$')


def prose_lines(path):
    """(line number, line) outside fenced code blocks."""
    fence = False
    with open(path, encoding='utf-8') as f:
        for no, line in enumerate(f, 1):
            if line.lstrip().startswith('```'):
                fence = not fence
            elif not fence:
                yield no, line.rstrip('\n')


def anchors(path):
    found, seen = set(), {}
    for _, line in prose_lines(path):
        m = HEADING.match(line)
        if m:
            slug = re.sub(r'[^\w\- ]', '', m.group(1).strip().lower()).replace(' ', '-')
            n = seen.get(slug, 0)
            found.add(slug if n == 0 else '%s-%d' % (slug, n))
            seen[slug] = n + 1
    return found


def bad_links(path):
    for no, line in prose_lines(path):
        for target in LINK.findall(line):
            if re.match(r'[a-z][a-z0-9+.-]*:', target):  # http:, mailto:, ...
                continue
            file, _, anchor = target.partition('#')
            full = os.path.normpath(os.path.join(os.path.dirname(path), file)) if file else path
            if not os.path.exists(full):
                yield '%s:%d: %s: no such file' % (path, no, target)
            elif anchor and full.endswith('.md') and anchor not in anchors(full):
                yield '%s:%d: %s: no heading makes the anchor #%s' % (path, no, target, anchor)


def main(paths):
    bad = [msg for p in paths for msg in bad_links(p)]
    for msg in bad:
        print(msg)
    print('%d files, %d bad links' % (len(paths), len(bad)))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
