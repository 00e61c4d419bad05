/* User text made fit for the files the runtime's users write. */
#include <stdio.h>
#include <string.h>

#include "prru.h"

size_t prru_utf8_char(const char *text)
{
  const unsigned char *s = (const unsigned char *)text;
  const unsigned char c = s[0];
  size_t n;
  if (c == 0) return 0;
  if (c < 0x80) return 1;
  unsigned char lo = 0x80, hi = 0xbf; /* range of the second byte */
  if (c >= 0xc2 && c <= 0xdf) n = 2;
  else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    if (c == 0xe0) lo = 0xa0;
    if (c == 0xed) hi = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    if (c == 0xf0) lo = 0x90;
    if (c == 0xf4) hi = 0x8f;
  } else
    return 0;
  if (s[1] < lo || s[1] > hi) return 0;
  for (size_t i = 2; i < n; i++)
    if (s[i] < 0x80 || s[i] > 0xbf) return 0;
  return n;
}

/* Bytes of the code point at s and whether it is a control character
 * (C0, DEL, C1: U+0080..U+009F is 0xc2 0x80..0x9f), 1 byte for a malformed
 * one. */
size_t prru_json_char(const char *s, char *out, size_t *used)
{
  const unsigned char c = (unsigned char)*s;
  const size_t n = prru_utf8_char(s);
  *used = n ? n : 1;
  if (c == '"' || c == '\\') {
    out[0] = '\\', out[1] = (char)c;
    return 2;
  }
  if (c < 0x20 || c == 0x7f || c == '<' || c == '>' || c == '&') return (size_t)sprintf(out, "\\u%04x", c);
  if (n == 0) return (size_t)sprintf(out, "\\ufffd");
  if (n == 3 && c == 0xe2 && (unsigned char)s[1] == 0x80 && ((unsigned char)s[2] & 0xfe) == 0xa8)
    return (size_t)sprintf(out, "\\u%04x", 0x2000 + ((unsigned char)s[2] - 0x80));
  memcpy(out, s, n);
  return n;
}

static size_t code_point(const unsigned char *s, int *bad)
{
  size_t n = prru_utf8_char((const char *)s);
  *bad = n == 0 || s[0] < 0x20 || s[0] == 0x7f || (s[0] == 0xc2 && s[1] < 0xa0);
  return n ? n : 1;
}

/* Appends the code points [from, to) of text (counted as code_point
 * does), cleaned, to out; returns the new length. Never beyond size - 1
 * nor in the middle of a code point: *full is set when one did not fit,
 * and nothing is appended after that. */
static size_t put_range(char *out, size_t used, size_t size, const char *text, size_t from, size_t to,
                        int *full)
{
  const unsigned char *s = (const unsigned char *)text;
  for (size_t k = 0; *s && k < to && !*full; k++) {
    int bad;
    const size_t n = code_point(s, &bad);
    if (k >= from) {
      const size_t w = bad ? 1 : n;
      *full = used + w >= size;
      if (*full) break;
      if (bad) out[used] = '?';
      else memcpy(out + used, s, n);
      used += w;
    }
    s += n;
  }
  out[used] = '\0';
  return used;
}

char *prru_description(char *out, size_t size, const char *text)
{
  size_t count = 0;
  for (const unsigned char *s = (const unsigned char *)text; *s; count++) {
    int bad;
    s += code_point(s, &bad);
  }
  int full = 0;
  if (count <= PRRU_DESCRIPTION_MAX) {
    put_range(out, 0, size, text, 0, count, &full);
  } else {
    const size_t head = (PRRU_DESCRIPTION_MAX - 3) / 2, tail = PRRU_DESCRIPTION_MAX - 3 - head;
    size_t used = put_range(out, 0, size, text, 0, head, &full);
    used = put_range(out, used, size, "...", 0, 3, &full);
    put_range(out, used, size, text, count - tail, count, &full);
  }
  for (char *p = out; (p = strstr(p, "*/")) != NULL; p++) p[1] = '|';
  return out;
}
