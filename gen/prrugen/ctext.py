"""Text in generated C: the one way a string becomes a C string literal
(c_string) and the one way text becomes part of a comment (c_comment).

Every string the generator writes into C goes through these, whatever its
source (a model's description, a file name, a body name), because any of
them may one day hold user text. They have to hold under every C99 mode a
user may compile with: with trigraphs on (-std=c99), "??/" is a backslash,
so a '?' in a literal is written as the escape "\\?", and a comment never
holds "??" at all.
"""

import re

# Characters written as themselves in a literal: printable ASCII except the
# three that need a backslash. Everything else is an octal escape of its
# UTF-8 bytes: octal escapes end after three digits (a hex escape would
# swallow the hex digits that follow), and the file stays ASCII.
_LITERAL_ESCAPES = {"\\": "\\\\", '"': '\\"', "?": "\\?"}


def c_string(text):
    """text as a C99 string literal whose bytes are text's UTF-8 bytes.
    ValueError for text that is not encodable (a lone surrogate)."""
    out = []
    for ch in text:
        if ch in _LITERAL_ESCAPES:
            out.append(_LITERAL_ESCAPES[ch])
        elif " " <= ch <= "~":
            out.append(ch)
        else:
            out.extend("\\%03o" % b for b in ch.encode("utf-8"))
    return '"%s"' % "".join(out)


# Pairs that end, open or splice a comment: "*/" ends it, "/*" inside one is
# a -Wcomment warning (an error under -Werror), and "??" may start the
# trigraph "??/", a backslash that splices the next line onto this one.
_COMMENT_PAIRS = re.compile(r"\*(?=/)|/(?=\*)|\?(?=\?)")


def c_comment(text):
    """text made safe inside a /* */ comment, on one line: control
    characters become spaces, the pairs above get a space between their
    characters, and a trailing backslash (a line splice) is followed by a
    space. Readable, not reversible: the exact text is in the literals."""
    text = "".join(" " if ord(ch) < 32 or 0x7f <= ord(ch) < 0xa0
                   or 0xd800 <= ord(ch) < 0xe000 or ch in "\u2028\u2029"
                   else ch for ch in text)
    text = _COMMENT_PAIRS.sub(lambda m: m.group() + " ", text)
    return text + "." if text.rstrip(" ").endswith("\\") else text
