/* prru runtime, text in and out: numeric CSV tables, the number parsing
 * the CLI shares (fuzzed), and the text a model file written by a program
 * holds (descriptions, JSON strings). */
#ifndef PRRU_IO_H
#define PRRU_IO_H

#include "prru_dynamics.h"
#include "prru_sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Numeric CSV tables (header row of column names) ---- */
typedef struct {
  int ncols, nrows;
  char **names;  /* ncols */
  double *data;  /* nrows * ncols, row-major */
} prru_table;

/* Reads a comma-separated table: one header row of names, then rows of
 * finite numbers, all rows as long as the header. Limits: 1e6 rows, 1024
 * columns. msg says `name:line: reason`. */
PRRU_API int prru_table_parse(prru_table *t, const char *text, size_t len, const char *name, char *msg,
                              int msglen);
PRRU_API int prru_table_read(prru_table *t, const char *path, char *msg, int msglen);
/* Index of a column by name, -1 if absent. */
PRRU_API int prru_table_column(const prru_table *t, const char *name);
PRRU_API void prru_table_free(prru_table *t);
/* prru_schedule_read_csv from memory. */
PRRU_API int prru_schedule_parse_csv(const prru_model *m, prru_load_schedule *s, const char *text, size_t len,
                                     const char *name, char *msg, int msglen);

/* ---- Parsing shared by the CLI (fuzzed) ---- */
/* Exactly n comma-separated finite doubles, nothing else. */
PRRU_API int prru_parse_list(const char *s, double *out, int n);
/* One finite double, nothing else. */
PRRU_API int prru_parse_double(const char *s, double *out);
/* As prru_parse_double and prru_parse_list, also accepting multiples of
 * pi (angles on the command line): [+|-][K[*]]pi[/N] with K and N decimal
 * numbers, N > 0, e.g. pi, -pi/4, 2pi, 0.5pi, 2*pi/3. */
PRRU_API int prru_parse_value(const char *s, double *out);
PRRU_API int prru_parse_values(const char *s, double *out, int n);

/* ---- Model files written by programs (prru identify, prru optimize) ----
 * A model file's "description" is one line of at most
 * PRRU_DESCRIPTION_MAX characters (Unicode code points) of UTF-8 text
 * without a star followed by a slash (the generator's rule,
 * gen/prrugen/model.py); a description built from user text (a file path)
 * goes through prru_description first. */
#define PRRU_DESCRIPTION_MAX 400
/* Bytes that always hold prru_description's result. */
#define PRRU_DESCRIPTION_SIZE (4 * PRRU_DESCRIPTION_MAX + 1)
/* text as a valid description, into out (size bytes, at least 1;
 * PRRU_DESCRIPTION_SIZE always suffice): well-formed UTF-8 is kept, every
 * byte of a malformed sequence and every control character becomes '?',
 * the slash after a star becomes '|', and a text of more than
 * PRRU_DESCRIPTION_MAX characters keeps its start and its end around
 * "..." (the end of a path names the file). Returns out. A description
 * still needs its JSON escapes (quotes, backslashes) in the file. */
PRRU_API char *prru_description(char *out, size_t size, const char *text);
/* Bytes (1 to 4) of the well-formed UTF-8 sequence of one character at s
 * (RFC 3629: no overlong form, no surrogate, at most U+10FFFF; ASCII
 * included, NUL excluded), 0 when s does not start one. For writers of
 * formats that must be UTF-8 (JSON, XML). */
PRRU_API size_t prru_utf8_char(const char *s);
/* The JSON string text of the character at s (not its NUL), into out
 * (at least 7 bytes; not NUL-terminated): quotes and backslashes
 * escaped, control characters, DEL and, for JSON embedded in HTML, <, >,
 * & and U+2028/9 as \uXXXX, a byte that starts no well-formed UTF-8
 * character as \ufffd, any other character as it is. Returns the bytes
 * written, *used the bytes of s consumed (at least 1). */
PRRU_API size_t prru_json_char(const char *s, char *out, size_t *used);

#ifdef __cplusplus
}
#endif
#endif /* PRRU_IO_H */
